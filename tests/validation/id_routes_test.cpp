// The core ID engine's two routes on real trials (converter/id/core_id_engine.hpp): Recursive
// (default: Newton-Euler, GRFs and the muscles' mass points as body wrenches, no M) against
// MassMatrix (tau = M qddot - f, the reference), frame by frame on the tool's own inputs:
//   - set E (gait2392, 23 DoF, 92 muscles: Types I and II with conditional and moving points) and
//     set F (gait10dof18musc, 18 muscles), without muscle mass and with physiological mass in
//     every muscle (20 points each);
//   - the running leg (osim_models/) with physiological mass, wrapping muscles included (smooth
//     model): Types I, II and III.
// Bound 1e-13 of the frame's largest |tau| (the goal was 1e-12); measured worst: set E 1.1e-14
// (massless) and 7.6e-15 (11.5 kg of muscle), set F 1.7e-14 and 1.5e-14, running leg 1.1e-15. Sets E and F skip when ../shared is absent. Credits: OpenSim
// (opensim-org/opensim-models), gait2392 (Delp et al.), gait10dof18musc.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"

namespace redmax::osim {
namespace {

namespace fs = std::filesystem;
using Source = MuscleMassOptions::Source;

std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }
std::string source(const std::string& rel) { return std::string(REDMAX_SOURCE_DIR) + "/" + rel; }

struct RouteDiff {
  double worst = 0.0;       // largest |tau_recursive - tau_M|_inf / |tau_M|_inf over the frames
  double muscle_mass = 0.0;
  int frames = 0;
};

RouteDiff compareRoutes(const IdToolSettings& settings) {
  const InverseDynamicsTool tool(resolveIdSettings(settings));
  CoreIdEngine rec(tool.musculoskeletalModel(), tool.engineOptions());
  CoreIdEngine ref(tool.musculoskeletalModel(), tool.engineOptions());
  ref.setRoute(CoreIdEngine::Route::MassMatrix);
  EXPECT_EQ(rec.route(), CoreIdEngine::Route::Recursive);
  RouteDiff d;
  d.muscle_mass = rec.muscleMass();
  d.frames = tool.numFrames();
  VecX q, v, a, t_rec, t_ref;
  std::vector<IdLoadSample> loads;
  for (int k = 0; k < tool.numFrames(); ++k) {
    const double t = tool.frameTime(k);
    tool.calcInputs(t, q, v, a, loads);
    rec.calcGeneralizedForces(t, q, v, a, loads, t_rec);
    ref.calcGeneralizedForces(t, q, v, a, loads, t_ref);
    d.worst = std::max(d.worst, (t_rec - t_ref).lpNorm<Eigen::Infinity>() / t_ref.lpNorm<Eigen::Infinity>());
  }
  return d;
}

IdToolSettings gaitSet(const std::string& set) {
  IdToolSettings s;
  if (set == "E") {
    s.setup_file = shared("opensim-models/Pipelines/Gait2392_Simbody/subject01_Setup_InverseDynamics.xml");
    s.model_file = shared("opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim");
  } else {
    s.setup_file = shared("opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/walk_Setup_ID.xml");
  }
  return s;
}

void report(const std::string& what, const RouteDiff& d) {
  std::printf("[ measured ] %s: %d frames, muscle mass %.3f kg, recursive vs M route worst %.2e of |tau|\n",
              what.c_str(), d.frames, d.muscle_mass, d.worst);
}

class IdRoutes : public ::testing::TestWithParam<std::string> {};

TEST_P(IdRoutes, RecursiveEqualsMassMatrixWithAndWithoutMuscleMass) {
  IdToolSettings s = gaitSet(GetParam());
  for (const std::string& f : {s.setup_file, s.model_file.value_or("")})
    if (!f.empty() && !fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  const RouteDiff none = compareRoutes(s);
  EXPECT_LE(none.worst, 1e-13);
  report("set " + GetParam() + " without muscle mass", none);
  s.muscle_mass.source = Source::Physiological;
  const RouteDiff mass = compareRoutes(s);
  EXPECT_GT(mass.muscle_mass, 1.0);  // every muscle carries mass (gait2392: about 9 kg)
  EXPECT_LE(mass.worst, 1e-13);
  report("set " + GetParam() + " with physiological mass", mass);
}

INSTANTIATE_TEST_SUITE_P(Sets, IdRoutes, ::testing::Values("E", "F"));

// fibre-following points (placement from each muscle's equilibrium per frame) take the compact
// J_ar route with the fibre's bias acceleration a_z, as MuscleTerm::addForce does
TEST(IdRoutesFibrePlacement, RecursiveEqualsMassMatrixOnSetF) {
  IdToolSettings s = gaitSet("F");
  if (!fs::exists(s.setup_file)) GTEST_SKIP() << "shared OpenSim data not found: " << s.setup_file;
  s.muscle_mass.source = Source::Physiological;
  s.muscle_mass.placement = MuscleMassOptions::Placement::Fibre;
  const RouteDiff d = compareRoutes(s);
  EXPECT_GT(d.muscle_mass, 1.0);
  EXPECT_LE(d.worst, 1e-13);
  report("set F, physiological mass, fibre-following placement", d);
}

TEST(IdRoutesRunningLeg, RecursiveEqualsMassMatrixWithWrappingMuscles) {
  IdToolSettings s;
  s.model_file = source("osim_models/running_leg.osim");
  s.coordinates_file = source("osim_models/running_leg_swing.mot");
  s.muscle_mass.source = Source::Physiological;
  s.muscle_mass.wrap_mass = true;  // the two wrapping muscles carry mass (Type III, smooth)
  const RouteDiff d = compareRoutes(s);
  EXPECT_GT(d.muscle_mass, 0.5);
  EXPECT_LE(d.worst, 1e-13);
  report("running leg, physiological mass, Types I-III", d);
}

}  // namespace
}  // namespace redmax::osim
