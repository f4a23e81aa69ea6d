// Millard2012EquilibriumMuscle: equilibrium, the damped and the classic fibre velocity, the
// rigid tendon, ignored activation dynamics, minimum fibre length, and OpenSim's parameter rules.
#include "core/muscles/hill/millard2012_equilibrium_muscle.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/muscles/hill/factory.hpp"
#include "tests/core/muscles/hill/hill_test_util.hpp"

namespace redmax::hill {
namespace {

using test::nearRel;

// a pennated muscle with a long tendon (soleus-like), OpenSim's curve defaults
MuscleParameters soleus() {
  MuscleParameters p;
  p.name = "soleus";
  p.set("max_isometric_force", 3549);
  p.set("optimal_fiber_length", 0.05);
  p.set("tendon_slack_length", 0.25);
  p.set("pennation_angle_at_optimal", 0.4363);
  return p;
}

// the static balance the equilibrium solves, evaluated from the model's curves: F_T - F_M cos(phi)
double staticImbalance(const Millard2012EquilibriumMuscle& m, double a, double L, double lf) {
  const auto& mp = m.properties();
  const double phi = m.pennation().pennationAngle(lf);
  const double tl = L - lf * std::cos(phi);
  const double lceN = lf / mp.optimal_fiber_length;
  const double Fm = (a * m.activeForceLengthCurve().value(lceN) + m.fiberForceLengthCurve().value(lceN)) *
                    mp.max_isometric_force;
  return m.tendonForceLengthCurve().value(tl / mp.tendon_slack_length) * mp.max_isometric_force - Fm * std::cos(phi);
}

TEST(Millard2012EquilibriumMuscle, EquilibrateBalancesDampedAndClassic) {
  for (double beta : {0.1, 0.0}) {
    MuscleParameters p = soleus();
    p.set("fiber_damping", beta);
    const Millard2012EquilibriumMuscle m(p);
    EXPECT_EQ(m.damped(), beta > 0);
    const double F_max = 3549;
    double worst = 0;
    for (double a : {0.01, 0.3, 1.0})
      for (double L : {0.28, 0.29, 0.30, 0.31}) {
        double z[2];
        m.defaultState(z);
        z[0] = a;
        m.equilibrate({L, 0.0, a}, z);
        ASSERT_GE(z[1], m.minFiberLength());
        worst = std::max(worst, std::abs(staticImbalance(m, a, L, z[1])));
        // the model's own outputs: tendon = (active + passive) cos(phi), and the fibre at rest
        MuscleOutput out;
        double zdot[2];
        m.calc(z, {L, 0.0, a}, out, zdot);
        EXPECT_NEAR(out.tendon_force,
                    (out.active_fiber_force + out.passive_fiber_force) * std::cos(out.pennation_angle),
                    1e-8 * F_max)
            << beta << " " << a << " " << L;
        EXPECT_NEAR(zdot[1], 0.0, 1e-6) << beta << " " << a << " " << L;
      }
    EXPECT_LE(worst, 1.5e-8 * F_max) << "beta " << beta;
  }
}

TEST(Millard2012EquilibriumMuscle, DampedVelocitySolvesTheDampedBalance) {
  const Millard2012EquilibriumMuscle m(soleus());
  const double F_max = 3549, beta = 0.1;
  for (double lf : {0.04, 0.05, 0.06})
    for (double L : {0.28, 0.3}) {
      const double z[2] = {0.4, lf};
      MuscleOutput out;
      double zdot[2];
      m.calc(z, {L, 0.05, 0.4}, out, zdot);
      const double v = out.normalized_fiber_velocity;
      const double lceN = lf / 0.05;
      const double Fm = (0.4 * m.activeForceLengthCurve().value(lceN) * m.forceVelocityCurve().value(v) +
                         m.fiberForceLengthCurve().value(lceN) + beta * v) *
                        F_max;
      EXPECT_NEAR(Fm * std::cos(out.pennation_angle), out.tendon_force, 1e-9 * F_max) << lf << " " << L;
      EXPECT_NEAR(zdot[1], v * 10 * 0.05, 1e-15);
      EXPECT_NEAR(out.passive_fiber_force, (m.fiberForceLengthCurve().value(lceN) + beta * v) * F_max, 1e-9 * F_max);
    }
}

TEST(Millard2012EquilibriumMuscle, ClassicVelocityFromTheInverseCurve) {
  MuscleParameters p = soleus();
  p.set("fiber_damping", 0.0);
  const Millard2012EquilibriumMuscle m(p);
  EXPECT_EQ(m.curveParameters().minimum_value, 0.1);  // raised for the classic model
  EXPECT_EQ(m.curveParameters().concentric_slope_at_vmax, 0.125);  // half the near slope
  const double z[2] = {0.4, 0.05};
  MuscleOutput out;
  double zdot[2];
  m.calc(z, {0.29, 0.0, 0.4}, out, zdot);
  const double lceN = 1.0;
  const double fv = (out.tendon_force / 3549 / std::cos(out.pennation_angle) - m.fiberForceLengthCurve().value(lceN)) /
                    (0.4 * m.activeForceLengthCurve().value(lceN));
  EXPECT_NEAR(out.normalized_fiber_velocity, m.forceVelocityInverseCurve().value(fv), 1e-14);
}

TEST(Millard2012EquilibriumMuscle, RigidTendonAndIgnoredActivation) {
  MuscleParameters p = soleus();
  p.set("ignore_tendon_compliance", 1);
  const Millard2012EquilibriumMuscle rigid(p);
  ASSERT_EQ(rigid.stateNames(), std::vector<std::string>{"activation"});
  const double h = 0.05 * std::sin(0.4363), L = 0.3;
  double z[1] = {0.5}, zdot[1];
  MuscleOutput out;
  rigid.calc(z, {L, -0.1, 0.8}, out, zdot);
  EXPECT_NEAR(out.fiber_length, std::hypot(h, L - 0.25), 1e-15);
  EXPECT_NEAR(out.tendon_length, 0.25, 1e-15);
  EXPECT_NEAR(out.fiber_velocity, -0.1 * std::cos(out.pennation_angle), 1e-15);
  EXPECT_NEAR(out.tendon_force, (out.active_fiber_force + out.passive_fiber_force) * std::cos(out.pennation_angle),
              1e-9);
  EXPECT_GT(zdot[0], 0.0);
  rigid.equilibrate({L, 0, 0.5}, z);  // nothing to solve
  EXPECT_EQ(z[0], 0.5);

  p.set("ignore_activation_dynamics", 1);
  const Millard2012EquilibriumMuscle none(p);
  EXPECT_EQ(none.numStates(), 0);
  none.calc(nullptr, {L, 0.0, 0.7}, out, nullptr);
  EXPECT_EQ(out.activation, 0.7);
  none.calc(nullptr, {L, 0.0, 1.7}, out, nullptr);
  EXPECT_EQ(out.activation, 1.0);  // excitation clamped to [minimum_activation, 1]

  MuscleParameters q = soleus();
  q.set("ignore_activation_dynamics", 1);
  const Millard2012EquilibriumMuscle elastic(q);
  ASSERT_EQ(elastic.stateNames(), std::vector<std::string>{"fiber_length"});
  double zl[1] = {0.05};
  elastic.equilibrate({L, 0, 0.6}, zl);
  EXPECT_LE(std::abs(staticImbalance(elastic, 0.6, L, zl[0])), 1.5e-8 * 3549);
}

TEST(Millard2012EquilibriumMuscle, FibreStaysAtOrAboveItsMinimumLength) {
  const Millard2012EquilibriumMuscle m(soleus());
  // max(min active length 0.4441 l_opt, h / sin(phi_max))
  const double h = 0.05 * std::sin(0.4363);
  EXPECT_NEAR(m.minFiberLength(), std::max(0.4441 * 0.05, h / std::sin(std::acos(0.1))), 1e-16);
  double z[2] = {1.0, 0.05};
  m.equilibrate({0.2, 0, 1.0}, z);  // shorter than the tendon: fibre at its minimum
  EXPECT_GE(z[1], m.minFiberLength());
  const double zs[2] = {0.5, 0.5 * m.minFiberLength()};
  MuscleOutput out;
  double zdot[2];
  m.calc(zs, {0.22, -0.5, 0.5}, out, zdot);
  EXPECT_EQ(out.fiber_length, m.minFiberLength());
  EXPECT_GE(zdot[1], 0.0);
}

TEST(Millard2012EquilibriumMuscle, ParameterRulesAsOpenSim) {
  const auto refuses = [](const std::string& key, double v, const std::string& other = "", double w = 0) {
    MuscleParameters p = soleus();
    p.set(key, v);
    if (!other.empty()) p.set(other, w);
    try {
      makeMuscleModel("Millard2012EquilibriumMuscle", p);
    } catch (const MuscleParameterError& e) {
      return e.property();
    }
    return std::string("(accepted)");
  };
  // optional curve properties: all or none
  EXPECT_EQ(refuses("TendonForceLengthCurve/curviness", 0.5), "TendonForceLengthCurve/stiffness_at_one_norm_force");
  EXPECT_EQ(refuses("ForceVelocityCurve/concentric_slope_near_vmax", 1e-9), "ForceVelocityCurve/concentric_slope_near_vmax");
  EXPECT_EQ(refuses("ActiveForceLengthCurve/max_norm_active_fiber_length", 0.9),
            "ActiveForceLengthCurve/max_norm_active_fiber_length");
  EXPECT_EQ(refuses("FiberForceLengthCurve/strain_at_one_norm_force", -0.1), "FiberForceLengthCurve/strain_at_one_norm_force");
  EXPECT_EQ(refuses("minimum_activation", 0.005, "fiber_damping", 0.0), "minimum_activation");  // classic
  EXPECT_EQ(refuses("minimum_activation", 0.005, "min_control", 0.005), "(accepted)");        // damped
  EXPECT_EQ(refuses("optimal_fiber_length", -1), "optimal_fiber_length");
  EXPECT_EQ(makeMuscleModel("Millard2012EquilibriumMuscle", soleus())->minControl(), 0.01);
}

}  // namespace
}  // namespace redmax::hill
