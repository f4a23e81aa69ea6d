// Hard cases of the work-precision report (validation/work_precision/hard_cases.hpp): each test
// asserts the property behind one row of the report's "hard cases" table, with the same library
// function, and records the measured number as a test property.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "tests/validation/hard_cases_test_util.hpp"
#include "validation/simulate/simulate.hpp"
#include "validation/work_precision/hard_cases.hpp"

namespace {

using namespace redmax;
using namespace redmax::validation;

using redmax_test::modelsDir;
using redmax_test::record;

// 1. exponential coordinates near |q| = pi and through the chart switch at 1.5 pi: 2 s of the
// spinning body (20 revolutions) keep energy and world angular momentum to 1e-7 (rk45 rtol 1e-10).
TEST(HardCases, SpinningBodyThroughManyCharts) {
  const SpinCase c = runSpinCase(2.0);
  record("spin_chart_switches", c.chart_switches);
  record("spin_energy_err_rel", c.energy_err_rel);
  record("spin_momentum_err_rel", c.momentum_err_rel);
  EXPECT_GE(c.revolutions, 20.0);
  EXPECT_GT(c.chart_switches, 10);
  EXPECT_GT(c.max_q_norm, M_PI);  // it passed |q| = pi (not a switch there: S is well conditioned)
  EXPECT_LE(c.max_q_norm, 1.5 * M_PI + 1e-12);
  EXPECT_LE(c.energy_err_rel, 1e-7);
  EXPECT_LE(c.momentum_err_rel, 1e-7);
}

// 2. gimbal lock: the guard's distance is |cos q2| for XYZ angles (closed form), and a run into
// the singularity stops with a SimulationError naming joint, time and step, never with NaN.
TEST(HardCases, GimbalLockIsReportedNotNaN) {
  ModelBuilder b("one_ball");
  b.addBody("body", 1.0, Vec3::Zero(), Mat3::Identity(), -1, "ball", SphericalEuler{});
  const Model m = b.finalize();
  State s;
  s.t = 0.5;
  s.q = Vec3(0.3, 0.5 * M_PI - 1e-3, -0.2);
  s.qdot = Vec3::Zero();
  EXPECT_NEAR(checkJointSingularities(m, s, 1e-4, 1e-3), std::sin(1e-3), 1e-12);
  s.q[1] = 0.5 * M_PI - 1e-5;
  try {
    checkJointSingularities(m, s, 1e-4, 1e-3);
    ADD_FAILURE() << "no error at |cos q2| = 1e-5";
  } catch (const SimulationError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("joint 'ball'"), std::string::npos) << w;
    EXPECT_NE(w.find("t = 0.5"), std::string::npos) << w;
    EXPECT_NE(w.find("h = 0.001"), std::string::npos) << w;
    EXPECT_EQ(e.time, 0.5);
  }

  for (const std::string integ : {"rk45", "euler"}) {
    const GimbalCase c = runGimbalCase(integ, 1e-3);
    std::printf("%s: %s\n  closest |cos q2| %.3e; unguarded: %s\n", integ.c_str(), c.message.c_str(), c.min_distance,
                c.unguarded.c_str());
    record("gimbal_" + integ + "_closest", c.min_distance);
    record("gimbal_" + integ + "_unguarded_closest", c.unguarded_min_distance);
    EXPECT_TRUE(c.reported) << integ;
    EXPECT_TRUE(c.state_finite) << integ;
    EXPECT_NE(c.message.find("joint 'ball'"), std::string::npos) << c.message;
    EXPECT_GT(c.report_time, 0.0);
    EXPECT_LT(c.min_distance, 1e-3) << integ;  // it got close before the report
  }
}

// 3. a 10 g distal link spanned by a 1 kg muscle (mass ratio 1:100): rk45 keeps the energy, the
// fixed-step methods survive at their finest step.
TEST(HardCases, LightDistalLinkHeavyMuscle) {
  const std::vector<HardRun> runs = runLightDistalCase(true);
  for (const auto& r : runs) {
    std::printf("%-10s %-8.0e %s drift %.3e J  %s\n", r.integrator.c_str(), r.value, r.ok ? "ok  " : "FAIL",
                r.max_energy_err, r.failure.substr(0, 100).c_str());
    if (r.integrator == "rk45" && r.value == 1e-9) {
      record("light_distal_rk45_1e-9_drift", r.max_energy_err);
      EXPECT_TRUE(r.ok) << r.failure;
      EXPECT_LE(r.max_energy_err, 1e-6);
    }
    if (r.value == 1e-4) {
      EXPECT_TRUE(r.ok) << r.integrator << ": " << r.failure;
    }
  }
}

// 4. stiff spring, omega = 1000 rad/s: symplectic Euler is stable exactly below h = 2 / omega
// (the closed-form limit of the method on a harmonic oscillator), linearly implicit bdf1 at every
// step up to 1 s.
TEST(HardCases, StiffSpringImplicitStableWhereExplicitDiverges) {
  const double limit = 2.0 / 1000.0;
  EXPECT_TRUE(stiffStable("euler", 0.99 * limit));
  EXPECT_FALSE(stiffStable("euler", 1.01 * limit));
  for (double f : {1.01, 10.0, 100.0}) EXPECT_TRUE(stiffStable("bdf1", f * limit)) << f;
  const StiffCase c = runStiffCase();
  record("stiff_euler_largest_stable", c.euler_largest_stable);
  record("stiff_bdf1_largest_stable", c.bdf1_largest_stable);
  EXPECT_NEAR(c.euler_largest_stable / c.euler_theory, 1.0, 0.01);
  EXPECT_GE(c.bdf1_largest_stable, 0.99);
}

// 5. 60 s of the conservative pendulum_straight scene (1 kg muscle on 20 points) with rk45 at rtol
// 1e-10: the energy error stays below 1e-7 J (the scene's energy scale is ~10 J).
TEST(HardCases, LongRunWithoutDrift) {
  const HardRun r = runLongRunCase(modelsDir(), 60.0, 1e-10);
  record("long_run_max_energy_err", r.max_energy_err);
  record("long_run_drift_per_s", r.max_energy_err / 60.0);
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_NEAR(r.t_reached, 60.0, 1e-9);
  EXPECT_LE(r.max_energy_err, 1e-7);
}

// 6. a conditional path point switching during a run: each energy jump equals the change of the
// mass points' kinetic and potential energy at the switch state (same q, qdot on both branches),
// and between switches the energy is kept.
TEST(HardCases, ConditionalPointEnergyJumps) {
  const ConditionalCase c = runConditionalCase(2.0);
  ASSERT_GE(c.switches.size(), 2u);
  double jmax = 0.0;
  for (const auto& s : c.switches) {
    std::printf("switch at t = %.4f: measured %.4e J, predicted %.4e J\n", s.time, s.measured, s.predicted);
    EXPECT_GT(std::abs(s.predicted), 1e-4);
    EXPECT_NEAR(s.measured, s.predicted, 0.02 * std::abs(s.predicted) + 1e-7) << s.time;
    jmax = std::max(jmax, std::abs(s.measured));
  }
  record("conditional_max_jump", jmax);
  record("conditional_smooth_drift", c.smooth_drift);
  EXPECT_LE(c.smooth_drift, 1e-6);
}

// 7. a force that turns NaN at t = 0.25 s stops every integrator there, naming the time, the
// coordinate and the step (divergence is covered by simulate_test and simulate_cli_test).
TEST(HardCases, NanStopsTheRunNamingTimeCoordinateStep) {
  for (const std::string integ : {"euler", "bdf1", "rk45", "cvode"}) {
    const NanCase c = runNanCase(integ);
    std::printf("%s: %s\n", integ.c_str(), c.message.c_str());
    ASSERT_TRUE(c.stopped) << integ;
    EXPECT_GE(c.time, 0.25 - 1e-9) << integ;
    EXPECT_LT(c.time, 0.3) << integ;
    EXPECT_NE(c.message.find("t = "), std::string::npos) << c.message;
    EXPECT_NE(c.message.find("h = "), std::string::npos) << c.message;
    EXPECT_NE(c.message.find("coordinate 'q"), std::string::npos) << c.message;
  }
}

/// NaN from t = 0.1 s on the first coordinate
class NanForce final : public ForceTerm {
 public:
  std::string name() const override { return "nan_force"; }
  void addForce(const Model&, const State& s, const TermContext&, VecX& f) const override {
    if (s.t >= 0.1) f[0] = std::numeric_limits<double>::quiet_NaN();
  }
};

// the same through the simulate() driver behind `redmax simulate` (its failure is exit 1)
TEST(HardCases, SimulateDriverStopsOnNaN) {
  for (const std::string integ : {"euler", "rk45"}) {
    SimulationModel m = loadSimulationModel(modelsDir() + "/double_pendulum_via.osim", {});
    m.system->addTerm(std::make_shared<NanForce>());
    SimulateOptions o;
    o.integrator = integ;
    o.duration = 0.5;
    const SimulationResult r = simulate(m, defaultInitialState(m), o);
    std::printf("%s: %s\n", integ.c_str(), r.failure.c_str());
    ASSERT_TRUE(r.failed) << integ;
    EXPECT_GE(r.failure_time, 0.1 - 1e-9);
    EXPECT_LT(r.failure_time, 0.15);
    // the quantity: fixed-step methods name the coordinate; the adaptive ones' right-hand side
    // names the entry of qddot by index (simulate() does not translate that one)
    EXPECT_TRUE(r.failure.find("coordinate '") != std::string::npos || r.failure.find("qddot[") != std::string::npos)
        << r.failure;
    EXPECT_NE(r.failure.find("t = "), std::string::npos) << r.failure;
    EXPECT_NE(r.failure.find("h = "), std::string::npos) << r.failure;
    EXPECT_TRUE(r.states.data.allFinite());
  }
}

}  // namespace
