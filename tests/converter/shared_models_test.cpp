// Every model of docs/shared_data.md's table loads with the table's numbers; the
// multibody-tree coordinate order matches OpenSim 4.6's inverse-dynamics column order; legacy
// files read with OpenSim's upgrades equal the copies OpenSim itself upgraded.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using test::sharedOpenSim;

struct Expected {
  const char* path;
  int version, bodies, coordinates, locked;  // locked -1: the table does not say
  int path_forces;
  const char* force_class;  // "" when there are none
  int couplers, conditional, moving;
  int cylinders, spheres, ellipsoids, tori;
  int type1, type2, type3;  // path types, counted independently from the XML (see report)
  std::vector<std::string> joint_types;
};

// numbers from docs/shared_data.md's models table; path-type counts from an
// independent ElementTree count of PathPointSet/PathWrapSet contents
const std::vector<Expected>& expectedModels() {
  static const std::vector<Expected> e = {
      {"opensim-models/Models/Arm26/arm26.osim", 40000, 3, 2, 0, 6, "Thelen2003Muscle", 0, 0, 0,
       2, 0, 2, 0, 0, 1, 5, {"CustomJoint", "WeldJoint"}},
      {"opensim-models/Models/DoublePendulum/double_pendulum.osim", 40000, 2, 2, 0, 0, "", 0, 0,
       0, 0, 0, 0, 0, 0, 0, 0, {"PinJoint"}},
      {"opensim-models/Models/Pendulum/double_pendulum.osim", 40000, 2, 2, 0, 0, "", 0, 0, 0, 0,
       0, 0, 0, 0, 0, 0, {"PinJoint"}},
      {"opensim-core/OpenSim/Tools/Test/double_pendulum33.osim", 30000, 2, 2, 0, 0, "", 0, 0, 0,
       0, 0, 0, 0, 0, 0, 0, {"PinJoint"}},
      {"opensim-models/Models/Tug_of_War/Tug_of_War.osim", 40000, 1, 1, 0, 2, "Thelen2003Muscle",
       0, 0, 0, 0, 0, 0, 0, 2, 0, 0, {"SliderJoint"}},
      {"opensim-models/Models/Tug_of_War/Tug_of_War_Millard.osim", 40000, 1, 1, 0, 2,
       "Millard2012EquilibriumMuscle", 0, 0, 0, 0, 0, 0, 0, 2, 0, 0, {"SliderJoint"}},
      {"opensim-models/Models/Leg6Dof9Musc/leg6dof9musc.osim", 40000, 7, 7, -1, 9,
       "Thelen2003Muscle", 1, 4, 2, 0, 0, 0, 0, 1, 8, 0, {"CustomJoint", "WeldJoint"}},
      {"opensim-models/Models/Leg39/leg39.osim", 40000, 7, 14, 3, 9, "Thelen2003Muscle", 5, 4, 2,
       0, 0, 0, 0, 1, 8, 0, {"CustomJoint"}},
      {"opensim-models/Models/Gait10dof18musc/gait10dof18musc.osim", 40000, 12, 10, -1, 18,
       "Millard2012EquilibriumMuscle", 0, 8, 4, 0, 0, 0, 0, 2, 16, 0,
       {"PinJoint", "CustomJoint", "WeldJoint"}},
      {"opensim-models/Models/Gait2354_Simbody/gait2354_simbody.osim", 40000, 12, 23, -1, 54,
       "Thelen2003Muscle", 0, 12, 4, 0, 0, 0, 0, 22, 32, 0, {"CustomJoint"}},
      {"opensim-models/Models/Gait2392_Simbody/gait2392_thelen2003muscle.osim", 40000, 12, 23, -1,
       92, "Thelen2003Muscle", 0, 26, 8, 0, 0, 0, 0, 36, 56, 0, {"CustomJoint"}},
      {"opensim-models/Models/Gait2392_Simbody/gait2392_millard2012muscle.osim", 40000, 12, 23,
       -1, 92, "Millard2012EquilibriumMuscle", 0, 26, 8, 0, 0, 0, 0, 36, 56, 0, {"CustomJoint"}},
      {"opensim-models/Models/Hamner/FullBodyModel_Hamner2010_v2_0.osim", 40000, 20, 37, 8, 92,
       "Thelen2003Muscle", 0, 26, 8, 0, 0, 0, 0, 36, 56, 0, {"CustomJoint"}},
      {"opensim-models/Models/Rajagopal/Rajagopal2016.osim", 40000, 22, 39, 8, 80,
       "Millard2012EquilibriumMuscle", 2, 0, 0, 40, 0, 0, 0, 14, 24, 42,
       {"PinJoint", "CustomJoint", "UniversalJoint"}},
      {"opensim-models/Models/Rajagopal/RajagopalLaiUhlrich2023.osim", 40000, 22, 39, 8, 80,
       "Millard2012EquilibriumMuscle", 2, 0, 0, 44, 0, 0, 0, 14, 24, 42,
       {"PinJoint", "CustomJoint", "UniversalJoint"}},
      {"opensim-models/Models/WristModel/wrist.osim", 40000, 28, 14, -1, 25,
       "Schutte1993Muscle_Deprecated", 4, 54, 0, 0, 0, 0, 0, 0, 25, 0,
       {"CustomJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Tests/shared/ThoracoscapularShoulderModel.osim", 40000, 7, 17, -1,
       33, "Millard2012EquilibriumMuscle", 0, 0, 5, 4, 2, 4, 0, 3, 0, 30,
       {"CustomJoint", "ScapulothoracicJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Tests/Wrapping/"
       "testGeometryPathWrapping_ShoulderWrappingWithPathSprings.osim",
       30000, 7, 10, -1, 103, "PathSpring", 0, 0, 9, 3, 2, 5, 3, 9, 0, 94,
       {"CustomJoint", "EllipsoidJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Tools/Test/test_wrapAllVis.osim", 30000, 4, 5, -1, 1,
       "Thelen2003Muscle", 0, 0, 0, 3, 1, 1, 1, 0, 0, 1, {"CustomJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Tests/Wrapping/testWrapObject_updateFromXMLNode30515.osim", 20302, 0,
       0, 0, 0, "", 0, 0, 0, 1, 1, 1, 0, 0, 0, 0, {}},
      {"opensim-core/OpenSim/Moco/Test/subject_walk_armless_18musc.osim", 30000, 14, 25, -1, 18,
       "Millard2012EquilibriumMuscle", 2, 0, 0, 40, 0, 0, 0, 2, 2, 14,
       {"PinJoint", "CustomJoint"}},
      {"opensim-core/OpenSim/Moco/Test/walk_gait1018_subject01.osim", 30000, 12, 10, -1, 18,
       "Millard2012EquilibriumMuscle", 0, 8, 4, 0, 0, 0, 0, 2, 16, 0,
       {"PinJoint", "CustomJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/P2PBallJointMomentArmTest.osim", 20001, 2, 3, 0, 1,
       "Thelen2003Muscle", 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, {"BallJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/P2PBallCustomJointMomentArmTest.osim", 20001, 2, 3, 0,
       1, "Thelen2003Muscle", 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, {"CustomJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/P2PCustomJointMomentArmTest.osim", 20001, 2, 1, 0, 1,
       "Thelen2003Muscle", 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, {"CustomJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/MovingPathPointMomentArmTest.osim", 20001, 2, 1, 0, 1,
       "Thelen2003Muscle", 0, 1, 1, 0, 0, 0, 0, 0, 1, 0, {"PinJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/MovingPointCustomJointMomentArmTest.osim", 20001, 2, 1,
       0, 1, "Thelen2003Muscle", 0, 1, 1, 0, 0, 0, 0, 0, 1, 0, {"CustomJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/WrapPathCustomJointMomentArmTest.osim", 20001, 2, 1,
       0, 1, "Thelen2003Muscle", 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, {"CustomJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/PathOnConstrainedBodyMomentArmTest.osim", 20001, 3, 6,
       -1, 1, "Thelen2003Muscle", 5, 1, 0, 0, 0, 0, 0, 0, 1, 0, {"CustomJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/MultipleMPPsMomentArmTest.osim", 30000, 3, 2, -1, 1,
       "Thelen2003Muscle", 0, 1, 2, 0, 0, 0, 0, 0, 1, 0, {"PinJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/CoupledCoordinatesMPPsMomentArmTest.osim", 30000, 4,
       5, -1, 1, "Thelen2003Muscle", 2, 1, 2, 0, 0, 0, 0, 0, 1, 0,
       {"PinJoint", "PlanarJoint", "WeldJoint"}},
      {"opensim-core/OpenSim/Simulation/Test/testMomentArmsConstraintB.osim", 30000, 4, 11, -1, 4,
       "Thelen2003Muscle", 1, 6, 0, 0, 0, 0, 0, 0, 4, 0, {"CustomJoint"}},
      // the models that produced the published inverse-dynamics results (sets A, E, F)
      {"opensim-models@a26e12c/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim",
       20303, 2, 2, 0, 6, "Thelen2003Muscle", 0, 0, 0, 2, 0, 2, 0, 0, 1, 5, {"CustomJoint"}},
      {"opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim",
       20303, 12, 23, 0, 92, "Thelen2003Muscle", 0, 26, 8, 0, 0, 0, 0, 36, 56, 0,
       {"CustomJoint"}},
      {"opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim", 30000,
       12, 10, 0, 18, "Millard2012EquilibriumMuscle", 0, 8, 4, 0, 0, 0, 0, 2, 16, 0,
       {"PinJoint", "CustomJoint", "WeldJoint"}},
      {"opensim-models/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim", 40000,
       12, 23, 0, 92, "Thelen2003Muscle", 0, 26, 8, 0, 0, 0, 0, 36, 56, 0, {"CustomJoint"}},
      {"opensim-models/Pipelines/Gait10dof18musc/OutputReference/subject01.osim", 40000, 12, 10,
       0, 18, "Millard2012EquilibriumMuscle", 0, 8, 4, 0, 0, 0, 0, 2, 16, 0,
       {"PinJoint", "CustomJoint", "WeldJoint"}},
      {"opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim", 40000, 3, 2,
       0, 6, "Thelen2003Muscle", 0, 0, 0, 2, 0, 2, 0, 0, 1, 5, {"CustomJoint", "WeldJoint"}},
  };
  return e;
}

class SharedModels : public ::testing::TestWithParam<Expected> {};

TEST_P(SharedModels, LoadsWithTheTablesNumbers) {
  REDMAX_REQUIRE_SHARED();
  const Expected& e = GetParam();
  const ModelDescription d = readOsimModel(sharedOpenSim(e.path));
  EXPECT_EQ(d.osim_version, e.version);
  EXPECT_EQ(static_cast<int>(d.bodies.size()), e.bodies);
  EXPECT_EQ(d.numDofs(), e.coordinates);
  if (e.locked >= 0) {
    int locked = 0;
    for (const auto& c : d.coordinates) locked += c.locked;
    EXPECT_EQ(locked, e.locked);
  }
  EXPECT_EQ(static_cast<int>(d.muscles.size()), e.path_forces);
  int cond = 0, moving = 0, types[3] = {0, 0, 0};
  for (const auto& m : d.muscles) {
    EXPECT_EQ(m.class_name, e.force_class) << m.name;
    types[static_cast<int>(m.path_type)]++;
    for (const auto& p : m.points) {
      cond += p.kind == PathPointKind::Conditional;
      moving += p.kind == PathPointKind::Moving;
    }
    // every path point and wrap is attached to a body of the model
    for (const auto& p : m.points)
      EXPECT_TRUE(p.body == d.ground_name || d.findBody(p.body) >= 0) << m.name << " " << p.name;
    for (const auto& w : m.wraps) EXPECT_GE(w.wrap_index, 0);
  }
  EXPECT_EQ(cond, e.conditional);
  EXPECT_EQ(moving, e.moving);
  EXPECT_EQ(types[0], e.type1);
  EXPECT_EQ(types[1], e.type2);
  EXPECT_EQ(types[2], e.type3);
  int couplers = 0;
  for (const auto& c : d.constraints) couplers += c.kind == ConstraintKind::CoordinateCoupler;
  EXPECT_EQ(couplers, e.couplers);
  std::map<std::string, int> wraps;
  for (const auto& w : d.wrap_objects) wraps[w.type]++;
  EXPECT_EQ(wraps["WrapCylinder"], e.cylinders);
  EXPECT_EQ(wraps["WrapSphere"], e.spheres);
  EXPECT_EQ(wraps["WrapEllipsoid"], e.ellipsoids);
  EXPECT_EQ(wraps["WrapTorus"], e.tori);
  std::set<std::string> types_seen;
  for (const auto& j : d.joints) types_seen.insert(j.type);
  EXPECT_EQ(types_seen, std::set<std::string>(e.joint_types.begin(), e.joint_types.end()));
  // structural invariants: every coordinate belongs to exactly one joint slot, q order is a
  // permutation, every joint is a mobilizer (no loops in these models)
  std::vector<int> seen(d.coordinates.size(), 0);
  for (const auto& j : d.joints)
    for (int c : j.coordinates) seen.at(c)++;
  for (int s : seen) EXPECT_EQ(s, 1);
  EXPECT_EQ(d.tree.mobilizers.size(), d.joints.size());
  for (const auto& c : d.coordinates) EXPECT_NE(c.motion_type, MotionType::Undefined) << c.name;
}

INSTANTIATE_TEST_SUITE_P(Table, SharedModels, ::testing::ValuesIn(expectedModels()),
                         [](const ::testing::TestParamInfo<Expected>& i) {
                           std::string n = std::to_string(i.index) + "_" + i.param.path;
                           for (auto& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

std::vector<std::string> coordinateNames(const ModelDescription& d) {
  std::vector<std::string> v;
  for (const auto& c : d.coordinates) v.push_back(c.name);
  return v;
}

// the coordinate names of an OpenSim ID output, in column order, suffixes removed
std::vector<std::string> idColumns(const std::string& sto) {
  const Storage s = readStorage(sto);
  std::vector<std::string> v;
  for (auto l : s.labels) {
    for (const char* suffix : {"_moment", "_force"}) {
      const std::string sx = suffix;
      if (l.size() > sx.size() && l.compare(l.size() - sx.size(), sx.size(), sx) == 0) {
        l = l.substr(0, l.size() - sx.size());
        break;
      }
    }
    v.push_back(l);
  }
  return v;
}

TEST(TreeOrder, Gait2392MatchesOpenSim46ColumnOrder) {
  REDMAX_REQUIRE_SHARED();
  // E.sto was written by OpenSim 4.6 from the 2017 model: its columns are the q order
  const auto expected = idColumns(sharedOpenSim("opensim-4.6-results/E.sto"));
  ASSERT_EQ(expected.size(), 23u);
  for (const char* model :
       {"opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim",
        "opensim-models/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim",
        "opensim-models/Models/Gait2392_Simbody/gait2392_thelen2003muscle.osim"}) {
    const ModelDescription d = readOsimModel(sharedOpenSim(model));
    EXPECT_EQ(coordinateNames(d), expected) << model;
  }
  // and the level structure of §3.1: pelvis, then hips and back, knees, ankles, ...
  const ModelDescription d = readOsimModel(sharedOpenSim(
      "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim"));
  std::vector<std::pair<std::string, int>> levels;
  for (const auto& m : d.tree.mobilizers) {
    levels.emplace_back(d.joints[m.joint].name, m.level);
    EXPECT_FALSE(m.reversed);
  }
  const std::vector<std::pair<std::string, int>> want = {
      {"ground_pelvis", 1}, {"hip_r", 2},      {"hip_l", 2},      {"back", 2},
      {"knee_r", 3},        {"knee_l", 3},     {"ankle_r", 4},    {"ankle_l", 4},
      {"subtalar_r", 5},    {"subtalar_l", 5}, {"mtp_r", 6},      {"mtp_l", 6}};
  EXPECT_EQ(levels, want);
}

TEST(TreeOrder, Gait10dofAndArm26MatchOpenSim46ColumnOrder) {
  REDMAX_REQUIRE_SHARED();
  const auto f = idColumns(sharedOpenSim("opensim-4.6-results/F.sto"));
  for (const char* model :
       {"opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim",
        "opensim-models/Pipelines/Gait10dof18musc/OutputReference/subject01.osim"})
    EXPECT_EQ(coordinateNames(readOsimModel(sharedOpenSim(model))), f) << model;
  const auto a = idColumns(sharedOpenSim("opensim-4.6-results/A-filtered.sto"));
  EXPECT_EQ(coordinateNames(readOsimModel(sharedOpenSim(
                "opensim-models@a26e12c/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim"))),
            a);
}

TEST(TreeOrder, OpenSim3OutputsUseAnotherOrderWithTheSameNames) {
  REDMAX_REQUIRE_SHARED();
  // OpenSim 3.x wrote BodySet depth-first order: same names, different order (match by name)
  const auto old = idColumns(sharedOpenSim(
      "opensim-models/Pipelines/Gait2392_Simbody/OutputReference/ResultsInverseDynamics/"
      "InverseDynamicsOutput.sto"));
  const auto now = coordinateNames(readOsimModel(sharedOpenSim(
      "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim")));
  EXPECT_NE(old, now);
  EXPECT_EQ(std::set<std::string>(old.begin(), old.end()),
            std::set<std::string>(now.begin(), now.end()));
}

// ---------------------------------------------------------------------------------------------

void expectSameGeometry(const ModelDescription& a, const ModelDescription& b,
                        const std::set<std::string>& skip_bodies = {}) {
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    EXPECT_EQ(a.bodies[i].name, b.bodies[i].name);
    EXPECT_EQ(a.bodies[i].mass, b.bodies[i].mass) << a.bodies[i].name;
    EXPECT_EQ(a.bodies[i].mass_center, b.bodies[i].mass_center) << a.bodies[i].name;
    if (!skip_bodies.count(a.bodies[i].name)) {
      EXPECT_EQ(a.bodies[i].inertia, b.bodies[i].inertia) << a.bodies[i].name;
    }
  }
  ASSERT_EQ(a.joints.size(), b.joints.size());
  for (size_t i = 0; i < a.joints.size(); ++i) {
    const auto& ja = a.joints[i];
    const auto& jb = b.joints[i];
    EXPECT_EQ(ja.name, jb.name);
    EXPECT_EQ(ja.type, jb.type);
    EXPECT_EQ(ja.parent_body, jb.parent_body);
    EXPECT_EQ(ja.child_body, jb.child_body);
    EXPECT_EQ(ja.parent_frame, jb.parent_frame);
    EXPECT_EQ(ja.child_frame, jb.child_frame);
    // OpenSim wrote the 4.0 copy from its 6-digit upgrade: the poses agree to the last bit
    EXPECT_TRUE((ja.X_PF - jb.X_PF).cwiseAbs().maxCoeff() <= 1e-15) << ja.name;
    EXPECT_TRUE((ja.X_BM - jb.X_BM).cwiseAbs().maxCoeff() <= 1e-15) << ja.name;
  }
  ASSERT_EQ(a.coordinates.size(), b.coordinates.size());
  for (size_t i = 0; i < a.coordinates.size(); ++i) {
    EXPECT_EQ(a.coordinates[i].name, b.coordinates[i].name);
    EXPECT_EQ(a.coordinates[i].motion_type, b.coordinates[i].motion_type) << a.coordinates[i].name;
    EXPECT_EQ(a.coordinates[i].range_min, b.coordinates[i].range_min);
    EXPECT_EQ(a.coordinates[i].range_max, b.coordinates[i].range_max);
  }
  ASSERT_EQ(a.muscles.size(), b.muscles.size());
  for (size_t i = 0; i < a.muscles.size(); ++i) {
    const auto& ma = a.muscles[i];
    const auto& mb = b.muscles[i];
    EXPECT_EQ(ma.name, mb.name);
    EXPECT_EQ(ma.max_isometric_force, mb.max_isometric_force);
    EXPECT_EQ(ma.optimal_fiber_length, mb.optimal_fiber_length);
    EXPECT_EQ(ma.tendon_slack_length, mb.tendon_slack_length);
    EXPECT_EQ(ma.pennation_angle_at_optimal, mb.pennation_angle_at_optimal);
    ASSERT_EQ(ma.points.size(), mb.points.size()) << ma.name;
    for (size_t k = 0; k < ma.points.size(); ++k) {
      EXPECT_EQ(ma.points[k].kind, mb.points[k].kind);
      EXPECT_EQ(ma.points[k].body, mb.points[k].body);
      EXPECT_EQ(ma.points[k].coordinate, mb.points[k].coordinate);
      EXPECT_EQ(ma.points[k].range_min, mb.points[k].range_min);
      if (ma.points[k].kind != PathPointKind::Moving) {
        EXPECT_EQ(ma.points[k].location, mb.points[k].location) << ma.name << " " << k;
      }
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(ma.points[k].location_coordinates[c], mb.points[k].location_coordinates[c]);
        EXPECT_EQ(ma.points[k].location_functions[c].y, mb.points[k].location_functions[c].y);
      }
    }
  }
}

TEST(LegacyUpgrade, Gait10dofVersion30000EqualsOpenSimsOwn40000Upgrade) {
  REDMAX_REQUIRE_SHARED();
  // the 2017 file (30000) and the copy OpenSim re-saved in the 4.0 format describe the same model
  const auto a = readOsimModel(
      sharedOpenSim("opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim"));
  const auto b = readOsimModel(
      sharedOpenSim("opensim-models/Pipelines/Gait10dof18musc/OutputReference/subject01.osim"));
  EXPECT_EQ(a.osim_version, 30000);
  EXPECT_EQ(b.osim_version, 40000);
  expectSameGeometry(a, b);
}

TEST(LegacyUpgrade, Gait2392Version20303EqualsTheCurrentCopyExceptTheToes) {
  REDMAX_REQUIRE_SHARED();
  const auto a = readOsimModel(sharedOpenSim(
      "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim"));
  const auto b = readOsimModel(
      sharedOpenSim("opensim-models/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim"));
  // docs/shared_data.md: the toes' Iyy changed in 2024; everything else is the upgrade of the same data
  expectSameGeometry(a, b, {"toes_r", "toes_l"});
  const int t = a.findBody("toes_r");
  EXPECT_NE(a.bodies[t].inertia[1], b.bodies[t].inertia[1]);
}

TEST(LegacyUpgrade, SixDigitRoundingOfInertiaAndJointOffsets) {
  REDMAX_REQUIRE_SHARED();
  // semantics §1.4's own example: 0.10423309 -> 0.104233 and the hip offset triple
  const auto d = readOsimModel(sharedOpenSim(
      "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim"));
  const auto& pelvis = d.bodies[d.findBody("pelvis")];
  EXPECT_EQ(pelvis.inertia[0], 0.104233);
  EXPECT_EQ(pelvis.mass, 11.37517129);  // mass is not rewritten, so not rounded
  const auto& hip = d.joints[d.findJoint("hip_r")];
  EXPECT_EQ(hip.X_PF(0, 3), -0.0724376);
  EXPECT_EQ(hip.X_PF(1, 3), -0.0677245);
  EXPECT_EQ(hip.X_PF(2, 3), 0.0855522);
  EXPECT_EQ(hip.parent_frame, "/jointset/hip_r/pelvis_offset");
  EXPECT_EQ(hip.child_frame, "/jointset/hip_r/femur_r_offset");
  // legacy MultiplierFunction(LinearFunction) translations are not a LinearFunction: Coupled
  EXPECT_EQ(d.coordinates[d.findCoordinate("pelvis_tx")].motion_type, MotionType::Coupled);
  EXPECT_EQ(d.coordinates[d.findCoordinate("pelvis_tilt")].motion_type, MotionType::Rotational);
  // the old motion_type element is kept only as information
  EXPECT_EQ(d.coordinates[d.findCoordinate("pelvis_tx")].legacy_motion_type, "translational");
}

TEST(SharedModels, JointAndFrameDetails) {
  REDMAX_REQUIRE_SHARED();
  {
    // ScapulothoracicJoint parameters and the AC PointConstraint
    const auto d = readOsimModel(
        sharedOpenSim("opensim-core/OpenSim/Tests/shared/ThoracoscapularShoulderModel.osim"));
    const auto& st = d.joints[d.findJoint("scapulothoracic")];
    EXPECT_EQ(st.kind, JointKind::Scapulothoracic);
    EXPECT_EQ(st.coordinates.size(), 4u);
    EXPECT_EQ(st.radii, Vec3(0.082997500000000002, 0.199991, 0.083001000000000005));
    EXPECT_EQ(d.coordinates[st.coordinates[0]].name, "scapula_abduction");
    EXPECT_EQ(d.coordinates[st.coordinates[3]].name, "scapula_winging");
    ASSERT_EQ(d.constraints.size(), 1u);
    const auto& ac = d.constraints[0];
    EXPECT_EQ(ac.kind, ConstraintKind::Point);
    EXPECT_EQ(ac.body1, "clavicle");
    EXPECT_EQ(ac.body2, "scapula");
    EXPECT_EQ(ac.location1, Vec3(-0.029239999999999999, 0.020240000000000001, 0.12005));
    // the thorax_offset orientation (0, -0.87, 0) is a rotation about y
    const Mat3 R = st.X_PF.topLeftCorner<3, 3>();
    EXPECT_NEAR(R(0, 0), std::cos(-0.87), 1e-15);
    EXPECT_NEAR(R(0, 2), std::sin(-0.87), 1e-15);
  }
  {
    // EllipsoidJoint radii; tori; legacy offset orientation (0 -0.87 -0.6) body-fixed XYZ
    const auto d = readOsimModel(sharedOpenSim(
        "opensim-core/OpenSim/Tests/Wrapping/"
        "testGeometryPathWrapping_ShoulderWrappingWithPathSprings.osim"));
    const auto& j = d.joints[d.findJoint("scapulothoracic")];
    EXPECT_EQ(j.kind, JointKind::Ellipsoid);
    EXPECT_EQ(j.radii, Vec3(0.09, 0.27, 0.08));
    const Mat3 R = j.X_BM.topLeftCorner<3, 3>();
    const Mat3 want = (Eigen::AngleAxisd(-0.87, Vec3::UnitY()) *
                       Eigen::AngleAxisd(-0.6, Vec3::UnitZ())).toRotationMatrix();
    EXPECT_LE((R - want).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_EQ(Vec3(j.X_BM.topRightCorner<3, 1>()), Vec3(-0.05982, -0.03904, -0.056));
    int tori = 0;
    for (const auto& w : d.wrap_objects)
      if (w.type == "WrapTorus") {
        ++tori;
        EXPECT_GT(w.outer_radius, w.inner_radius);
      }
    EXPECT_EQ(tori, 3);
  }
  {
    // UniversalJoint and PolynomialFunction (decreasing powers, stored as written)
    const auto d = readOsimModel(
        sharedOpenSim("opensim-models/Models/Rajagopal/RajagopalLaiUhlrich2023.osim"));
    const auto& u = d.joints[d.findJoint("radius_hand_r")];
    EXPECT_EQ(u.kind, JointKind::Universal);
    ASSERT_EQ(u.coordinates.size(), 2u);
    for (int c : u.coordinates) EXPECT_EQ(d.coordinates[c].motion_type, MotionType::Rotational);
    const auto& knee = d.joints[d.findJoint("walker_knee_r")];
    bool poly = false;
    for (const auto& ax : knee.spatial_transform)
      if (ax.function.kind == FunctionKind::Polynomial && ax.function.coefficients.size() == 4) {
        poly = true;
        EXPECT_EQ(ax.function.coefficients[0], 0.025165762727423002);
      }
    EXPECT_TRUE(poly);
    // the patella coupler's dependent coordinate exists and is coupled to knee_angle_r
    bool found = false;
    for (const auto& c : d.constraints)
      if (c.kind == ConstraintKind::CoordinateCoupler && c.independent_coordinates.size() == 1 &&
          c.independent_coordinates[0] == "knee_angle_r") {
        found = true;
        EXPECT_GE(d.findCoordinate(c.dependent_coordinate), 0);
      }
    EXPECT_TRUE(found);
  }
  {
    // Multiplier(Constant) in the named form with a wrapper inner function
    const auto d = readOsimModel(sharedOpenSim("opensim-models/Models/Leg6Dof9Musc/leg6dof9musc.osim"));
    const auto& gp = d.joints[0];
    bool multiplier = false;
    for (const auto& ax : gp.spatial_transform)
      if (ax.function.kind == FunctionKind::Multiplier) {
        multiplier = true;
        ASSERT_EQ(ax.function.inner.size(), 1u);
        EXPECT_EQ(ax.function.scale, 1.0);
      }
    EXPECT_TRUE(multiplier);
  }
  {
    // every wrist body is massless: OpenSim's graph maker would reject this tree; we say so
    const auto d = readOsimModel(sharedOpenSim("opensim-models/Models/WristModel/wrist.osim"));
    for (const auto& b : d.bodies) EXPECT_EQ(b.mass, 0.0);
    bool warned = false;
    for (const auto& w : d.warnings) warned = warned || w.find("massless") != std::string::npos;
    EXPECT_TRUE(warned);
  }
}

TEST(SharedModels, CustomJointMobilityOrderFollowsTheTransform) {
  REDMAX_REQUIRE_SHARED();
  // gait2392's pelvis lists tilt, list, rotation, tx, ty, tz and its transform uses them in that
  // order; each axis's mobilities index the joint's q
  const auto d = readOsimModel(
      sharedOpenSim("opensim-models/Models/Gait2392_Simbody/gait2392_thelen2003muscle.osim"));
  const auto& p = d.joints[d.findJoint("ground_pelvis")];
  for (int k = 0; k < 6; ++k) {
    ASSERT_EQ(p.spatial_transform[k].mobilities.size(), 1u);
    EXPECT_EQ(p.spatial_transform[k].mobilities[0], k);
    EXPECT_EQ(d.coordinates[p.coordinates[k]].name, p.spatial_transform[k].coordinates[0]);
  }
  // the knee: one coordinate drives rotation3 and two translations through splines
  const auto& knee = d.joints[d.findJoint("knee_r")];
  ASSERT_EQ(knee.coordinates.size(), 1u);
  int spline_axes = 0;
  for (const auto& ax : knee.spatial_transform) {
    if (ax.function.kind == FunctionKind::SimmSpline) {
      ++spline_axes;
      EXPECT_EQ(ax.mobilities, std::vector<int>{0});
      EXPECT_EQ(ax.function.x.size(), ax.function.y.size());
    }
  }
  EXPECT_GE(spline_axes, 2);
  EXPECT_EQ(d.coordinates[knee.coordinates[0]].motion_type, MotionType::Rotational);
}

}  // namespace
}  // namespace redmax::osim
