// The dissertation's 6.2.10 scene (validation/forward/spline_leg_scene.hpp): the revolute variant
// is the spline knee frozen at its start, the scene does what it is built for (the knee extends,
// then flexes; the ankle controller holds the ankle), and muscle mass changes the motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "converter/build/build_core_model.hpp"
#include "converter/build/functions_to_core.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/lengths/path_lengths.hpp"
#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"
#include "validation/forward/spline_leg_scene.hpp"

namespace redmax::validation {
namespace {

const std::string kModel = std::string(REDMAX_SOURCE_DIR) + "/osim_models/spline_leg.osim";

const osim::JointDesc& joint(const osim::ModelDescription& d, const std::string& name) {
  for (const auto& j : d.joints)
    if (j.name == name) return j;
  throw std::logic_error("no joint " + name);
}

double valueAt(const osim::FunctionDesc& f, double q) {
  VecJ x(1);
  x[0] = q;
  return osim::makeCoreFunction(f, 1, "test", "test")->value(x);
}

TEST(SplineLegScene, RevoluteKneeIsTheSplineKneeFrozenAtTheGivenAngle) {
  osim::test::TempDir dir;
  const double q0 = -1.0471976;
  const std::string rev = dir.write("rev.osim", revoluteKneeModel(kModel, "knee_r", q0));
  const osim::ModelDescription a = osim::readOsimModel(kModel), b = osim::readOsimModel(rev);
  const osim::JointDesc &ja = joint(a, "knee_r"), &jb = joint(b, "knee_r");
  for (int i = 3; i < 6; ++i) {
    const auto &fa = ja.spatial_transform[i], &fb = jb.spatial_transform[i];
    EXPECT_EQ(fb.function.kind, osim::FunctionKind::Constant) << fb.name;
    EXPECT_TRUE(fb.coordinates.empty()) << fb.name;
    const double want = fa.coordinates.empty() ? fa.function.value : valueAt(fa.function, q0);
    EXPECT_EQ(fb.function.value, want) << fb.name;  // %.17g round-trips
  }
  // the spline knee moves the tibia by centimetres over its range; the rotation is untouched
  EXPECT_GT(std::abs(valueAt(ja.spatial_transform[4].function, -2.0) - valueAt(ja.spatial_transform[4].function, q0)),
            0.01);
  EXPECT_EQ(jb.spatial_transform[0].coordinates, ja.spatial_transform[0].coordinates);
  // a joint that is not there is an error naming the file
  try {
    revoluteKneeModel(kModel, "no_such_knee", q0);
    FAIL() << "no error";
  } catch (const osim::ConvertError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_knee"), std::string::npos) << e.what();
  }
}

TEST(SplineLegScene, KneeMusclesStartAtTheirOptimalFibreLength) {
  // the model's two knee muscles have tendon slack lengths fitted so that, with a rigid tendon,
  // the fibre is at its optimal length at the default pose (the file's header comment):
  // path length = slack + l_opt cos(pennation), to the 0.1 mm the slack lengths are written to
  const osim::ModelDescription d = osim::readOsimModel(kModel);
  const osim::BuildResult b = osim::buildCoreModel(d);
  const VecX q = b.model.skeleton().defaultQ();
  std::vector<Mat4> E;
  calcBodyPoses(b.model, q, E);
  NetworkWrapWorkspace ws;
  std::vector<int> active;
  std::vector<Vec3> x;
  int checked = 0;
  for (size_t m = 0; m < b.model.muscles().size(); ++m) {
    const osim::PathForceDesc& pf = d.muscles[b.muscle_source[m]];
    if (pf.name != "rect_fem_r" && pf.name != "semimem_r") continue;
    const double path = calcModelPathLength(b.model, b.model.muscles()[m], q, E, ws, active, x);
    EXPECT_NEAR(path, pf.tendon_slack_length + pf.optimal_fiber_length * std::cos(pf.pennation_angle_at_optimal),
                1e-4)
        << pf.name;
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

TEST(SplineLegScene, KneeExtendsThenFlexesAnkleHeldAndMassChangesTheMotion) {
  osim::test::TempDir dir;
  SplineLegOptions o;
  o.model_path = kModel;
  o.out_dir = dir.str();
  o.duration = 1.2;
  o.plots = false;
  std::ostringstream log;
  const SplineLegResult r = runSplineLegScene(o, log);
  ASSERT_EQ(r.runs.size(), 4u);
  for (const SplineLegRun& run : r.runs) {
    SCOPED_TRACE(run.name);
    const auto kmax = std::max_element(run.knee.begin(), run.knee.end());
    // the rectus femoris extends the knee by more than 0.4 rad (measured 0.88 spline, 0.48
    // revolute), then the semimembranosus flexes it again by more than half a radian
    EXPECT_GT(*kmax - run.knee.front(), 0.4);
    EXPECT_GT(*kmax - run.knee.back(), 0.5);
    const double t_peak = run.result.states.time[kmax - run.knee.begin()];
    EXPECT_GT(t_peak, 0.25);
    EXPECT_LT(t_peak, 0.9);
    // the proportional controller keeps the ankle within 0.1 rad of neutral (measured 0.071)
    for (double a : run.ankle) EXPECT_LT(std::abs(a), 0.1);
    // the knee's CoordinateLimitForce stops flexion near -120 degrees (-2.094 rad) and its
    // 5 degree transition
    for (double q : run.knee) EXPECT_GT(q, -2.094 - 0.2);
    for (const auto& f : run.tendon_force)
      for (double v : f) ASSERT_TRUE(std::isfinite(v) && v >= 0.0);
  }
  // physiological mass: F_max / 0.6 MPa * l_opt * 1059.7 kg/m^3 summed over the six muscles (the
  // three Type III ones included: the scene asks for wrap_mass)
  double want = 0;
  for (const auto& [F, l] : std::vector<std::pair<double, double>>{
           {3549, 0.05}, {905, 0.098}, {1558, 0.06}, {683, 0.064}, {779, 0.084}, {1288, 0.080}})
    want += F / 0.6e6 * l * 1059.7;
  EXPECT_EQ(r.runs[0].muscle_mass, 0.0);
  EXPECT_NEAR(r.runs[1].muscle_mass, want, 1e-12 * want);
  // 1.01 kg of muscle mass changes the knee's path by milliradians: measured 7.3e-3 rad (spline)
  // and 7.8e-3 rad (revolute), far above the rk45 error at 1e-7 (measured at most 9.4e-6 rad against
  // rtol 1e-10) and far below
  // the 2 rad the knee travels
  auto maxDiff = [](const std::vector<double>& a, const std::vector<double>& b) {
    double m = 0;
    for (size_t k = 0; k < a.size(); ++k) m = std::max(m, std::abs(a[k] - b[k]));
    return m;
  };
  const double spline_mass = maxDiff(r.runs[1].knee, r.runs[0].knee);
  const double revolute_mass = maxDiff(r.runs[3].knee, r.runs[2].knee);
  EXPECT_GT(spline_mass, 3e-3);
  EXPECT_LT(spline_mass, 3e-2);
  EXPECT_GT(revolute_mass, 3e-3);
  EXPECT_LT(revolute_mass, 3e-2);
  // the revolute knee holds its centre where the spline puts it at the start: the runs start
  // alike and part as the spline's centre moves (measured 22.5 mm; the knees differ by up to
  // 0.65 rad: the spline's rolling changes the moment arms)
  EXPECT_EQ(r.runs[2].knee.front(), r.runs[0].knee.front());
  EXPECT_GT(r.knee_centre_offset, 0.01);
  EXPECT_LT(r.knee_centre_offset, 0.05);
  EXPECT_GT(maxDiff(r.runs[2].knee, r.runs[0].knee), 0.1);
  for (const std::string& f : r.files) EXPECT_TRUE(std::filesystem::is_regular_file(f)) << f;
  std::printf("%s", log.str().c_str());
}

}  // namespace
}  // namespace redmax::validation
