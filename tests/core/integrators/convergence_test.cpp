// Convergence orders of the fixed-step methods and their behaviour on stiff springs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/integrators/sdirk2.hpp"
#include "tests/core/integrators/integrator_test_util.hpp"

namespace redmax {
namespace {
using namespace testing_util;

/// errors at t = 1 s of `name` with steps h, h/2, h/4, h/8 on the sprung, damped double pendulum
/// against an rk45 reference at rtol 1e-13; returns the observed orders log2(e_h / e_h/2)
std::vector<double> observedOrders(const std::string& name, double h0, std::vector<double>* errs) {
  System sys(springDampedPendulum());
  State s0 = sys.defaultState();
  s0.q << 1.0, 0.5;
  s0.qdot << 0.3, -0.2;
  IntegratorOptions ref_opt;
  ref_opt.rtol = 1e-13;
  ref_opt.atol = 1e-15;
  const VecX ref = stacked(integrate("rk45", ref_opt, sys, s0, 1.0));
  std::vector<double> e;
  double h = h0;
  for (int i = 0; i < 4; ++i, h *= 0.5) {
    IntegratorOptions opt;
    opt.dt = h;
    opt.newton_tol = 1e-13;
    e.push_back((stacked(integrate(name, opt, sys, s0, 1.0)) - ref).norm());
  }
  std::vector<double> p;
  for (size_t i = 0; i + 1 < e.size(); ++i) p.push_back(std::log2(e[i] / e[i + 1]));
  if (errs) *errs = e;
  return p;
}

// Halving h halves the error of bdf1 (order 1) and quarters that of sdirk2 (order 2). The
// pendulum has joint springs and dampers, so bdf1's implicit terms are exercised (without them
// it would reduce to symplectic Euler).
TEST(Convergence, Bdf1IsFirstOrder) {
  std::vector<double> e;
  const auto p = observedOrders("bdf1", 0.02, &e);
  std::printf("bdf1 errors at h = 0.02..0.0025: %.3e %.3e %.3e %.3e; orders %.3f %.3f %.3f\n", e[0], e[1],
              e[2], e[3], p[0], p[1], p[2]);
  for (double o : p) {
    EXPECT_GE(o, 0.8);
    EXPECT_LE(o, 1.2);
  }
}

TEST(Convergence, Sdirk2IsSecondOrder) {
  std::vector<double> e;
  const auto p = observedOrders("sdirk2", 0.02, &e);
  std::printf("sdirk2 errors at h = 0.02..0.0025: %.3e %.3e %.3e %.3e; orders %.3f %.3f %.3f\n", e[0],
              e[1], e[2], e[3], p[0], p[1], p[2]);
  for (double o : p) {
    EXPECT_GE(o, 1.7);
    EXPECT_LE(o, 2.3);
  }
}

TEST(Convergence, SymplecticEulerIsFirstOrder) {
  std::vector<double> e;
  const auto p = observedOrders("euler", 0.02, &e);
  std::printf("euler errors at h = 0.02..0.0025: %.3e %.3e %.3e %.3e; orders %.3f %.3f %.3f\n", e[0], e[1],
              e[2], e[3], p[0], p[1], p[2]);
  for (double o : p) {
    EXPECT_GE(o, 0.8);
    EXPECT_LE(o, 1.2);
  }
}

// The adaptive methods meet their tolerance: the error against the tight reference shrinks with
// rtol (by at least 100x over four decades of rtol) and stays within 1000 rtol at each setting.
TEST(Convergence, AdaptiveErrorFollowsTolerance) {
  System sys(springDampedPendulum());
  State s0 = sys.defaultState();
  s0.q << 1.0, 0.5;
  IntegratorOptions ref_opt;
  ref_opt.rtol = 1e-13;
  ref_opt.atol = 1e-15;
  const VecX ref = stacked(integrate("rk45", ref_opt, sys, s0, 1.0));
  for (const std::string name : {"rk45", "cvode"}) {
    double e_loose = 0.0, e_tight = 0.0;
    for (double rtol : {1e-5, 1e-9}) {
      IntegratorOptions opt;
      opt.rtol = rtol;
      opt.atol = 1e-2 * rtol;
      const double e = (stacked(integrate(name, opt, sys, s0, 1.0)) - ref).norm() / ref.norm();
      std::printf("%s rtol %.0e: relative error %.3e\n", name.c_str(), rtol, e);
      EXPECT_LE(e, 1e3 * rtol) << name;
      (rtol > 1e-7 ? e_loose : e_tight) = e;
    }
    EXPECT_LE(e_tight, 1e-2 * e_loose) << name;
  }
}

/// one hinge with a stiff joint spring and damper (omega ~ 550 rad/s, damping ratio ~ 0.02)
System stiffPendulum() {
  Model m = springDampedPendulum(0.0, 0.0);
  {
    ModelBuilder edit(m);
    edit.coordinateAt(0).stiffness = 1e5;
    edit.coordinateAt(0).damping = 20.0;
    m = edit.finalize();
  }
  return System(m);
}

// At h = 10 ms the stiff spring on the first hinge has h omega ~ 5.5: explicit (symplectic)
// Euler diverges, and says so with a SimulationError naming the time and step, handing back a
// finite state; the linearly implicit bdf1 stays bounded and dissipates energy; sdirk2
// (L-stable) too. (The second hinge is free and may swing over.)
TEST(Stiff, EulerDivergesWithErrorWhereImplicitMethodsStayBounded) {
  System sys = stiffPendulum();
  State s0 = sys.defaultState();
  s0.q << 0.1, 0.3;
  const double E0 = totalEnergy(sys, s0);
  IntegratorOptions opt;
  opt.dt = 0.01;

  State s = s0;
  auto euler = makeIntegrator("euler", opt);
  try {
    euler->advance(sys, s, 5.0);
    ADD_FAILURE() << "euler should diverge at h = 10 ms";
  } catch (const SimulationError& e) {
    std::printf("euler at h = 10 ms: %s\n", e.what());
    EXPECT_GT(e.time, 0.0);
    EXPECT_LT(e.time, 5.0);
    EXPECT_DOUBLE_EQ(e.step, 0.01);
    EXPECT_NE(std::string(e.what()).find("euler"), std::string::npos);
  }
  EXPECT_TRUE(stacked(s).allFinite());

  for (const std::string name : {"bdf1", "sdirk2"}) {
    State si = s0;
    auto integ = makeIntegrator(name, opt);
    double E_max = 0.0;
    for (int k = 1; k <= 500; ++k) {
      integ->advance(sys, si, 0.01 * k);
      E_max = std::max(E_max, totalEnergy(sys, si));
      ASSERT_LE(std::abs(si.q[0]), 1.0) << name << " at t = " << si.t;  // the stiff hinge
    }
    const double E_end = totalEnergy(sys, si);
    std::printf("%s at h = 10 ms: E0 %.4f, max E %.4f, E(5 s) %.4f\n", name.c_str(), E0, E_max, E_end);
    // damped system: the energy never rises above its start (1e-9 for round-off)
    EXPECT_LE(E_max, E0 + 1e-9 * std::abs(E0)) << name;
    EXPECT_LT(E_end, E0) << name;
  }
}

// The linearly implicit step is exact for the linearised system it solves: a single hinge with
// spring and damper and no gravity is linear, so bdf1 must match the closed-form backward Euler
// recursion (M + h D + h^2 K) v+ = M v - h K q, q+ = q + h v+ to round-off.
TEST(Stiff, Bdf1MatchesBackwardEulerOnLinearOscillator) {
  ModelBuilder b("oscillator");
  b.setGravity(Vec3::Zero());
  Vec3 c;
  Mat3 I;
  rod(1.0, 0.5, c, I);
  b.addBody("a", 1.0, c, I, -1, "ja", Revolute{Vec3::UnitZ()});
  b.coordinateAt(0).stiffness = 1e4;
  b.coordinateAt(0).damping = 3.0;
  b.coordinateAt(0).rest_value = 0.2;
  Model m = b.finalize();
  System sys(m);
  State s = sys.defaultState();
  s.q << 1.0;
  s.qdot << -2.0;
  DynamicsWorkspace ws(m);
  sys.calcMassAndForce(s, ws);
  const double M = ws.M(0, 0), K = 1e4, D = 3.0, h = 0.01;
  double q = 1.0, v = -2.0;
  for (int k = 0; k < 200; ++k) {
    v = (M * v - h * K * (q - 0.2)) / (M + h * D + h * h * K);
    q += h * v;
  }
  IntegratorOptions opt;
  opt.dt = h;
  auto integ = makeIntegrator("bdf1", opt);
  integ->advance(sys, s, 2.0);
  EXPECT_NEAR(s.q[0], q, 1e-12 * (1.0 + std::abs(q)));
  EXPECT_NEAR(s.qdot[0], v, 1e-12 * (1.0 + std::abs(v)));
}

// sdirk2 is L-stable: on the undamped stiff oscillator at h omega = 100 its stability function
// R(z) = (1 + (1 - 2 gamma) z) / (1 - gamma z)^2 has |R(100 i)| ~ 0.05 (R(inf) = 0), so ten steps
// damp the amplitude below 1e-9 instead of letting it oscillate or grow.
TEST(Stiff, Sdirk2IsLStable) {
  ModelBuilder b("oscillator");
  b.setGravity(Vec3::Zero());
  Vec3 c;
  Mat3 I;
  rod(1.0, 0.5, c, I);
  b.addBody("a", 1.0, c, I, -1, "ja", Revolute{Vec3::UnitZ()});
  Model m = b.finalize();
  System probe(m);
  DynamicsWorkspace ws(m);
  State s = probe.defaultState();
  probe.calcMassAndForce(s, ws);
  const double h = 0.01, omega = 100.0 / h;
  {
    ModelBuilder edit(m);
    edit.coordinateAt(0).stiffness = omega * omega * ws.M(0, 0);
    m = edit.finalize();
  }
  System sys(m);
  s.q << 1.0;
  IntegratorOptions opt;
  opt.dt = h;
  auto integ = makeIntegrator("sdirk2", opt);
  integ->advance(sys, s, 10 * h);
  EXPECT_LE(std::abs(s.q[0]), 1e-9);
  EXPECT_LE(std::abs(s.qdot[0]) / omega, 1e-9);
}

// An overdamped stiff mode (second hinge with k = 1e6, d = 1e4: eigenvalues near -1e2 and -3e4)
// makes explicit rk45 stability-limited; cvode's BDF takes far fewer steps for the same answer.
TEST(Stiff, CvodeTakesFewerStepsThanRk45OnStiffDampedSystem) {
  Model m = springDampedPendulum(0.0, 0.0);
  {
    ModelBuilder edit(m);
    edit.coordinateAt(1).stiffness = 1e6;
    edit.coordinateAt(1).damping = 1e4;
    m = edit.finalize();
  }
  System sys(m);
  State s0 = sys.defaultState();
  s0.q << 1.0, 0.4;
  IntegratorOptions opt;
  opt.rtol = 1e-6;
  opt.atol = 1e-8;
  IntegratorStats st_cv, st_rk;
  const VecX cv = stacked(integrate("cvode", opt, sys, s0, 2.0, &st_cv));
  const VecX rk = stacked(integrate("rk45", opt, sys, s0, 2.0, &st_rk));
  std::printf("stiff damped: cvode %ld steps %ld rhs; rk45 %ld steps %ld rhs; difference %.3e\n", st_cv.steps,
              st_cv.rhs_evals, st_rk.steps, st_rk.rhs_evals, (cv - rk).norm());
  EXPECT_LE((cv - rk).norm(), 1e-4 * (1.0 + rk.norm()));
  EXPECT_LT(5 * st_cv.steps, st_rk.steps);
}

// A stiff spring hidden in a ForceTerm that reports no K (an explicit term): sdirk2's cheap
// Newton matrix (M only) cannot converge at h omega ~ 5.5, so each stage falls back to full
// Newton on a finite-difference Jacobian, and the result equals (to 1e-7, well above the Newton
// tolerance) the same spring given as a joint spring, whose K is known.
TEST(Stiff, Sdirk2FallsBackToFiniteDifferenceJacobian) {
  const double k = 1e5;
  System hidden = stiffPendulum();
  Model m = hidden.model();
  {
    ModelBuilder edit(m);
    edit.coordinateAt(0).stiffness = 0.0;
    m = edit.finalize();
  }
  System explicit_spring(m);
  explicit_spring.addTerm(std::make_shared<LambdaForce>([k](const State& s, VecX& f) { f[0] -= k * s.q[0]; }));
  State s0 = hidden.defaultState();
  s0.q << 0.1, 0.3;
  IntegratorOptions opt;
  opt.dt = 0.01;
  IntegratorStats st_known, st_hidden;
  const VecX known = stacked(integrate("sdirk2", opt, hidden, s0, 0.5, &st_known));
  const VecX fd = stacked(integrate("sdirk2", opt, explicit_spring, s0, 0.5, &st_hidden));
  std::printf("sdirk2 stiff spring as joint spring: %ld rhs, %ld restarts; as explicit term: %ld rhs, %ld restarts\n",
              st_known.rhs_evals, st_known.failed_steps, st_hidden.rhs_evals, st_hidden.failed_steps);
  // with K known the cheap iteration almost always suffices; hidden, every stage (2 per step,
  // 50 steps) needs the fallback
  EXPECT_LE(st_known.failed_steps, 10);
  EXPECT_EQ(st_hidden.failed_steps, 100);
  EXPECT_TRUE(nearRel(fd, known, 1e-7));
}

// max_step caps the adaptive step: 1 s at max_step 1 ms takes at least 1000 steps.
TEST(Adaptive, MaxStepIsHonoured) {
  System sys(springDampedPendulum());
  State s0 = sys.defaultState();
  s0.q << 1.0, 0.5;
  for (const std::string name : {"rk45", "cvode"}) {
    IntegratorOptions opt;
    opt.max_step = 1e-3;
    IntegratorStats st;
    integrate(name, opt, sys, s0, 1.0, &st);
    EXPECT_GE(st.steps, 1000) << name;
    EXPECT_LE(st.steps, 1100) << name;
  }
}

}  // namespace
}  // namespace redmax
