// The finger flick of [D 6.2.5]: with semi-implicit Euler at 1 ms, the finger whose flexors carry
// 0.2 kg each survives a fingertip force at which the lumped finger (muscle mass ignored) fails.
// Properties, not copied numbers: the lumped threshold is found by bisection, then both variants
// are run at a multiple of it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "validation/simulate/finger_flick.hpp"

namespace {

using namespace redmax;
using namespace redmax::validation;

FlickOptions finger() {
  FlickOptions o;
  o.model_path = std::string(REDMAX_SOURCE_DIR) + "/osim_models/finger.osim";
  o.integrator = "euler";
  o.dt = 1e-3;
  o.duration = 1.0;
  return o;
}

TEST(FingerFlick, InertialFingerSurvivesAForceThatBreaksTheLumpedOne) {
  FlickOptions lumped = finger(), inertial = finger();
  inertial.muscle_masses = {{"FDP", 0.2}, {"FDS", 0.2}};
  for (bool divergence_only : {false, true}) {
    SCOPED_TRACE(divergence_only ? "criterion: divergence" : "criterion: energy artifact");
    if (divergence_only) lumped.energy_growth = inertial.energy_growth = std::numeric_limits<double>::infinity();
    const FlickSearch s = findLargestSurvivedFlick(lumped, 0.5, 2000.0, 2.0, 0.05);
    ASSERT_GT(s.largest_survived, 0.0) << "even 0.5 N fails: " << s.first_failure;
    ASSERT_TRUE(std::isfinite(s.smallest_failed)) << "the lumped finger survives 2 kN";
    // the search brackets a real threshold: a run just below survives, the one just above fails
    EXPECT_TRUE(runFlick(lumped, s.largest_survived).survived);
    EXPECT_FALSE(runFlick(lumped, s.smallest_failed).survived);
    // the muscles' inertia carries the finger through the lumped finger's failing force and twice it
    for (double factor : {1.0, 2.0}) {
      const FlickRun r = runFlick(inertial, factor * s.smallest_failed);
      EXPECT_TRUE(r.survived) << factor << " x " << s.smallest_failed << " N: " << r.why;
    }
  }
}

TEST(FingerFlick, WithItsJointRangesEnforcedTheFingerStopsAtTheBone) {
  // without limits the lumped finger (bdf1 = euler here) fails at 6.7 N with its joints spinning
  // through the bone; with the ranges as hard limits (bdf1's contact QP) lumped and inertial alike
  // survive 1 kN and never leave their ranges
  FlickOptions free_joints = finger();
  free_joints.integrator = "bdf1";
  const FlickRun spun = runFlick(free_joints, 10.0);
  EXPECT_FALSE(spun.survived);
  EXPECT_GT(spun.max_excursion, 1.0);  // measured: tens of rad through the bone
  FlickOptions limited = free_joints;
  limited.joint_limits = "hard";
  for (bool inertial : {false, true}) {
    if (inertial) limited.muscle_masses = {{"FDP", 0.2}, {"FDS", 0.2}};
    for (double force : {10.0, 1000.0}) {
      const FlickRun r = runFlick(limited, force);
      EXPECT_TRUE(r.survived) << force << " N, " << (inertial ? "inertial" : "lumped") << ": " << r.why;
      EXPECT_LT(r.max_excursion, 1e-6) << force << " N";  // measured at most 3.9e-7 rad (1 kN)
    }
  }
}

TEST(FingerFlick, NoFlickNoFailureAndNoMotionWithoutGravity) {
  // without gravity and without a force the finger stays at rest, whatever its muscles weigh
  FlickOptions o = finger();
  o.gravity = false;
  o.muscle_masses = {{"FDP", 0.2}, {"FDS", 0.2}};
  const FlickRun r = runFlick(o, 0.0);
  EXPECT_TRUE(r.survived) << r.why;
}

TEST(FingerFlick, StudyTableHasEveryCombination) {
  FlickOptions o = finger();
  o.duration = 0.05;  // short: the table's shape, not its numbers
  const auto rows = runFlickStudy(o, {"euler"}, {true, false});
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].variant, "lumped");
  EXPECT_EQ(rows[1].variant, "inertial");
  EXPECT_FALSE(rows[2].gravity);
  for (const auto& r : rows) {
    // the divergence criterion is weaker than the artifact one: it survives at least as much
    EXPECT_GE(r.divergence.largest_survived, r.artifact.largest_survived) << r.variant;
  }
  const std::string table = formatFlickTable(rows);
  EXPECT_NE(table.find("| euler | 1 | off | inertial |"), std::string::npos) << table;
  const std::string csv = formatFlickCsv(rows);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
}

}  // namespace
