// The Integrator contract: output sampling, resuming, bad input, failure reporting, constraints.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/dynamics/coordinate_map.hpp"
#include "core/integrators/linearly_implicit_euler.hpp"
#include "core/integrators/sdirk2.hpp"
#include "core/integrators/symplectic_euler.hpp"
#include "tests/core/integrators/integrator_test_util.hpp"

namespace redmax {
namespace {
using namespace testing_util;

State pendulumStart(const System& sys) {
  State s = sys.defaultState();
  s.q << 1.0, 0.5;
  s.qdot << 0.2, -0.4;
  return s;
}

class EveryIntegrator : public ::testing::TestWithParam<std::string> {};

// advance() to successive t_out lands on them exactly; fixed-step methods take ceil(span/dt)
// steps per call (span 0.0137 s, dt 4 ms -> 4 steps).
TEST_P(EveryIntegrator, LandsExactlyOnOutputTimes) {
  System sys(springDampedPendulum());
  State s = pendulumStart(sys);
  IntegratorOptions opt;
  opt.dt = 0.004;
  opt.rtol = 1e-8;
  opt.atol = 1e-10;
  auto integ = makeIntegrator(GetParam(), opt);
  EXPECT_EQ(integ->name(), GetParam());
  for (int k = 1; k <= 50; ++k) {
    const double t_out = 0.0137 * k;
    integ->advance(sys, s, t_out);
    ASSERT_EQ(s.t, t_out) << "k = " << k;
  }
  const bool fixed = GetParam() == "euler" || GetParam() == "bdf1" || GetParam() == "sdirk2";
  if (fixed) {
    EXPECT_EQ(integ->stats().steps, 50 * 4);
  }
  EXPECT_GT(integ->stats().rhs_evals, 0);
  // t_out == state.t is a no-op
  const State before = s;
  const long steps = integ->stats().steps;
  integ->advance(sys, s, s.t);
  EXPECT_EQ(s.q, before.q);
  EXPECT_EQ(s.qdot, before.qdot);
  EXPECT_EQ(integ->stats().steps, steps);
}

// Bad input gives std::invalid_argument, never a crash: wrong state size, t_out < t.
TEST_P(EveryIntegrator, RejectsBadArguments) {
  System sys(springDampedPendulum());
  IntegratorOptions opt;
  auto integ = makeIntegrator(GetParam(), opt);
  State s = pendulumStart(sys);
  s.t = 1.0;
  EXPECT_THROW(integ->advance(sys, s, 0.5), std::invalid_argument);
  State wrong = s;
  wrong.q.resize(3);
  EXPECT_THROW(integ->advance(sys, wrong, 2.0), std::invalid_argument);
  wrong = s;
  wrong.qdot.resize(1);
  EXPECT_THROW(integ->advance(sys, wrong, 2.0), std::invalid_argument);
  EXPECT_THROW(integ->advance(sys, s, std::nan("")), std::invalid_argument);
}

// A force that turns NaN at t = 0.3 s is reported as SimulationError near that time, naming the
// integrator; nothing non-finite is handed back.
TEST_P(EveryIntegrator, NonFiniteForceBecomesSimulationError) {
  System sys(springDampedPendulum());
  sys.addTerm(std::make_shared<LambdaForce>([](const State& s, VecX& f) {
    if (s.t > 0.3) f[1] += std::nan("");
  }));
  State s = pendulumStart(sys);
  IntegratorOptions opt;
  opt.dt = 0.01;
  auto integ = makeIntegrator(GetParam(), opt);
  try {
    integ->advance(sys, s, 1.0);
    ADD_FAILURE() << "no error";
  } catch (const SimulationError& e) {
    const std::string what = e.what();
    std::printf("%s\n", e.what());
    EXPECT_NE(what.find(GetParam()), std::string::npos) << what;
    EXPECT_NE(what.find("non-finite"), std::string::npos) << what;
    EXPECT_GE(e.time, 0.3 - 0.02);
    EXPECT_LE(e.time, 0.35);
    EXPECT_GT(e.step, 0.0);
  }
  EXPECT_TRUE(stacked(s).allFinite());
}

// Every method keeps the reduced coupling q0 = q1 [D Eq. 4.103]: euler and bdf1 exactly through
// their velocity-level rows, the acceleration-level methods through Baumgarte stabilisation
// (alpha = beta = 20 1/s). The coupled pendulum moves (q changes by > 0.5 rad).
TEST_P(EveryIntegrator, KeepsReducedCoordinateConstraint) {
  System sys(scenes::doublePendulum());
  sys.addConstraint(std::make_shared<CouplingConstraint>(0, 1));
  sys.stabilization.alpha = 20.0;
  sys.stabilization.beta = 20.0;
  State s = sys.defaultState();
  s.q << 0.7, 0.7;
  IntegratorOptions opt;
  opt.dt = 1e-3;
  opt.rtol = 1e-9;
  opt.atol = 1e-11;
  auto integ = makeIntegrator(GetParam(), opt);
  double max_err = 0.0, min_q = 1.0;
  for (int k = 1; k <= 200; ++k) {
    integ->advance(sys, s, 0.01 * k);
    max_err = std::max(max_err, std::abs(s.q[0] - s.q[1]));
    min_q = std::min(min_q, s.q[0]);
  }
  const bool velocity_level = GetParam() == "euler" || GetParam() == "bdf1";
  EXPECT_LE(max_err, velocity_level ? 1e-12 : 1e-7) << GetParam();
  EXPECT_LT(min_q, 0.2);
}

INSTANTIATE_TEST_SUITE_P(All, EveryIntegrator, ::testing::ValuesIn(allIntegrators()),
                         [](const auto& info) { return info.param; });

// A constrained conservative system keeps its energy under rk45 (constraint forces do no work):
// checks that the KKT accelerations are right, not only the constraint error.
TEST(Constraints, Rk45ConservesEnergyOfCoupledPendulum) {
  System sys(scenes::doublePendulum());
  sys.addConstraint(std::make_shared<CouplingConstraint>(0, 1));
  State s = sys.defaultState();
  s.q << 1.2, 1.2;
  s.qdot << 0.5, 0.5;
  const double E0 = totalEnergy(sys, s);
  IntegratorOptions opt;
  opt.rtol = 1e-11;
  opt.atol = 1e-13;
  const State e = integrate("rk45", opt, sys, s, 3.0);
  EXPECT_LE(std::abs(totalEnergy(sys, e) - E0), 1e-8 * std::abs(E0));
}

// Hyper-reduced coordinates (q1 = q0 eliminated, ndof 1 < nr 2 [D Sec. 4.6.2]) against the same
// coupling enforced by a KKT constraint (ndof 2): the integrators work on the System's
// coordinates, and both routes give the same motion (rk45 at rtol 1e-11: agree to 1e-8 after 2 s).
TEST(Constraints, HyperReducedCoordinatesMatchKktCoupling) {
  System reduced(scenes::doublePendulum());
  auto map = std::make_shared<CoordinateMap>(reduced.model());
  map->addDependent(1, {0}, makeLinearFunction({1.0}));
  reduced.setCoordinateMap(map);
  ASSERT_EQ(reduced.ndof(), 1);
  System coupled(scenes::doublePendulum());
  coupled.addConstraint(std::make_shared<CouplingConstraint>(0, 1));
  IntegratorOptions opt;
  opt.rtol = 1e-11;
  opt.atol = 1e-13;
  State a = reduced.defaultState();
  a.q << 1.1;
  a.qdot << -0.3;
  State b = coupled.defaultState();
  b.q << 1.1, 1.1;
  b.qdot << -0.3, -0.3;
  for (const std::string name : {"rk45", "cvode", "sdirk2"}) {
    State ra = integrate(name, opt, reduced, a, 2.0);
    State rb = integrate(name, opt, coupled, b, 2.0);
    const double tol = name == "rk45" ? 1e-8 : 1e-3;
    EXPECT_NEAR(ra.q[0], rb.q[0], tol) << name;
    EXPECT_NEAR(ra.q[0], rb.q[1], tol) << name;
    EXPECT_NEAR(ra.qdot[0], rb.qdot[1], 10 * tol) << name;
  }
}

TEST(Factory, UnknownNameThrowsInvalidArgument) {
  IntegratorOptions opt;
  EXPECT_THROW(makeIntegrator("rk4", opt), std::invalid_argument);
  EXPECT_THROW(makeIntegrator("", opt), std::invalid_argument);
  EXPECT_THROW(makeIntegrator("Euler", opt), std::invalid_argument);
  for (const auto& n : allIntegrators()) EXPECT_NO_THROW(makeIntegrator(n, opt)) << n;
}

TEST(Factory, InvalidOptionsThrowInvalidArgument) {
  IntegratorOptions opt;
  opt.dt = 0.0;
  EXPECT_THROW(makeIntegrator("euler", opt), std::invalid_argument);
  EXPECT_THROW(makeIntegrator("sdirk2", opt), std::invalid_argument);
  opt = IntegratorOptions{};
  opt.dt = std::nan("");
  EXPECT_THROW(makeIntegrator("bdf1", opt), std::invalid_argument);
  opt = IntegratorOptions{};
  opt.rtol = -1e-6;
  EXPECT_THROW(makeIntegrator("rk45", opt), std::invalid_argument);
  opt = IntegratorOptions{};
  opt.atol = 0.0;
  EXPECT_THROW(makeIntegrator("cvode", opt), std::invalid_argument);
}

// Fixed-step methods take ceil(span / dt) equal steps: one advance() equals n explicit step()
// calls of size span / n, bit for bit.
TEST(FixedStep, AdvanceTakesEqualSteps) {
  System sys(springDampedPendulum());
  IntegratorOptions opt;
  opt.dt = 0.003;
  const double span = 0.1;  // ceil(33.33) = 34 steps of 0.1/34
  const int n = 34;
  SymplecticEuler euler(opt);
  LinearlyImplicitEuler bdf1(opt);
  Sdirk2 sdirk2(opt);
  FixedStepIntegrator* methods[3] = {&euler, &bdf1, &sdirk2};
  for (FixedStepIntegrator* m : methods) {
    State a = pendulumStart(sys);
    State b = a;
    m->advance(sys, a, span);
    DynamicsWorkspace ws(sys.model());
    for (int k = 0; k < n; ++k) m->step(sys, b, span / n, ws);
    EXPECT_EQ(m->stats().steps, n) << m->name();
    EXPECT_EQ(a.q, b.q) << m->name();
    EXPECT_EQ(a.qdot, b.qdot) << m->name();
    EXPECT_EQ(a.t, span);
  }
}

// The adaptive methods continue from their internal solution between advance() calls: many
// short calls take exactly the internal steps of one long call (same step count), and the final
// state agrees to round-off. A state modified by the caller restarts the solver from it.
TEST(Adaptive, ResumesBetweenCallsAndRestartsOnModifiedState) {
  System sys(springDampedPendulum());
  for (const std::string name : {"rk45", "cvode"}) {
    IntegratorOptions opt;
    opt.rtol = 1e-8;
    opt.atol = 1e-10;
    opt.initial_step = 1e-4;  // so the first step does not depend on t_out
    State one = pendulumStart(sys);
    auto a = makeIntegrator(name, opt);
    a->advance(sys, one, 2.0);
    State many = pendulumStart(sys);
    auto b = makeIntegrator(name, opt);
    for (int k = 1; k <= 200; ++k) b->advance(sys, many, 0.01 * k);
    EXPECT_EQ(a->stats().steps, b->stats().steps) << name;
    EXPECT_LE((stacked(one) - stacked(many)).norm(), 1e-12 * stacked(one).norm()) << name;

    // modify the returned state: the next call starts from it, as a fresh integrator would
    many.qdot *= -0.5;
    State fresh = many;
    b->advance(sys, many, 3.0);
    auto c = makeIntegrator(name, opt);
    c->advance(sys, fresh, 3.0);
    EXPECT_LE((stacked(many) - stacked(fresh)).norm(), 1e-12 * stacked(fresh).norm()) << name;
  }
}

// One integrator used on systems of different sizes rebuilds its SUNDIALS objects and gives the
// same answers as fresh integrators.
TEST(Adaptive, SwitchingSystemSizeRebuildsSolver) {
  System small(springDampedPendulum());
  System large(mixedChain());
  for (const std::string name : {"rk45", "cvode"}) {
    IntegratorOptions opt;
    opt.rtol = 1e-8;
    opt.atol = 1e-10;
    auto shared = makeIntegrator(name, opt);
    State s1 = pendulumStart(small), s2 = chainInitialState(large), s3 = pendulumStart(small);
    shared->advance(small, s1, 0.5);
    shared->advance(large, s2, 0.5);
    shared->advance(small, s3, 0.5);
    const State r1 = integrate(name, opt, small, pendulumStart(small), 0.5);
    const State r2 = integrate(name, opt, large, chainInitialState(large), 0.5);
    EXPECT_LE((stacked(s1) - stacked(r1)).norm(), 1e-12 * stacked(r1).norm()) << name;
    EXPECT_LE((stacked(s2) - stacked(r2)).norm(), 1e-12 * stacked(r2).norm()) << name;
    EXPECT_LE((stacked(s3) - stacked(r1)).norm(), 1e-12 * stacked(r1).norm()) << name;
  }
}

// A force that blows up in finite time (1 / (0.5 - t)^3) defeats every step-size controller:
// the failure (SUNDIALS error, divergence or max_steps) is a SimulationError before t = 0.5.
TEST(Adaptive, SolverFailureBecomesSimulationError) {
  System sys(springDampedPendulum());
  sys.addTerm(std::make_shared<LambdaForce>([](const State& s, VecX& f) {
    const double d = 0.5 - s.t;
    f[0] += 1.0 / (d * d * d);
  }));
  for (const std::string name : {"rk45", "cvode"}) {
    IntegratorOptions opt;
    opt.max_steps = 20000;
    auto integ = makeIntegrator(name, opt);
    State s = pendulumStart(sys);
    try {
      integ->advance(sys, s, 1.0);
      ADD_FAILURE() << name << " passed a singularity";
    } catch (const SimulationError& e) {
      std::printf("%s\n", e.what());
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos);
      EXPECT_GT(e.time, 0.4) << name;
      EXPECT_LE(e.time, 0.5) << name;
      EXPECT_GT(e.step, 0.0) << name;
    }
    EXPECT_EQ(s.t, 0.0);  // the adaptive methods leave the state as it was passed
  }
}

// An exception thrown by the dynamics inside a SUNDIALS callback reaches the caller unchanged
// (it is never unwound through C frames), and the integrator is usable afterwards.
TEST(Adaptive, ExceptionInDynamicsPropagates) {
  System sys(springDampedPendulum());
  sys.addTerm(std::make_shared<LambdaForce>([](const State& s, VecX&) {
    if (s.t > 0.3 && s.t < 10.0) throw std::domain_error("force model failed");
  }));
  for (const std::string name : {"rk45", "cvode"}) {
    IntegratorOptions opt;
    auto integ = makeIntegrator(name, opt);
    State s = pendulumStart(sys);
    EXPECT_THROW(integ->advance(sys, s, 1.0), std::domain_error) << name;
    State again = pendulumStart(sys);
    EXPECT_NO_THROW(integ->advance(sys, again, 0.2)) << name;
    EXPECT_EQ(again.t, 0.2);
  }
}

}  // namespace
}  // namespace redmax
