// Legacy .osim upgrades on generated files (docs/opensim_compatibility.md §1.3-1.4): ground body to Ground,
// joints out of bodies in BodySet order, offset frames with 6-digit rounding, inertia defaults,
// reverse=true, isDisabled, pennation_angle, MusclePointSet without GeometryPath, aliases.
#include <gtest/gtest.h>

#include <cmath>

#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

// a 2.x/3.x model: ground, then bodies with their joints inside
std::string legacyOsim(const std::string& bodies, const std::string& extra = "",
                       const std::string& version = "20303") {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenSimDocument Version=\"" + version +
         "\">\n<Model name=\"legacy\">\n" + extra +
         "<BodySet name=\"\"><objects>\n"
         "<Body name=\"ground\"><mass>0</mass><Joint/></Body>\n" +
         bodies + "</objects></BodySet>\n</Model>\n</OpenSimDocument>\n";
}

std::string legacyBody(const std::string& name, const std::string& inertia,
                       const std::string& joint) {
  return "<Body name=\"" + name + "\">\n<mass>2.5</mass>\n<mass_center>0 0.1 0</mass_center>\n" +
         inertia + "<Joint>\n" + joint + "</Joint>\n</Body>\n";
}

std::string legacyPin(const std::string& name, const std::string& parent, const std::string& coord,
                      const std::string& more = "") {
  return "<PinJoint name=\"" + name + "\">\n<parent_body>" + parent +
         "</parent_body>\n<location_in_parent>0.123456789 -0.0000123456789 1</location_in_parent>\n"
         "<orientation_in_parent>0 0 0.5</orientation_in_parent>\n"
         "<location>0 0.7777777 0</location>\n<orientation>0 0 0</orientation>\n"
         "<CoordinateSet><objects><Coordinate name=\"" + coord +
         "\"><motion_type>rotational</motion_type><default_value>0.1</default_value>"
         "<range>-1 1</range></Coordinate></objects></CoordinateSet>\n" + more + "</PinJoint>\n";
}

ModelDescription readText(const std::string& text) {
  test::TempDir dir;
  return readOsimModel(dir.write("legacy.osim", text));
}

TEST(LegacyUpgrade, GroundBodyJointsAndOffsetFrames) {
  const auto d = readText(legacyOsim(
      legacyBody("thigh", "<inertia_xx>0.12345678</inertia_xx><inertia_yy>2</inertia_yy>"
                          "<inertia_zz>3</inertia_zz><inertia_xy>0.000123456789</inertia_xy>",
                 legacyPin("hip", "ground", "hip_q"))));
  EXPECT_EQ(d.osim_version, 20303);
  EXPECT_EQ(d.ground_name, "ground");
  ASSERT_EQ(d.bodies.size(), 1u);  // ground is not a body
  // six inertia scalars through a 6-digit stream; absent products are 0
  const auto& I = d.bodies[0].inertia;
  EXPECT_EQ(I[0], 0.123457);
  EXPECT_EQ(I[1], 2.0);
  EXPECT_EQ(I[3], 0.000123457);
  EXPECT_EQ(I[4], 0.0);
  EXPECT_EQ(I[5], 0.0);
  ASSERT_EQ(d.joints.size(), 1u);
  const auto& j = d.joints[0];
  EXPECT_EQ(j.parent_frame, "/jointset/hip/ground_offset");
  EXPECT_EQ(j.child_frame, "/jointset/hip/thigh_offset");
  EXPECT_EQ(j.parent_body, "ground");
  EXPECT_EQ(j.child_body, "thigh");
  // location_in_parent 0.123456789 -0.0000123456789 1 -> 0.123457 -1.23457e-05 1
  EXPECT_EQ(j.X_PF(0, 3), 0.123457);
  EXPECT_EQ(j.X_PF(1, 3), -1.23457e-05);
  EXPECT_EQ(j.X_PF(2, 3), 1.0);
  EXPECT_NEAR(j.X_PF(0, 0), std::cos(0.5), 1e-15);
  EXPECT_NEAR(j.X_PF(1, 0), std::sin(0.5), 1e-15);
  EXPECT_EQ(j.X_BM(1, 3), 0.777778);
  ASSERT_EQ(d.coordinates.size(), 1u);
  EXPECT_EQ(d.coordinates[0].default_value, 0.1);
  EXPECT_EQ(d.coordinates[0].motion_type, MotionType::Rotational);
  EXPECT_EQ(d.frames.size(), 2u);
}

TEST(LegacyUpgrade, MissingInertiaDiagonalBecomesOne) {
  // no inertia elements at all: diag 1, products 0 (Body::updateFromXMLNode)
  const auto d = readText(legacyOsim(legacyBody("b", "", legacyPin("p", "ground", "q"))));
  const auto& I = d.bodies[0].inertia;
  EXPECT_EQ(I[0], 1.0);
  EXPECT_EQ(I[1], 1.0);
  EXPECT_EQ(I[2], 1.0);
  EXPECT_EQ(I[3], 0.0);
  // a 4.0 file has no such rule: a missing <inertia> is zero
  const auto m = readText(test::modernOsim(
      "<Body name=\"b\"><mass>1</mass></Body>\n",
      test::pinXml("p", "/ground", "/bodyset/b")));
  EXPECT_EQ(m.bodies[0].inertia[0], 0.0);
}

TEST(LegacyUpgrade, ReverseSwapsTheJointFramesAndTheTreeReversesTheMobilizer) {
  const auto d = readText(legacyOsim(legacyBody(
      "b", "", legacyPin("p", "ground", "q", "<reverse> true </reverse>\n"))));
  const auto& j = d.joints[0];
  EXPECT_TRUE(j.reversed_in_file);
  // the child-side frame (on b) is now the parent frame, and vice versa
  EXPECT_EQ(j.parent_frame, "/jointset/p/b_offset");
  EXPECT_EQ(j.child_frame, "/jointset/p/ground_offset");
  EXPECT_EQ(j.parent_body, "b");
  EXPECT_EQ(j.child_body, "ground");
  EXPECT_EQ(j.X_PF(1, 3), 0.777778);  // location (in the child body) is now X_PF
  ASSERT_EQ(d.tree.mobilizers.size(), 1u);
  EXPECT_TRUE(d.tree.mobilizers[0].reversed);
  EXPECT_EQ(d.tree.mobilizers[0].outboard_body, "b");
}

TEST(LegacyUpgrade, JointsFollowBodySetOrderAndNamelessOnesAreNamed) {
  // nameless joints get their lowercased class name, duplicates _0, _1 ...
  const std::string weld =
      "<WeldJoint name=\"\"><parent_body>ground</parent_body><location_in_parent>0 0 0"
      "</location_in_parent></WeldJoint>\n";
  const std::string weld2 =
      "<WeldJoint name=\"\"><parent_body>a</parent_body></WeldJoint>\n";
  const auto d = readText(legacyOsim(legacyBody("a", "", weld) + legacyBody("b", "", weld2) +
                                     legacyBody("c", "", legacyPin("pin", "b", "q"))));
  ASSERT_EQ(d.joints.size(), 3u);
  EXPECT_EQ(d.joints[0].name, "weldjoint");
  EXPECT_EQ(d.joints[1].name, "weldjoint_0");
  EXPECT_EQ(d.joints[2].name, "pin");
  EXPECT_EQ(d.joints[1].parent_body, "a");
  EXPECT_EQ(d.joints[1].child_body, "b");
}

TEST(LegacyUpgrade, OldMuscleLayoutIsReadWithTheRenamedProperties) {
  // <= 20301: MusclePointSet directly in the muscle, MusclePoint/MuscleViaPoint/MovingMusclePoint
  // with XAttachment, natCubicSpline, pennation_angle, isDisabled; ActuatorSet is the ForceSet
  const std::string forces =
      "<ActuatorSet><objects>\n"
      "<Schutte1993Muscle name=\"m\">\n<isDisabled>true</isDisabled>\n"
      "<MusclePointSet><objects>\n"
      "<MusclePoint name=\"o\"><location>0 0 0</location><body>ground</body></MusclePoint>\n"
      "<MuscleViaPoint name=\"v\"><location>0 1 0</location><body>b</body>"
      "<range>-1 0.5</range><coordinates>q</coordinates></MuscleViaPoint>\n"
      "<MovingMusclePoint name=\"i\"><location>9 9 9</location><body>b</body>\n"
      "<XAttachment><natCubicSpline><x>-1 0 1</x><y>0.1 0.2 0.4</y></natCubicSpline>"
      "</XAttachment>\n<x_coordinate>q</x_coordinate>\n</MovingMusclePoint>\n"
      "</objects></MusclePointSet>\n"
      "<max_isometric_force>321</max_isometric_force>\n"
      "<pennation_angle>0.25</pennation_angle>\n"
      "</Schutte1993Muscle>\n</objects></ActuatorSet>\n";
  const auto d = readText(legacyOsim(legacyBody("b", "", legacyPin("p", "ground", "q")), forces,
                                     "20001"));
  ASSERT_EQ(d.muscles.size(), 1u);
  const auto& m = d.muscles[0];
  EXPECT_EQ(m.class_name, "Schutte1993Muscle_Deprecated");  // the registered alias
  EXPECT_TRUE(m.is_muscle);
  EXPECT_FALSE(m.applies_force);  // isDisabled=true
  EXPECT_EQ(m.max_isometric_force, 321.0);
  EXPECT_EQ(m.pennation_angle_at_optimal, 0.25);
  ASSERT_EQ(m.points.size(), 3u);
  EXPECT_EQ(m.points[0].frame, "/ground");
  EXPECT_EQ(m.points[1].kind, PathPointKind::Conditional);
  EXPECT_EQ(m.points[1].coordinate, "q");
  EXPECT_EQ(m.points[1].range_max, 0.5);
  EXPECT_EQ(m.points[2].kind, PathPointKind::Moving);
  EXPECT_EQ(m.points[2].location_functions[0].type, "SimmSpline");
  EXPECT_EQ(m.points[2].location_functions[0].written_type, "natCubicSpline");
  EXPECT_EQ(m.points[2].location_coordinates[0], "q");
  EXPECT_EQ(m.points[2].location_functions[1].type, "Constant");  // absent: Constant(0)
  EXPECT_EQ(m.path_type, PathType::II);
}

TEST(LegacyUpgrade, LegacyConstraintsBecomeSocketsAndOffsetFrames) {
  const std::string constraints =
      "<ConstraintSet><objects>\n"
      "<WeldConstraint name=\"w\"><isDisabled>false</isDisabled><body_1>a</body_1>"
      "<body_2>b</body_2><location_body_1>0 0 0</location_body_1>"
      "<orientation_body_1>0 0 0</orientation_body_1>"
      "<location_body_2>0 -0.4832031 0</location_body_2></WeldConstraint>\n"
      "<PointConstraint name=\"pc\"><body_1>a</body_1><body_2>ground</body_2>"
      "<location_body_1>1 2 3</location_body_1></PointConstraint>\n"
      "<CoordinateCouplerConstraint><isDisabled>true</isDisabled>"
      "<coupled_coordinates_function><LinearFunction><coefficients>0.5 0</coefficients>"
      "</LinearFunction></coupled_coordinates_function>"
      "<independent_coordinate_names>qa</independent_coordinate_names>"
      "<dependent_coordinate_name>qb</dependent_coordinate_name></CoordinateCouplerConstraint>\n"
      "</objects></ConstraintSet>\n";
  // the constraint set sits after the bodies in real files; put it in the Model tail
  std::string text = legacyOsim(legacyBody("a", "", legacyPin("pa", "ground", "qa")) +
                                    legacyBody("b", "", legacyPin("pb", "a", "qb")),
                                "", "30000");
  text.insert(text.find("</Model>"), constraints);
  const auto d = readText(text);
  ASSERT_EQ(d.constraints.size(), 3u);
  const auto& w = d.constraints[0];
  EXPECT_EQ(w.kind, ConstraintKind::Weld);
  EXPECT_TRUE(w.enforced);
  EXPECT_EQ(w.frame1, "/bodyset/a");  // identity offset: the body itself
  EXPECT_EQ(w.frame2, "/constraintset/w/b_offset");
  EXPECT_EQ(w.X_B2F2(1, 3), -0.483203);  // rounded through the 6-digit stream
  const auto& pc = d.constraints[1];
  EXPECT_EQ(pc.body2, "ground");
  EXPECT_EQ(pc.location1, Vec3(1, 2, 3));
  const auto& cc = d.constraints[2];
  EXPECT_EQ(cc.name, "coordinatecouplerconstraint");
  EXPECT_FALSE(cc.enforced);
  EXPECT_EQ(cc.function->coefficients[0], 0.5);
}

TEST(LegacyUpgrade, Version10901WithTheSetsInsideTheSimbodyEngine) {
  // 1.x files keep gravity and the sets in <DynamicsEngine><SimbodyEngine>
  std::string text = legacyOsim(legacyBody("b", "", legacyPin("p", "ground", "q")), "", "10901");
  text.replace(text.find("<BodySet"), 0,
               "<DynamicsEngine><SimbodyEngine>\n<gravity>0 0 -9.81</gravity>\n");
  text.replace(text.find("</Model>"), 0, "</SimbodyEngine></DynamicsEngine>\n");
  const auto d = readText(text);
  EXPECT_EQ(d.osim_version, 10901);
  EXPECT_EQ(d.gravity, Vec3(0, 0, -9.81));
  ASSERT_EQ(d.bodies.size(), 1u);
  EXPECT_EQ(d.numDofs(), 1);
}

TEST(LegacyUpgrade, MixedFilesReadModernElementsWhateverTheVersion) {
  // OpenSim reads properties by tag: a 3.0 file may already use sockets in its paths
  const std::string forces =
      "<ForceSet><objects>\n<Thelen2003Muscle name=\"m\"><GeometryPath><PathPointSet><objects>\n"
      "<PathPoint name=\"a\"><socket_parent_frame>/bodyset/b</socket_parent_frame>"
      "<location>1 0 0</location></PathPoint>\n"
      "<PathPoint name=\"b\"><location>0 0 0</location><body>ground</body></PathPoint>\n"
      "</objects></PathPointSet></GeometryPath></Thelen2003Muscle>\n</objects></ForceSet>\n";
  const auto d =
      readText(legacyOsim(legacyBody("b", "", legacyPin("p", "ground", "q")), forces, "30000"));
  ASSERT_EQ(d.muscles.size(), 1u);
  EXPECT_EQ(d.muscles[0].points[0].body, "b");
  EXPECT_EQ(d.muscles[0].points[1].body, "ground");
  EXPECT_EQ(d.muscles[0].path_type, PathType::I);
}

}  // namespace
}  // namespace redmax::osim
