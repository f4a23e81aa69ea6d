// What happens to the mass points where a Type II path is not smooth (path.hpp header):
//   - a conditional point switching on/off: positions continuous only if the point lies on the
//     segment between its neighbours at the switch; J_ar and the kinetic energy always jump;
//   - a mass point sliding past a via point: position continuous, J_ar jumps; its kinetic energy is
//     continuous when the via point is fixed in the world and jumps when the via point moves.
// Sizes are measured at the double pendulum (1 kg links) with a 0.3 kg muscle of 20 points, and
// recorded as test properties; the assertions check the qualitative claims of the header.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/muscles/muscle_kinematics.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

void record(const char* key, double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  ::testing::Test::RecordProperty(key, buf);
}

struct Jump {
  double position = 0.0;   // max over mass points of |x_a(after) - x_a(before)| (m)
  double jacobian = 0.0;   // |J_ar(after) - J_ar(before)| / |J_ar(before)|
  double kinetic = 0.0;    // T(after) - T(before) (J)
  double potential = 0.0;  // V(after) - V(before) (J)
  double kinetic_before = 0.0;
};

Jump measure(const Model& m, const Muscle& mu, const State& before, const State& after) {
  const MuscleKinematics a = test::evalMuscle(m, mu, before), b = test::evalMuscle(m, mu, after);
  Jump j;
  for (size_t k = 0; k < a.x_a.size(); ++k) j.position = std::max(j.position, (b.x_a[k] - a.x_a[k]).norm());
  j.jacobian = (b.J_ar - a.J_ar).norm() / a.J_ar.norm();
  j.kinetic_before = muscleKineticEnergy(mu.mass_points, a, before.qdot);
  j.kinetic = muscleKineticEnergy(mu.mass_points, b, after.qdot) - j.kinetic_before;
  j.potential = musclePotentialEnergy(mu.mass_points, b, m.gravity()) - musclePotentialEnergy(mu.mass_points, a, m.gravity());
  return j;
}

Muscle conditionalMuscle(const Vec3& via_in_link1) {
  Muscle mu;
  mu.name = "conditional";
  mu.path.points = {makeFixedPoint(-1, Vec3(-0.3, 0.2, 0)),
                    makeConditionalPoint(0, via_in_link1, 1, -1.0, 0.3),  // active for q2 <= 0.3 (+1e-5)
                    makeFixedPoint(1, Vec3(0.1, -0.6, 0))};
  mu.mass_points = makeMassPoints(0.3, 0.25, 0.15, {});
  return mu;
}

// states on both sides of the switch at q2 = 0.3 + 1e-5, same velocity
void switchStates(State& before, State& after) {
  const double edge = 0.3 + kConditionalTolerance;
  before.q = Vec2(0.2, edge - 1e-10);
  after.q = Vec2(0.2, edge + 1e-10);
  before.qdot = after.qdot = Vec2(1.0, 1.5);
}

TEST(ConditionalSwitch, OffSegmentPointMakesPositionsAndEnergyJump) {
  const Model m = scenes::doublePendulum();
  const Muscle mu = conditionalMuscle(Vec3(0.25, -0.5, 0));
  State before, after;
  switchStates(before, after);
  ASSERT_EQ(test::evalMuscle(m, mu, before).active.size(), 3u);
  ASSERT_EQ(test::evalMuscle(m, mu, after).active.size(), 2u);
  const Jump j = measure(m, mu, before, after);
  record("position_jump_m", j.position);
  record("kinetic_jump_J", j.kinetic);
  record("potential_jump_J", j.potential);
  record("kinetic_before_J", j.kinetic_before);
  EXPECT_GT(j.position, 1e-2);
  EXPECT_GT(j.jacobian, 1e-2);
  EXPECT_GT(std::abs(j.kinetic) + std::abs(j.potential), 1e-3);
}

TEST(ConditionalSwitch, OnSegmentPointKeepsPositionsButNotVelocities) {
  const Model m = scenes::doublePendulum();
  State before, after;
  switchStates(before, after);
  // put the point on the origin-insertion segment at the switch configuration
  SkeletonWorkspace sk(m);
  State edge = before;
  edge.q[1] = 0.3 + kConditionalTolerance;
  calcKinematics(m, edge, sk);
  const Vec3 o(-0.3, 0.2, 0);
  const Vec3 ins = transformPoint(sk.E_wi[1], Vec3(0.1, -0.6, 0));
  const Vec3 via_w = o + 0.45 * (ins - o);
  const Muscle mu = conditionalMuscle(transformPoint(inverseE(sk.E_wi[0]), via_w));
  const Jump j = measure(m, mu, before, after);
  record("position_jump_m", j.position);
  record("jacobian_jump_rel", j.jacobian);
  record("kinetic_jump_J", j.kinetic);
  record("kinetic_before_J", j.kinetic_before);
  EXPECT_LT(j.position, 1e-8);                       // continuous up to the 2e-10 step in q2
  EXPECT_LT(std::abs(j.potential), 1e-8);
  EXPECT_GT(j.jacobian, 1e-2);                       // but the Jacobian jumps
  EXPECT_GT(std::abs(j.kinetic), 1e-3 * j.kinetic_before);  // and so does the kinetic energy
}

// a mass point exactly at the via point's material coordinate at q0, crossed along qdot
Jump crossVia(const Model& m, int via_body, const Vec3& via, int& seg_before, int& seg_after) {
  Muscle mu;
  mu.name = "crossing";
  mu.path.points = {makeFixedPoint(-1, Vec3(-0.3, 0.3, 0)), makeFixedPoint(via_body, via),
                    makeFixedPoint(1, Vec3(0.1, -0.6, 0))};
  State s0;
  s0.q = Vec2(0.3, 0.5);
  s0.qdot = Vec2(1.0, -2.0);
  mu.mass_points = makeMassPoints({0.5}, {0.3});
  const double s_via = test::evalMuscle(m, mu, s0).s[1];
  mu.mass_points = makeMassPoints({s_via}, {0.3});
  const State before = test::along(s0, -1e-9), after = test::along(s0, 1e-9);
  seg_before = test::evalMuscle(m, mu, before).segment[0];
  seg_after = test::evalMuscle(m, mu, after).segment[0];
  return measure(m, mu, before, after);
}

TEST(ViaPointCrossing, WorldFixedViaKeepsKineticEnergyContinuous) {
  const Model m = scenes::doublePendulum();
  int sb = 0, sa = 0;
  const Jump j = crossVia(m, -1, Vec3(0.4, 0.1, 0), sb, sa);
  ASSERT_NE(sb, sa) << "the mass point must change segment";
  record("jacobian_jump_rel", j.jacobian);
  record("kinetic_jump_J", j.kinetic);
  EXPECT_LT(j.position, 1e-7);
  EXPECT_GT(j.jacobian, 1e-2);  // the velocity turns the corner...
  EXPECT_LT(std::abs(j.kinetic), 1e-7 * j.kinetic_before);  // ...at unchanged speed
}

TEST(ViaPointCrossing, MovingViaMakesKineticEnergyJump) {
  const Model m = scenes::doublePendulum();
  int sb = 0, sa = 0;
  const Jump j = crossVia(m, 0, Vec3(0.3, -0.4, 0), sb, sa);
  ASSERT_NE(sb, sa) << "the mass point must change segment";
  record("jacobian_jump_rel", j.jacobian);
  record("kinetic_jump_J", j.kinetic);
  record("kinetic_before_J", j.kinetic_before);
  EXPECT_LT(j.position, 1e-7);
  EXPECT_GT(std::abs(j.kinetic), 1e-3 * j.kinetic_before);
}

}  // namespace
}  // namespace redmax
