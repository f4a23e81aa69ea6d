// The contact scenes (validation/scenes/contact_scenes.hpp) against their closed forms, and the
// hard cases: many simultaneous and rank-deficient contacts, a step far too large.
#include "validation/scenes/contact_scenes.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace redmax::scenes {
namespace {

constexpr double kG = 9.81;

// apex k (1-based) after bounces with restitution e from h0 is e^(2k) h0; each bounce starts up to
// one step's travel h |v| above the ground (the impact is taken at the step's start), so the
// error of apex k is below dt times the impact speed e^(k-1) v0
void expectApexes(const BallDropResult& r, const BallDropOptions& o, int count) {
  ASSERT_GE(static_cast<int>(r.apexes.size()), count);
  const double v0 = std::sqrt(2 * kG * o.drop_height);
  double expect = o.drop_height, v = v0;
  for (int k = 0; k < count; ++k) {
    expect *= o.restitution * o.restitution;
    EXPECT_NEAR(r.apexes[k], expect, o.dt * v) << "bounce " << k + 1 << " dt " << o.dt;
    v *= o.restitution;
  }
}

TEST(ContactScenes, BallBouncesToERSquaredHeightsAndRestsOnTheGround) {
  BallDropOptions o;
  const BallDropResult r = runBallDrop(o);
  expectApexes(r, o, 3);
  EXPECT_NEAR(r.rest_height, o.radius, 1e-8);
  EXPECT_LE(r.run.stats.max_penetration, 1e-8);
  // first order: ten times smaller steps, ten times tighter bounds
  o.dt = 1e-4;
  const BallDropResult fine = runBallDrop(o);
  expectApexes(fine, o, 3);
  // e = 1: every bounce returns to the drop height (no energy lost at the impacts)
  o.dt = 1e-3;
  o.restitution = 1.0;
  o.duration = 2.0;
  const BallDropResult elastic = runBallDrop(o);
  expectApexes(elastic, o, 3);
}

TEST(ContactScenes, ContactsAppearingAndVanishingEveryFewSteps) {
  // an elastic ball bouncing 5 mm high with 10 ms steps: a flight lasts about six steps, so the
  // contact comes and goes all the time; it must neither sink nor gain height
  BallDropOptions o;
  o.restitution = 1.0;
  o.drop_height = 5e-3;
  o.dt = 1e-2;
  o.duration = 2.0;
  const BallDropResult r = runBallDrop(o);
  const double v0 = std::sqrt(2 * kG * o.drop_height);
  ASSERT_GE(r.apexes.size(), 20u);
  for (double a : r.apexes) EXPECT_LE(a, o.drop_height + o.dt * v0);
  EXPECT_LE(r.run.stats.max_penetration, 1e-9);
  // the contact was in the QP in a large share of the steps, and the ball kept bouncing
  EXPECT_GT(r.run.stats.unilateral_steps, r.run.stats.steps / 4);
  EXPECT_GT(r.apexes.back(), 0.25 * o.drop_height);
}

TEST(ContactScenes, BlockSlidesTheCoulombDistance) {
  const BlockSlideOptions o;
  const BlockSlideResult r = runBlockSlide(o);
  // v_{k+1} = v_k - mu g h, x += h v_{k+1}: the discrete distance is v0^2/(2 mu g) - h v0 / 2 + O(h^2)
  EXPECT_NEAR(r.distance, o.v0 * o.v0 / (2 * o.friction * kG), o.dt * o.v0);
  EXPECT_NEAR(r.stop_time, o.v0 / (o.friction * kG), 2 * o.dt);
  EXPECT_LE(r.final_speed, 1e-8);  // static friction holds it
  EXPECT_LE(r.max_tilt, 1e-8);
  EXPECT_EQ(r.run.stats.friction_unconverged, 0);
}

TEST(ContactScenes, BoxStackSettlesWithoutDrift) {
  const BoxStackOptions o;
  const BoxStackResult r = runBoxStack(o);
  EXPECT_LE(r.drift_per_second, 1e-8);
  EXPECT_LE(r.max_penetration, 1e-8);
}

TEST(ContactScenes, ManyRankDeficientContactsSettle) {
  // six boxes dropped onto each other: 24 corner contacts at once, four coplanar per box (rank 3)
  BoxStackOptions o;
  o.boxes = 6;
  o.initial_gap = 0.02;
  o.duration = 3.0;
  const BoxStackResult r = runBoxStack(o);
  EXPECT_EQ(r.run.stats.max_contacts, 24);
  EXPECT_LE(r.drift_per_second, 1e-8);
  EXPECT_LE(r.max_penetration, 1e-8);
  EXPECT_LE(r.run.stats.max_penetration, 1e-6);
}

TEST(ContactScenes, LimitStopsThePendulumWithRestitution) {
  LimitPendulumOptions o;
  const LimitPendulumResult r = runLimitPendulum(o);
  EXPECT_NEAR(r.energy_before, r.free_fall_energy, 1e-3 * r.free_fall_energy);
  EXPECT_NEAR(r.energy_after, o.restitution * o.restitution * r.energy_before, 1e-6 * r.energy_before);
  EXPECT_GE(r.min_angle, -M_PI / 2 - 1e-9);
  o.restitution = 0.0;
  const LimitPendulumResult stop = runLimitPendulum(o);
  EXPECT_LE(stop.energy_after, 1e-12);
  EXPECT_NEAR(stop.run.rows.back()[1], -M_PI / 2, 1e-8);  // stays at the limit
}

TEST(ContactScenes, StepFarTooLargeStaysFiniteAndOutOfTheGround) {
  // hard constraints have no stiffness to resolve: a 0.2 s step is inaccurate, not unstable
  BallDropOptions o;
  o.dt = 0.2;
  o.duration = 4.0;
  const BallDropResult r = runBallDrop(o);
  EXPECT_NEAR(r.rest_height, o.radius, 1e-6);
  EXPECT_LE(r.run.stats.max_penetration, 1e-6);
  BoxStackOptions s;
  s.dt = 0.2;
  s.duration = 4.0;
  const BoxStackResult q = runBoxStack(s);
  EXPECT_TRUE(std::isfinite(q.drift_per_second));
  EXPECT_LE(q.drift_per_second, 1e-3);  // measured 9e-5 m/s (regularised split of the impulses)
  EXPECT_LE(q.max_penetration, 1e-3);
}

}  // namespace
}  // namespace redmax::scenes
