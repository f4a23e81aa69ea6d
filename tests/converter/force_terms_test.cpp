// The ForceSet's actuators and passive forces read from .osim and built as core terms
// (converter/osim_forces.cpp, converter/build/force_terms.hpp): OpenSim's property names and
// defaults, CoordinateLimitForce's degrees, frames resolved to their base bodies, and bad values
// refused at their line.
#include "converter/build/force_terms.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

std::string twoBodies(const std::string& forces) {
  const std::string bodies = test::bodyXml("a") + test::bodyXml("b");
  const std::string joints =
      test::pinXml("pa", "/ground", "/bodyset/a", "qa") +
      "<SliderJoint name=\"sb\"><socket_parent_frame>/bodyset/a</socket_parent_frame>"
      "<socket_child_frame>/bodyset/b</socket_child_frame><coordinates><Coordinate name=\"xb\"/></coordinates>"
      "<frames><PhysicalOffsetFrame name=\"b_off\"><socket_parent>/bodyset/b</socket_parent>"
      "<translation>0 0.5 0</translation><orientation>0 0 1.5707963267948966</orientation></PhysicalOffsetFrame>"
      "</frames></SliderJoint>\n";
  return test::modernOsim(bodies, joints, "<ForceSet><objects>\n" + forces + "</objects></ForceSet>\n");
}

TEST(ForceTerms, ReadAndBuiltWithOpenSimsDefaultsAndUnits) {
  test::TempDir dir;
  const std::string path = dir.write(
      "m.osim",
      twoBodies("<CoordinateLimitForce name=\"lim_rot\"><coordinate>qa</coordinate><upper_stiffness>2</upper_stiffness>"
                "<upper_limit>30</upper_limit><lower_limit>-45</lower_limit></CoordinateLimitForce>\n"
                "<CoordinateLimitForce name=\"lim_slide\"><coordinate>xb</coordinate><upper_limit>0.2</upper_limit>"
                "</CoordinateLimitForce>\n"
                "<PointActuator name=\"p\"><body>b</body></PointActuator>\n"
                "<TorqueActuator name=\"t\"><bodyA>/jointset/sb/b_off</bodyA><bodyB>ground</bodyB>"
                "<axis>1 0 0</axis><torque_is_global>false</torque_is_global></TorqueActuator>\n"
                "<SpringGeneralizedForce name=\"g\"><coordinate>qa</coordinate><stiffness>3</stiffness></SpringGeneralizedForce>\n"
                "<PointToPointSpring name=\"s\"><socket_body1>/ground</socket_body1><socket_body2>/jointset/sb/b_off</socket_body2>"
                "<point2>0 1 0</point2></PointToPointSpring>\n"
                "<BushingForce name=\"bush\"><socket_frame1>a_off</socket_frame1><socket_frame2>/bodyset/b</socket_frame2>"
                "<rotational_stiffness>1 2 3</rotational_stiffness><translational_damping>4 5 6</translational_damping>"
                "<frames><PhysicalOffsetFrame name=\"a_off\"><socket_parent>/bodyset/a</socket_parent>"
                "<translation>0.1 0.2 0.3</translation></PhysicalOffsetFrame></frames></BushingForce>\n"
                "<ExpressionBasedCoordinateForce name=\"expr\"/>\n"));
  const ModelDescription d = readOsimModel(path);
  BuildOptions bo;
  const BuildResult b = buildCoreModel(d, bo);
  std::vector<std::string> warnings;
  const ForceTermSet set = buildForceTerms(d, b, warnings);
  EXPECT_TRUE(warnings.empty());
  // CoordinateLimitForce: OpenSim's defaults (stiffness 1, damping 0.001, transition 0.1), and
  // degrees for a rotational coordinate, SI for a translational one
  ASSERT_TRUE(set.limit_forces);
  const auto& lr = set.limit_forces->limits()[0];
  const double w = M_PI / 180.0;
  EXPECT_DOUBLE_EQ(lr.upper_limit, 30 * w);
  EXPECT_DOUBLE_EQ(lr.lower_limit, -45 * w);
  EXPECT_DOUBLE_EQ(lr.upper_stiffness, 2 / w);
  EXPECT_DOUBLE_EQ(lr.lower_stiffness, 1 / w);
  EXPECT_DOUBLE_EQ(lr.damping, 0.001 / w);
  EXPECT_DOUBLE_EQ(lr.transition, 0.1 * w);
  const auto& ls = set.limit_forces->limits()[1];
  EXPECT_EQ(ls.upper_limit, 0.2);
  EXPECT_EQ(ls.upper_stiffness, 1.0);
  EXPECT_EQ(ls.transition, 0.1);
  // PointActuator: point 0, direction (1, 0, 0), both in the body, optimal force 1
  ASSERT_TRUE(set.point_actuators);
  const auto& p = set.point_actuators->actuators()[0];
  EXPECT_EQ(p.direction, Vec3::UnitX());
  EXPECT_FALSE(p.point_is_global || p.force_is_global);
  EXPECT_EQ(p.optimal_force, 1.0);
  // TorqueActuator on an offset frame: its base body, the axis re-expressed there (frame turned
  // 90 deg about z: x -> y); bodyB ground
  ASSERT_TRUE(set.torque_actuators);
  const auto& t = set.torque_actuators->actuators()[0];
  EXPECT_EQ(t.body_a, b.body_index[static_cast<size_t>(d.findBody("b"))]);
  EXPECT_EQ(t.body_b, -1);
  EXPECT_NEAR((t.axis - Vec3::UnitY()).norm(), 0.0, 1e-15);
  EXPECT_EQ(set.actuatorTerms().size(), 2u);
  EXPECT_EQ(set.generalized_springs->springs()[0].stiffness, 3.0);
  // PointToPointSpring: the frame's base body; stiffness 1 by default
  const auto& s = set.point_springs->springs()[0];
  EXPECT_EQ(s.body1, -1);
  EXPECT_EQ(s.body2, t.body_a);
  EXPECT_EQ(s.stiffness, 1.0);
  // BushingForce: its own offset frame on body a, OpenSim's property order (rotational first)
  ASSERT_TRUE(set.bushings);
  const auto& bu = set.bushings->bushings()[0];
  EXPECT_EQ(bu.body1, b.body_index[static_cast<size_t>(d.findBody("a"))]);
  EXPECT_EQ(bu.body2, t.body_a);
  EXPECT_EQ(Vec3(bu.X_1F.topRightCorner<3, 1>()), Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(bu.stiffness, (Vec6() << 1, 2, 3, 0, 0, 0).finished());
  EXPECT_EQ(bu.damping, (Vec6() << 0, 0, 0, 4, 5, 6).finished());
  EXPECT_EQ(set.passiveTerms().size(), 4u);
  // a class redmax does not model is listed
  bool listed = false;
  for (const auto& u : d.unsupported) listed = listed || u.what.find("'expr' (ExpressionBasedCoordinateForce)") != std::string::npos;
  EXPECT_TRUE(listed);
}

TEST(ForceTerms, BadValuesAreErrorsAtTheirLine) {
  test::expectReadError(twoBodies("<PointActuator name=\"p\">\n<body>c</body>\n</PointActuator>\n"), "<body>c</body>",
                        "body 'c' is not a body");
  test::expectReadError(twoBodies("<PointActuator name=\"p\"><body>a</body>\n<direction>0 0 0</direction>\n</PointActuator>\n"),
                        "<direction>0 0 0", "direction must be a non-zero vector");
  test::expectReadError(
      twoBodies("<CoordinateLimitForce name=\"l\"><coordinate>qa</coordinate>\n<damping>-1</damping>\n</CoordinateLimitForce>\n"),
      "<damping>-1", "damping must be finite and >= 0");
  test::expectReadError(
      twoBodies("<CoordinateLimitForce name=\"l\"><coordinate>qa</coordinate>\n<transition>0</transition>\n</CoordinateLimitForce>\n"),
      "<transition>0", "transition must be positive");
  test::expectReadError(twoBodies("<SpringGeneralizedForce name=\"g\">\n<coordinate>zz</coordinate>\n</SpringGeneralizedForce>\n"),
                        "<coordinate>zz", "coordinate 'zz' is not a coordinate");
  test::expectReadError(
      twoBodies("<PointToPointSpring name=\"s\"><socket_body1>/ground</socket_body1>\n<socket_body2>/bodyset/nope</socket_body2>\n"
                "</PointToPointSpring>\n"),
      "<socket_body2>/bodyset/nope", "does not name a frame");
  test::expectReadError(
      twoBodies("<PointToPointSpring name=\"s\"><socket_body1>/ground</socket_body1><socket_body2>/bodyset/a</socket_body2>\n"
                "<stiffness>-5</stiffness>\n</PointToPointSpring>\n"),
      "<stiffness>-5", "stiffness must be finite and >= 0");
}

// A force_set_files file without <OpenSimDocument> is version 10500 to OpenSim, and its
// PointActuators and TorqueActuators get the conversions of documents older than 10905
// (PointActuator / TorqueActuator::updateFromXMLNode): direction and axis negated even when the
// new names are used (OpenSim 4.6 reads gait2354_CMC_Actuators.xml's MX axis 1 0 0 as -1 0 0,
// measured), the old names body_B, point_B, direction_A (PointActuator) and body_A -> bodyB,
// body_B -> bodyA, direction_A -> axis (TorqueActuator) read, and a PointActuator's force global
// unless it says otherwise. The same file in a version-40000 document reads as written.
TEST(ForceTerms, UnversionedForceSetFilesGetOpenSimsOldActuatorConversions) {
  test::TempDir dir;
  const ModelDescription d = readOsimModel(dir.write("m.osim", twoBodies("")));
  const std::string forces =
      "<objects>\n"
      "<PointActuator name=\"p\"><body>b</body><point>0.1 0 0</point><direction>1 0 0</direction>"
      "<force_is_global>true</force_is_global></PointActuator>\n"
      "<PointActuator name=\"p_old\"><body_B>a</body_B><point_B>0 0.2 0</point_B><direction_A>0 1 0</direction_A>"
      "</PointActuator>\n"
      "<TorqueActuator name=\"t\"><bodyA>a</bodyA><bodyB>ground</bodyB><axis>1 0 0</axis></TorqueActuator>\n"
      "<Torque name=\"t_old\"><body_A>ground</body_A><body_B>b</body_B><direction_A>0 0 1</direction_A></Torque>\n"
      "</objects>";
  ModelDescription old_doc = d;
  appendForceSetFile(old_doc, dir.write("old.xml", "<ForceSet name=\"f\">" + forces + "</ForceSet>"));
  ModelDescription new_doc = d;
  // (the old names are no properties there: a version-40000 file holds the new ones only)
  const std::string modern =
      "<objects>\n"
      "<PointActuator name=\"p\"><body>b</body><point>0.1 0 0</point><direction>1 0 0</direction>"
      "</PointActuator>\n"
      "<TorqueActuator name=\"t\"><bodyA>a</bodyA><bodyB>ground</bodyB><axis>1 0 0</axis></TorqueActuator>\n"
      "</objects>";
  appendForceSetFile(new_doc, dir.write("new.xml", "<OpenSimDocument Version=\"40000\"><ForceSet name=\"f\">" + modern +
                                                       "</ForceSet></OpenSimDocument>"));
  auto find = [](const ModelDescription& m, const std::string& name) -> const ForceDesc& {
    for (const ForceDesc& f : m.forces)
      if (f.name == name) return f;
    ADD_FAILURE() << "no force " << name;
    return m.forces.front();
  };
  // version 10500: negated, old names read
  EXPECT_EQ(find(old_doc, "p").direction, Vec3(-1, 0, 0));
  EXPECT_TRUE(find(old_doc, "p").force_is_global);
  const ForceDesc& po = find(old_doc, "p_old");
  EXPECT_EQ(po.class_name, "PointActuator");
  EXPECT_EQ(po.body1, "a");
  EXPECT_EQ(po.point1, Vec3(0, 0.2, 0));
  EXPECT_EQ(po.direction, Vec3(0, -1, 0));
  EXPECT_TRUE(po.force_is_global);
  EXPECT_EQ(find(old_doc, "t").direction, Vec3(-1, 0, 0));
  EXPECT_EQ(find(old_doc, "t").body1, "a");
  const ForceDesc& to = find(old_doc, "t_old");
  EXPECT_EQ(to.class_name, "TorqueActuator");
  EXPECT_EQ(to.body1, "b");  // bodyA was body_B
  EXPECT_EQ(to.body2, d.ground_name);
  EXPECT_EQ(to.direction, Vec3(0, 0, -1));
  // version 40000: as written
  EXPECT_EQ(find(new_doc, "p").direction, Vec3(1, 0, 0));
  EXPECT_EQ(find(new_doc, "t").direction, Vec3(1, 0, 0));
  EXPECT_FALSE(find(new_doc, "p").force_is_global);
}

// OpenSim's ForceSet::append (AbstractTool::updateModelForces) skips an appended force whose name the
// set already holds (OpenSim's testStaticOptimization passive-force setup appends reserves the
// model already has: appending them again doubled them, so each carried half); with
// replace_force_set the model's are gone and the file's count. Earlier files keep their entries.
TEST(ForceTerms, ForceSetFilesDoNotAppendANameTheSetHolds) {
  test::TempDir dir;
  const ModelDescription d = readOsimModel(dir.write(
      "m.osim", twoBodies("<CoordinateActuator name=\"r\"><coordinate>qa</coordinate><optimal_force>1</optimal_force>"
                          "</CoordinateActuator>\n")));
  const std::string file = dir.write(
      "f.xml", "<OpenSimDocument Version=\"40000\"><ForceSet name=\"f\"><objects>\n"
               "<CoordinateActuator name=\"r\"><coordinate>qa</coordinate><optimal_force>5</optimal_force>"
               "</CoordinateActuator>\n"
               "<CoordinateActuator name=\"s\"><coordinate>xb</coordinate></CoordinateActuator>\n"
               "</objects></ForceSet></OpenSimDocument>");
  auto count = [](const ModelDescription& m, const std::string& name) {
    return std::count_if(m.forces.begin(), m.forces.end(), [&](const ForceDesc& f) { return f.name == name; });
  };
  ModelDescription kept = d;
  appendForceSetFile(kept, file);
  EXPECT_EQ(count(kept, "r"), 1);
  EXPECT_EQ(count(kept, "s"), 1);
  for (const ForceDesc& f : kept.forces)
    if (f.name == "r") EXPECT_EQ(f.optimal_force, 1.0);  // the model's
  bool named = false;
  for (const std::string& w : kept.warnings) named = named || w.find("force 'r' is not appended") != std::string::npos;
  EXPECT_TRUE(named);
  appendForceSetFile(kept, file);  // a second file: its entries are all held already
  EXPECT_EQ(count(kept, "s"), 1);
  // replace_force_set: the file's r joins (the model's is no longer in the set)
  ModelDescription replaced = d;
  appendForceSetFile(replaced, file, true);
  EXPECT_EQ(count(replaced, "r"), 2);
  EXPECT_EQ(replaced.forces.back().name, "s");
}

}  // namespace
}  // namespace redmax::osim
