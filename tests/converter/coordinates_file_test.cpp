// The one coordinates reader (converter/coordinates_file.hpp) that `redmax id`, `lengths` and
// `simulate --initial` share: each label form a column may name a coordinate by, the ID tool's
// exact-name rule with the path labels it passes over, speeds, and the degree factor (Rotational
// columns of a degrees table only, OpenSim's (double)(pi/180)).
#include <gtest/gtest.h>

#include <cmath>

#include "converter/coordinates_file.hpp"

namespace redmax::osim {
namespace {

CoordinateDesc coordinate(const std::string& name, const std::string& joint, MotionType type) {
  CoordinateDesc c;
  c.name = name;
  c.joint = joint;
  c.motion_type = type;
  return c;
}

Storage table(std::vector<std::string> labels, bool in_degrees = false) {
  Storage s;
  s.labels = std::move(labels);
  s.in_degrees = in_degrees;
  s.time = {0.0};
  s.data = MatX::Zero(1, static_cast<Eigen::Index>(s.labels.size()));
  return s;
}

TEST(CoordinatesFile, EveryLabelFormNamesTheCoordinate) {
  const CoordinateDesc q = coordinate("knee_angle", "knee", MotionType::Rotational);
  EXPECT_EQ(coordinatePath(q), "/jointset/knee/knee_angle");
  // name, state path, and the path forms the three readers accepted before they shared one rule
  for (const std::string& label :
       {"knee_angle", "/jointset/knee/knee_angle/value", "knee_angle/value", "/forceset/x/knee_angle",
        "/jointset/other/knee_angle/value"}) {
    const Storage s = table({"hip", label});
    EXPECT_EQ(findCoordinateColumn(s, q), 1) << label;
    EXPECT_EQ(findCoordinateColumn(s, q, CoordinateLabels::ExactName), label == "knee_angle" ? 1 : -1) << label;
  }
  // labels that do not name it
  for (const std::string& label : {"knee_angle_u", "/jointset/knee/knee_angle/speed", "knee_angle_moment",
                                   "xknee_angle", "/jointset/knee/knee_angle_beta/value", "knee"}) {
    EXPECT_EQ(findCoordinateColumn(table({label}), q), -1) << label;
  }
}

TEST(CoordinatesFile, TheNameWinsThenTheStatePathThenOtherPaths) {
  const CoordinateDesc q = coordinate("q1", "j1", MotionType::Rotational);
  EXPECT_EQ(findCoordinateColumn(table({"/a/q1", "/jointset/j1/q1/value", "q1"}), q), 2);
  EXPECT_EQ(findCoordinateColumn(table({"/a/q1", "/jointset/j1/q1/value"}), q), 1);
  EXPECT_EQ(findCoordinateColumn(table({"/b/q1/value", "/a/q1"}), q), 0);
}

TEST(CoordinatesFile, SpeedsByStatePathPathOrUnderscoreU) {
  const CoordinateDesc q = coordinate("q1", "j1", MotionType::Rotational);
  EXPECT_EQ(findSpeedColumn(table({"q1", "/jointset/j1/q1/speed"}), q), 1);
  EXPECT_EQ(findSpeedColumn(table({"q1", "q1/speed"}), q), 1);
  EXPECT_EQ(findSpeedColumn(table({"q1", "q1_u"}), q), 1);
  EXPECT_EQ(findSpeedColumn(table({"q1", "/jointset/j1/q1/value"}), q), -1);
}

TEST(CoordinatesFile, DegreesConvertRotationalCoordinatesOnly) {
  EXPECT_EQ(degreesToRadians(), static_cast<double>(3.14159265358979323846264338327950288L / 180.0L));
  EXPECT_NEAR(degreesToRadians(), M_PI / 180.0, 1e-18);
  const Storage deg = table({"r", "t", "c"}, true), rad = table({"r", "t", "c"}, false);
  const CoordinateDesc r = coordinate("r", "j", MotionType::Rotational);
  const CoordinateDesc t = coordinate("t", "j", MotionType::Translational);
  const CoordinateDesc c = coordinate("c", "j", MotionType::Coupled);
  EXPECT_EQ(coordinateScale(deg, r), degreesToRadians());
  EXPECT_EQ(coordinateScale(deg, t), 1.0);
  EXPECT_EQ(coordinateScale(deg, c), 1.0);
  EXPECT_EQ(coordinateScale(rad, r), 1.0);
}

TEST(CoordinatesFile, MatchingAllCoordinatesReportsPathLabelsTheExactRuleLeaves) {
  const std::vector<CoordinateDesc> cs = {coordinate("q1", "j1", MotionType::Rotational),
                                          coordinate("q2", "j2", MotionType::Translational),
                                          coordinate("q3", "j3", MotionType::Rotational)};
  const Storage s = table({"q1", "/jointset/j2/q2/value", "other"}, true);
  const CoordinateColumns any = matchCoordinateColumns(s, cs);
  EXPECT_EQ(any.value_column, (std::vector<int>{0, 1, -1}));
  EXPECT_EQ(any.matched, 2);
  EXPECT_EQ(any.scale, (std::vector<double>{degreesToRadians(), 1.0, degreesToRadians()}));
  EXPECT_TRUE(any.unused_path_labels.empty());
  const CoordinateColumns exact = matchCoordinateColumns(s, cs, CoordinateLabels::ExactName);
  EXPECT_EQ(exact.value_column, (std::vector<int>{0, -1, -1}));
  EXPECT_EQ(exact.matched, 1);
  EXPECT_EQ(exact.unused_path_labels, (std::vector<std::string>{"/jointset/j2/q2/value"}));
}

}  // namespace
}  // namespace redmax::osim
