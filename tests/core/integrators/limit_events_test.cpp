// Hard joint limits under the adaptive integrators by event location (core/integrators/
// event_driven.hpp): a 1 m, 1 kg rod on a hinge (scenes::singlePendulum, q = 0 hanging) released
// from the horizontal onto a limit. With the impact located in time the kinetic energy after it is
// e^2 times the energy before to the integrator's tolerance (bdf1's contact step is first order in
// h there); with e = 0 the rod stops and stays on the limit; a rod resting on a limit that gravity
// pulls it off is released and swings as without the limit. Contact pairs: contact_events_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "core/dynamics/system.hpp"
#include "core/dynamics/unilateral/unilateral.hpp"
#include "core/integrators/event_driven.hpp"
#include "core/integrators/integrator.hpp"
#include "validation/scenes/deformable_scenes.hpp"

namespace redmax {
namespace {

std::shared_ptr<System> rodWithLimit(double lower, double upper, double e) {
  auto sys = std::make_shared<System>(scenes::singlePendulum());
  sys->setUnilateral(std::make_shared<UnilateralConstraints>(sys->model(), std::vector<CollisionGeometry>{},
                                                             std::vector<CollisionPair>{},
                                                             std::vector<JointLimit>{{"pin", 0, lower, upper, e}}));
  return sys;
}

TEST(LimitEvents, TheImpactKeepsESquaredOfTheKineticEnergy) {
  // from the horizontal (q = pi/2) down onto the lower limit at -0.5 rad: the energy just before is
  // m g L/2 (cos(-0.5) - cos(pi/2)) (no other loss), just after e^2 of it
  const double e = 0.5, lower = -0.5;
  for (const char* method : {"rk45", "cvode"}) {
    auto sys = rodWithLimit(lower, 3.0, e);
    State s = sys->defaultState();
    s.q[0] = M_PI / 2;
    IntegratorOptions io;
    io.rtol = 1e-11;
    io.atol = 1e-12;
    auto integ = makeIntegrator(method, io);
    const double before = 9.81 * 0.5 * std::cos(lower);
    // run until the first impact has happened and the rod swings back up
    double after = -1.0, lowest = 1e9;
    for (int k = 1; k <= 1500 && after < 0.0; ++k) {
      integ->advance(*sys, s, 0.001 * k);
      lowest = std::min(lowest, s.q[0]);
      if (integ->stats().event_impacts > 0 && s.qdot[0] > 0.0) {
        // energy is conserved after the impact: the kinetic energy at the limit's angle is the
        // total energy less the potential there
        DynamicsWorkspace ws(*sys);
        const double E = sys->kineticEnergy(s, ws) + sys->potentialEnergy(s, ws);
        State at = s;
        at.q[0] = lower;
        at.qdot[0] = 0.0;
        after = E - sys->potentialEnergy(at, ws);
      }
    }
    ASSERT_GE(after, 0.0) << method << ": no impact seen";
    const double ratio = after / before;
    std::printf("[ measured ] %s: kinetic energy after / before the stop %.12f (e^2 = %.2f); lowest sampled angle "
                "%.3e from the limit; %ld impacts, %ld steps\n",
                method, ratio, e * e, lower - lowest, integ->stats().event_impacts, integ->stats().steps);
    EXPECT_NEAR(ratio, e * e, 2e-8);  // measured 1.5e-9 (rk45), 7.4e-9 (cvode): the tolerances' error
    EXPECT_GE(lowest, lower);         // never beyond the limit
  }
}

TEST(LimitEvents, WithoutRestitutionTheRodStopsAndStaysOnTheLimit) {
  // the limit at 0.5 rad on the way down from the horizontal: gravity keeps pushing the rod onto it
  auto sys = rodWithLimit(0.5, 3.0, 0.0);
  State s = sys->defaultState();
  s.q[0] = M_PI / 2;
  IntegratorOptions io;
  io.rtol = 1e-10;
  io.atol = 1e-12;
  auto integ = makeIntegrator("rk45", io);
  integ->advance(*sys, s, 0.6);  // the impact is at about 0.4 s
  ASSERT_EQ(integ->stats().event_impacts, 1);
  for (int k = 1; k <= 10; ++k) {
    integ->advance(*sys, s, 0.6 + 0.05 * k);
    EXPECT_DOUBLE_EQ(s.q[0], 0.5);
    EXPECT_NEAR(s.qdot[0], 0.0, 1e-12);  // (the KKT solve's round-off, 1e-16 per check)
  }
  EXPECT_EQ(integ->stats().event_releases, 0);
}

TEST(LimitEvents, StoppedWhereGravityPullsItBackItIsReleased) {
  // the limit at -0.5 rad on the far side of the bottom, e = 0: the rod stops there, gravity pulls
  // it back at once (a release), and with no loss after that it swings between the limit and +0.5
  // rad (the mirror angle) and touches the limit again at zero speed
  auto sys = rodWithLimit(-0.5, 3.0, 0.0);
  State s = sys->defaultState();
  s.q[0] = M_PI / 2;
  IntegratorOptions io;
  io.rtol = 1e-11;
  io.atol = 1e-12;
  auto integ = makeIntegrator("rk45", io);
  double highest = -1e9;
  integ->advance(*sys, s, 0.8);
  ASSERT_EQ(integ->stats().event_impacts, 1);
  EXPECT_EQ(integ->stats().event_releases, 1);
  for (int k = 1; k <= 1000; ++k) {
    integ->advance(*sys, s, 0.8 + 0.001 * k);
    highest = std::max(highest, s.q[0]);
  }
  std::printf("[ measured ] after the stop at -0.5 rad the rod rises to %.9f rad (mirror 0.5)\n", highest);
  EXPECT_NEAR(highest, 0.5, 1e-5);  // sampled every 1 ms near the turning point: the sampling's error
}

TEST(LimitEvents, ARodGravityPullsOffItsLimitIsReleasedAndSwingsFree) {
  // resting on its upper limit at 0.3 rad, gravity pulls it back toward 0: released at once, it
  // swings exactly as without the limit (to the integrator's tolerance) until it returns
  auto limited = rodWithLimit(-1.0, 0.3, 0.0);
  System free_rod(scenes::singlePendulum());
  State a = limited->defaultState(), b = free_rod.defaultState();
  a.q[0] = b.q[0] = 0.3;
  IntegratorOptions io;
  io.rtol = 1e-11;
  io.atol = 1e-12;
  auto ia = makeIntegrator("rk45", io), ib = makeIntegrator("rk45", io);
  double worst = 0.0;
  for (int k = 1; k <= 50; ++k) {
    ia->advance(*limited, a, 0.01 * k);
    ib->advance(free_rod, b, 0.01 * k);
    worst = std::max(worst, std::abs(a.q[0] - b.q[0]));
  }
  std::printf("[ measured ] released rod against the free rod over 0.5 s: %.2e rad\n", worst);
  EXPECT_EQ(ia->stats().event_releases, 1);
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(a.q[0], 0.0);  // it swung down past the bottom
}

TEST(LimitEvents, Sdirk2RefusesHardConstraints) {
  State s = rodWithLimit(-1, 1, 0)->defaultState();
  EXPECT_THROW(makeIntegrator("sdirk2", IntegratorOptions{})->advance(*rodWithLimit(-1, 1, 0), s, 0.1),
               std::invalid_argument);
}

}  // namespace
}  // namespace redmax
