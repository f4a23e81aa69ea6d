// Muscles of converted models (converter/build/build_core_model.hpp):
//  - walk_gait1018 (conditional and moving path points, CustomJoint splines, no wraps): the
//    path length of every muscle along the reference trial equals OpenSim 4.4.1's published
//    lengths to 1e-12 m (measured ~3e-16; OpenSim's own test tolerance is 1e-6);
//  - every shared model: lengths at the default pose are positive and finite;
//  - a synthetic model with points on rotated offset frames, on ground, conditional and moving
//    points, against an independent computation (1e-12);
//  - addMusclePointMasses: masses, sizes, rejections.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using test::sharedOpenSim;

// coordinate name from a storage label: "name", ".../name/value" or ".../name"
std::string coordinateOfLabel(const std::string& label) {
  std::string l = label;
  const std::string suffix = "/value";
  if (l.size() > suffix.size() && l.compare(l.size() - suffix.size(), suffix.size(), suffix) == 0)
    l = l.substr(0, l.size() - suffix.size());
  const auto s = l.rfind('/');
  return s == std::string::npos ? l : l.substr(s + 1);
}

TEST(BuildMuscles, WalkGait1018LengthsEqualOpenSims) {
  REDMAX_REQUIRE_SHARED();
  const ModelDescription d =
      readOsimModel(sharedOpenSim("opensim-core/OpenSim/Moco/Test/walk_gait1018_subject01.osim"));
  const Storage motion =
      readStorage(sharedOpenSim("opensim-core/OpenSim/Moco/Test/walk_gait1018_state_reference.mot"));
  const Storage ref = readStorage(sharedOpenSim(
      "opensim-core/OpenSim/Tests/Wrapping/std_testGeometryPathWrapping_walk_gait1018_muscle_lengths.sto"));
  BuildOptions opt;
  opt.constraints = false;
  const BuildResult r = buildCoreModel(d, opt);
  ASSERT_EQ(r.model.muscles().size(), 18u);
  ASSERT_EQ(motion.numRows(), ref.numRows());
  ASSERT_TRUE(motion.in_degrees);

  // map the motion's columns to coordinates; rotational ones are in degrees
  std::vector<int> column_coord(motion.numColumns(), -1);
  std::vector<double> column_scale(motion.numColumns(), 1.0);
  for (int c = 0; c < motion.numColumns(); ++c) {
    const int k = d.findCoordinate(coordinateOfLabel(motion.labels[c]));
    ASSERT_GE(k, 0) << motion.labels[c];
    column_coord[c] = r.coordinate_index[k];
    if (d.coordinates[k].motion_type == MotionType::Rotational) column_scale[c] = std::numbers::pi / 180;
  }
  std::vector<int> ref_column(r.model.muscles().size());
  for (size_t m = 0; m < r.model.muscles().size(); ++m) {
    ref_column[m] = ref.findColumn("/forceset/" + r.model.muscles()[m].name + "|length");
    ASSERT_GE(ref_column[m], 0) << r.model.muscles()[m].name;
  }

  std::vector<double> max_err(r.model.muscles().size(), 0.0);
  std::vector<Mat4> E;
  for (int row = 0; row < motion.numRows(); ++row) {
    ASSERT_NEAR(motion.time[row], ref.time[row], 1e-6);
    VecX q = r.model.skeleton().defaultQ();  // coordinates absent from the file keep their defaults
    for (int c = 0; c < motion.numColumns(); ++c) q[column_coord[c]] = motion.data(row, c) * column_scale[c];
    calcBodyPoses(r.model, q, E);
    for (size_t m = 0; m < r.model.muscles().size(); ++m) {
      const double l = calcPathLength(r.model, r.model.muscles()[m].path, q, E);
      max_err[m] = std::max(max_err[m], std::abs(l - ref.data(row, ref_column[m])));
    }
  }
  for (size_t m = 0; m < r.model.muscles().size(); ++m)
    EXPECT_LT(max_err[m], 1e-12) << r.model.muscles()[m].name << ": max |l - l_OpenSim| = " << max_err[m] << " m";
}

TEST(BuildMuscles, EverySharedModelHasPositiveLengthsAtTheDefaultPose) {
  REDMAX_REQUIRE_SHARED();
  for (const char* path :
       {"opensim-models/Models/Arm26/arm26.osim", "opensim-models/Models/Tug_of_War/Tug_of_War.osim",
        "opensim-models/Models/Leg6Dof9Musc/leg6dof9musc.osim", "opensim-models/Models/Leg39/leg39.osim",
        "opensim-models/Models/Gait10dof18musc/gait10dof18musc.osim",
        "opensim-models/Models/Gait2354_Simbody/gait2354_simbody.osim",
        "opensim-models/Models/Gait2392_Simbody/gait2392_millard2012muscle.osim",
        "opensim-models/Models/Hamner/FullBodyModel_Hamner2010_v2_0.osim",
        "opensim-models/Models/Rajagopal/Rajagopal2016.osim", "opensim-models/Models/WristModel/wrist.osim",
        "opensim-core/OpenSim/Tests/shared/ThoracoscapularShoulderModel.osim",
        "opensim-core/OpenSim/Tests/Wrapping/testGeometryPathWrapping_ShoulderWrappingWithPathSprings.osim",
        "opensim-core/OpenSim/Simulation/Test/CoupledCoordinatesMPPsMomentArmTest.osim",
        "opensim-core/OpenSim/Simulation/Test/testMomentArmsConstraintB.osim"}) {
    const ModelDescription d = readOsimModel(sharedOpenSim(path));
    const BuildResult r = buildCoreModel(d);
    ASSERT_EQ(r.model.muscles().size(), d.muscles.size()) << path;
    const VecX q = r.model.skeleton().defaultQ();
    std::vector<Mat4> E;
    calcBodyPoses(r.model, q, E);
    for (size_t m = 0; m < r.model.muscles().size(); ++m) {
      const double l = calcPathLength(r.model, r.model.muscles()[m].path, q, E);
      EXPECT_TRUE(std::isfinite(l) && l > 0.0) << path << " " << r.model.muscles()[m].name << " " << l;
      // path type and wrap count as the description says
      const PathForceDesc& pf = d.muscles[r.muscle_source[m]];
      EXPECT_EQ(r.model.muscles()[m].path.num_wraps, static_cast<int>(pf.wraps.size()));
      EXPECT_EQ(std::string(pathTypeName(pathType(r.model.muscles()[m].path))), toString(pf.path_type))
          << path << " " << pf.name;
    }
  }
}

// a model whose path points sit on rotated offset frames, on ground, and move with a coordinate
TEST(BuildMuscles, PointsInOffsetFramesMovingAndConditionalPoints) {
  const std::string bodies =
      "<Body name=\"a\"><mass>1</mass><mass_center>0 0 0</mass_center><inertia>1 1 1 0 0 0</inertia>"
      "<components><PhysicalOffsetFrame name=\"site\"><socket_parent>/bodyset/a</socket_parent>"
      "<translation>0.1 0.2 -0.05</translation><orientation>0.3 -0.4 0.5</orientation>"
      "</PhysicalOffsetFrame></components></Body>\n";
  const std::string joints =
      "<PinJoint name=\"pin\"><socket_parent_frame>/ground</socket_parent_frame>"
      "<socket_child_frame>/bodyset/a</socket_child_frame><coordinates><Coordinate name=\"q\">"
      "<default_value>0.3</default_value><range>-1 1</range></Coordinate></coordinates></PinJoint>\n";
  const std::string forces =
      "<ForceSet><objects><PathSpring name=\"spring\"><GeometryPath name=\"path\"><PathPointSet><objects>\n"
      "<PathPoint name=\"p0\"><socket_parent_frame>/ground</socket_parent_frame>"
      "<location>0 1 0</location></PathPoint>\n"
      "<ConditionalPathPoint name=\"p1\"><socket_parent_frame>/bodyset/a/site</socket_parent_frame>"
      "<location>0.2 0 0</location><socket_coordinate>/jointset/pin/q</socket_coordinate>"
      "<range>0 0.5</range></ConditionalPathPoint>\n"
      "<MovingPathPoint name=\"p2\"><socket_parent_frame>/bodyset/a/site</socket_parent_frame>"
      "<socket_x_coordinate>/jointset/pin/q</socket_x_coordinate>"
      "<socket_y_coordinate>/jointset/pin/q</socket_y_coordinate>"
      "<socket_z_coordinate>/jointset/pin/q</socket_z_coordinate>"
      "<x_location><LinearFunction><coefficients>0.5 0.1</coefficients></LinearFunction></x_location>"
      "<y_location><Constant><value>-0.3</value></Constant></y_location>"
      "<z_location><PolynomialFunction><coefficients>0.2 0 0.05</coefficients></PolynomialFunction></z_location>"
      "</MovingPathPoint>\n"
      "</objects></PathPointSet></GeometryPath><resting_length>0.5</resting_length>"
      "<stiffness>10</stiffness><dissipation>0.1</dissipation></PathSpring></objects></ForceSet>\n";
  test::TempDir dir;
  const ModelDescription d =
      readOsimModel(dir.write("m.osim", test::modernOsim(bodies, joints, forces)));
  const BuildResult r = buildCoreModel(d);
  ASSERT_EQ(r.model.muscles().size(), 1u);
  const MusclePath& path = r.model.muscles()[0].path;
  ASSERT_EQ(path.points.size(), 3u);
  EXPECT_EQ(path.points[1].kind, redmax::PathPointKind::Conditional);
  EXPECT_EQ(path.points[2].kind, redmax::PathPointKind::Moving);

  const Mat4 X_site = makePose(Vec3(0.1, 0.2, -0.05), Vec3(0.3, -0.4, 0.5));
  for (double q : {0.3, 0.7, 1.4, -0.8}) {
    // independent: body pose Rz(q); site points x_a = X_site x_site; moving f(clamp(q, -1, 1))
    const Mat4 X_GA = makeE(Eigen::AngleAxisd(q, Vec3::UnitZ()).toRotationMatrix(), Vec3::Zero());
    const double qc = std::clamp(q, -1.0, 1.0);
    const Vec3 f(0.5 * qc + 0.1, -0.3, 0.2 * qc * qc + 0.05);
    const Vec3 p0(0, 1, 0);
    const Vec3 p1 = transformPoint(X_GA * X_site, Vec3(0.2, 0, 0));
    const Vec3 p2 = transformPoint(X_GA * X_site, f);
    const bool active = q >= -1e-5 && q <= 0.5 + 1e-5;
    const double expected = active ? (p1 - p0).norm() + (p2 - p1).norm() : (p2 - p0).norm();
    VecX qv = VecX::Constant(1, q);
    std::vector<Mat4> E;
    calcBodyPoses(r.model, qv, E);
    EXPECT_NEAR(calcPathLength(r.model, path, qv, E), expected, 1e-12) << "q = " << q;
  }
}

TEST(BuildMuscles, PointMassesAreAddedOnRequest) {
  REDMAX_REQUIRE_SHARED();
  const ModelDescription d =
      readOsimModel(sharedOpenSim("opensim-models/Models/Gait10dof18musc/gait10dof18musc.osim"));
  const BuildResult r = buildCoreModel(d);
  for (const Muscle& m : r.model.muscles()) EXPECT_EQ(m.mass_points.size(), 0);  // massless as built
  std::vector<double> masses(r.model.muscles().size());
  for (size_t k = 0; k < masses.size(); ++k) masses[k] = k == 3 ? 0.0 : 0.1 * (k + 1);
  MassPointOptions opt;
  opt.count = 7;
  const std::vector<Muscle> with = addMusclePointMasses(r.model.muscles(), masses, opt);
  ASSERT_EQ(with.size(), r.model.muscles().size());
  for (size_t k = 0; k < with.size(); ++k) {
    EXPECT_EQ(with[k].mass_points.size(), k == 3 ? 0 : 7);
    EXPECT_NEAR(with[k].mass_points.totalMass(), masses[k], 1e-15);
  }
  EXPECT_THROW(addMusclePointMasses(r.model.muscles(), {1.0}), ModelError);
  masses[0] = -1.0;
  EXPECT_THROW(addMusclePointMasses(r.model.muscles(), masses), ModelError);
  // a wrapping (Type III) muscle stays lumped
  const ModelDescription arm = readOsimModel(sharedOpenSim("opensim-models/Models/Arm26/arm26.osim"));
  const BuildResult ra = buildCoreModel(arm);
  std::vector<double> m(ra.model.muscles().size(), 0.0);
  for (size_t k = 0; k < m.size(); ++k)
    if (ra.model.muscles()[k].path.num_wraps > 0) m[k] = 0.2;
  EXPECT_THROW(addMusclePointMasses(ra.model.muscles(), m), ModelError);
}

}  // namespace
}  // namespace redmax::osim
