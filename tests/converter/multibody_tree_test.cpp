// Multibody-tree order on synthetic models whose answers follow from docs/opensim_compatibility.md §3.1:
// breadth-first by level in JointSet order, reversed joints, massless bodies extended at once,
// loops cut by slave bodies or weld constraints, FreeJoints for unconnected bodies.
#include <gtest/gtest.h>

#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using test::bodyXml;
using test::modernOsim;
using test::pinXml;
using test::weldXml;

std::vector<std::string> qNames(const ModelDescription& d) {
  std::vector<std::string> v;
  for (const auto& c : d.coordinates) v.push_back(c.name);
  return v;
}

std::vector<std::string> mobilizerJoints(const ModelDescription& d) {
  std::vector<std::string> v;
  for (const auto& m : d.tree.mobilizers) v.push_back(d.joints[m.joint].name);
  return v;
}

ModelDescription readText(const std::string& text) {
  test::TempDir dir;
  return readOsimModel(dir.write("m.osim", text));
}

TEST(MultibodyTree, LevelOrderIgnoresJointSetOrderAcrossLevels) {
  // a chain listed tip first still gets q in root-to-tip order
  const auto d = readText(modernOsim(bodyXml("a") + bodyXml("b") + bodyXml("c"),
                                     pinXml("j3", "/bodyset/b", "/bodyset/c") +
                                         pinXml("j2", "/bodyset/a", "/bodyset/b") +
                                         pinXml("j1", "/ground", "/bodyset/a")));
  EXPECT_EQ(qNames(d), (std::vector<std::string>{"j1_q", "j2_q", "j3_q"}));
  ASSERT_EQ(d.tree.mobilizers.size(), 3u);
  EXPECT_EQ(d.tree.mobilizers[0].level, 1);
  EXPECT_EQ(d.tree.mobilizers[2].level, 3);
  // the JointSet order itself is kept in d.joints
  EXPECT_EQ(d.joints[0].name, "j3");
}

TEST(MultibodyTree, WithinALevelJointSetOrderDecides) {
  // two legs: level 2 holds r1 and l1 in JointSet order, then level 3 holds r2 and l2
  const auto d = readText(modernOsim(
      bodyXml("p") + bodyXml("r1") + bodyXml("r2") + bodyXml("l1") + bodyXml("l2"),
      pinXml("r2", "/bodyset/r1", "/bodyset/r2") + pinXml("l2", "/bodyset/l1", "/bodyset/l2") +
          pinXml("r1", "/bodyset/p", "/bodyset/r1") + pinXml("l1", "/bodyset/p", "/bodyset/l1") +
          pinXml("p", "/ground", "/bodyset/p")));
  EXPECT_EQ(mobilizerJoints(d), (std::vector<std::string>{"p", "r1", "l1", "r2", "l2"}));
}

TEST(MultibodyTree, JointWhoseChildIsInboardIsReversed) {
  // the joint names ground as its child: Simbody builds it with Direction::Reverse
  const auto d = readText(
      modernOsim(bodyXml("a") + bodyXml("b"),
                 pinXml("rev", "/bodyset/a", "/ground") + pinXml("fwd", "/bodyset/a", "/bodyset/b")));
  ASSERT_EQ(d.tree.mobilizers.size(), 2u);
  EXPECT_EQ(d.joints[d.tree.mobilizers[0].joint].name, "rev");
  EXPECT_TRUE(d.tree.mobilizers[0].reversed);
  EXPECT_EQ(d.tree.mobilizers[0].inboard_body, "ground");
  EXPECT_EQ(d.tree.mobilizers[0].outboard_body, "a");
  EXPECT_FALSE(d.tree.mobilizers[1].reversed);
  // the joint keeps its own parent/child and coordinate
  EXPECT_EQ(d.joints[0].parent_body, "a");
  EXPECT_EQ(d.joints[0].child_body, "ground");
  EXPECT_EQ(qNames(d), (std::vector<std::string>{"rev_q", "fwd_q"}));
}

TEST(MultibodyTree, MasslessBodyIsExtendedToAMassfulOneAtOnce) {
  // BFS would give j1, j3, j2; the massless m pulls its heavy child h in immediately
  const std::string bodies = bodyXml("m", 0.0) + bodyXml("h", 2.0) + bodyXml("x", 1.0);
  const auto d = readText(modernOsim(bodies, pinXml("j1", "/ground", "/bodyset/m") +
                                                 pinXml("j3", "/ground", "/bodyset/x") +
                                                 pinXml("j2", "/bodyset/m", "/bodyset/h")));
  EXPECT_EQ(mobilizerJoints(d), (std::vector<std::string>{"j1", "j2", "j3"}));
  EXPECT_EQ(d.tree.mobilizers[1].level, 2);
  // welded massless bodies need no extension: plain level order
  const auto w = readText(modernOsim(bodies, weldXml("j1", "/ground", "/bodyset/m") +
                                                 pinXml("j3", "/ground", "/bodyset/x") +
                                                 pinXml("j2", "/bodyset/m", "/bodyset/h")));
  EXPECT_EQ(mobilizerJoints(w), (std::vector<std::string>{"j1", "j3", "j2"}));
  EXPECT_TRUE(w.warnings.empty());
}

TEST(MultibodyTree, PinLoopIsCutWithASlaveBodyAndAWeld) {
  const auto d = readText(modernOsim(bodyXml("a") + bodyXml("b"),
                                     pinXml("j1", "/ground", "/bodyset/a") +
                                         pinXml("j2", "/bodyset/a", "/bodyset/b") +
                                         pinXml("j3", "/ground", "/bodyset/b")));
  // level 1 takes j1 and j3; j2 then joins two tree bodies and closes the loop
  EXPECT_EQ(mobilizerJoints(d), (std::vector<std::string>{"j1", "j3", "j2"}));
  EXPECT_EQ(qNames(d), (std::vector<std::string>{"j1_q", "j3_q", "j2_q"}));
  ASSERT_EQ(d.tree.slaves.size(), 1u);
  EXPECT_EQ(d.tree.slaves[0].name, "b_slave_0");
  EXPECT_EQ(d.tree.slaves[0].master, "b");
  EXPECT_EQ(d.tree.mobilizers[2].outboard_body, "b_slave_0");
  EXPECT_EQ(d.tree.mobilizers[2].level, 2);
  ASSERT_EQ(d.constraints.size(), 1u);
  EXPECT_EQ(d.constraints[0].name, "b_slave_0_weld");
  EXPECT_EQ(d.constraints[0].kind, ConstraintKind::Weld);
  EXPECT_FALSE(d.constraints[0].generated_by.empty());
}

TEST(MultibodyTree, WeldLoopBecomesAWeldConstraintWithTheJointFrames) {
  const std::string extra_frames =
      "<WeldJoint name=\"w\">\n<socket_parent_frame>a_off</socket_parent_frame>\n"
      "<socket_child_frame>/bodyset/b</socket_child_frame>\n<frames>\n"
      "<PhysicalOffsetFrame name=\"a_off\"><socket_parent>/bodyset/a</socket_parent>"
      "<translation>0.1 0.2 0.3</translation><orientation>0 0 0</orientation>"
      "</PhysicalOffsetFrame>\n</frames>\n</WeldJoint>\n";
  const auto d = readText(modernOsim(bodyXml("a") + bodyXml("b"),
                                     pinXml("j1", "/ground", "/bodyset/a") + extra_frames +
                                         pinXml("j3", "/ground", "/bodyset/b")));
  EXPECT_EQ(mobilizerJoints(d), (std::vector<std::string>{"j1", "j3"}));
  ASSERT_EQ(d.constraints.size(), 1u);
  const auto& c = d.constraints[0];
  EXPECT_EQ(c.name, "w_Loop");
  EXPECT_EQ(c.body1, "a");
  EXPECT_EQ(c.body2, "b");
  EXPECT_EQ(Vec3(c.X_B1F1.topRightCorner<3, 1>()), Vec3(0.1, 0.2, 0.3));
  EXPECT_TRUE(d.tree.slaves.empty());
}

TEST(MultibodyTree, UnconnectedBodiesGetFreeJointsToGround) {
  // c is connected by nothing; x-y form a floating subtree whose root x gets the free joint
  const auto d = readText(modernOsim(bodyXml("a") + bodyXml("c") + bodyXml("x") + bodyXml("y"),
                                     pinXml("j1", "/ground", "/bodyset/a") +
                                         pinXml("xy", "/bodyset/x", "/bodyset/y")));
  ASSERT_EQ(d.joints.size(), 4u);
  EXPECT_EQ(d.joints[2].name, "free_c");
  EXPECT_TRUE(d.joints[2].added);
  EXPECT_EQ(d.joints[3].name, "free_x");
  EXPECT_EQ(mobilizerJoints(d), (std::vector<std::string>{"j1", "free_c", "free_x", "xy"}));
  const auto q = qNames(d);
  ASSERT_EQ(q.size(), 14u);
  EXPECT_EQ(q[1], "free_c_coord_0");
  EXPECT_EQ(q[6], "free_c_coord_5");
  EXPECT_EQ(d.coordinates[1].motion_type, MotionType::Rotational);
  EXPECT_EQ(d.coordinates[6].motion_type, MotionType::Translational);
  EXPECT_EQ(q.back(), "xy_q");
}

TEST(MultibodyTree, BodiesAndJointsInTheModelsComponentsComeFirst) {
  // OpenSim's component order puts the Model's own components list before its JointSet
  const std::string comps =
      "<components>\n" + bodyXml("c") + pinXml("jc", "/ground", "/c") + "</components>\n";
  std::string text = modernOsim(bodyXml("a"), pinXml("ja", "/ground", "/bodyset/a"));
  text.insert(text.find("<Ground"), comps);
  const auto d = readText(text);
  ASSERT_EQ(d.bodies.size(), 2u);
  EXPECT_EQ(d.bodies[0].name, "c");
  EXPECT_EQ(mobilizerJoints(d), (std::vector<std::string>{"jc", "ja"}));
  EXPECT_EQ(d.joints[0].child_frame, "/c");
  EXPECT_TRUE(d.unsupported.empty());
}

TEST(MultibodyTree, BuilderRejectsJointsOnUnknownBodies) {
  ModelDescription d;
  d.source_file = "x.osim";
  BodyDesc b;
  b.name = "a";
  d.bodies.push_back(b);
  JointDesc j;
  j.name = "bad";
  j.parent_body = "ground";
  j.child_body = "nobody";
  j.line = 7;
  d.joints.push_back(j);
  try {
    buildMultibodyTree(d);
    FAIL() << "expected a ConvertError";
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), 7);
    EXPECT_NE(std::string(e.what()).find("nobody"), std::string::npos);
  }
}

}  // namespace
}  // namespace redmax::osim
