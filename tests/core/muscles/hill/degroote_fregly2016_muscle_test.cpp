// DeGrooteFregly2016Muscle: its analytic curves against De Groote et al. 2016's definitions
// (values they are built to take) and central differences, the explicit tendon dynamics, the
// tanh-smoothed activation dynamics and the bisection equilibrium.
#include "core/muscles/hill/degroote_fregly2016_muscle.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/muscles/hill/factory.hpp"
#include "tests/core/muscles/hill/hill_test_util.hpp"

namespace redmax::hill {
namespace {

using test::centralDifference;

MuscleParameters gastroc() {
  MuscleParameters p;
  p.name = "gastroc";
  p.set("max_isometric_force", 1500);
  p.set("optimal_fiber_length", 0.06);
  p.set("tendon_slack_length", 0.39);
  p.set("pennation_angle_at_optimal", 0.3);
  return p;
}

TEST(DeGrooteFregly2016Curves, MatchThePapersDefinitions) {
  const DeGrooteFregly2016Curves c;
  EXPECT_NEAR(c.activeForceLength(1.0), 1.0, 2e-5);  // OpenSim adjusted b11 so that fal(1) ~ 1
  EXPECT_NEAR(c.passiveForceLength(0.2), 0.0, 1e-16);  // offset to zero at 0.2 l_opt
  EXPECT_NEAR(c.passiveForceLength(1.6), 1.0, 1e-15);  // 1 at 1 + e0
  EXPECT_NEAR(c.tendonForceLength(1.0), 0.0, 1e-16);   // slack at 1
  EXPECT_NEAR(c.tendonForceLength(1.049), 1.0, 1e-14);  // 1 at 1 + e0
  EXPECT_NEAR(c.tendonStiffness(), std::log(6.0) / 0.049, 1e-12);
  EXPECT_NEAR(DeGrooteFregly2016Curves::forceVelocity(0.0), 1.0, 1e-3);  // about 1 at rest
  // the paper's force-velocity: d1 ln(d2 v + d3 + sqrt((d2 v + d3)^2 + 1)) + d4
  const double v = -0.4, t = -8.149 * v - 0.374;
  EXPECT_NEAR(DeGrooteFregly2016Curves::forceVelocity(v),
              -0.3211346127989808 * std::asinh(t) + 0.8825327733249912, 1e-15);
  double worst = 0;
  for (double x = -1.0; x <= 1.0; x += 0.05)
    worst = std::max(worst, std::abs(DeGrooteFregly2016Curves::forceVelocityInverse(
                                         DeGrooteFregly2016Curves::forceVelocity(x)) - x));
  EXPECT_LE(worst, 1e-13);
  worst = 0;
  for (double l = 0.3; l <= 1.8; l += 0.017) {
    worst = std::max(worst, std::abs(c.activeForceLengthDerivative(l) -
                                     centralDifference([&](double y) { return c.activeForceLength(y); }, l)));
    worst = std::max(worst, std::abs(c.passiveForceLengthDerivative(l) -
                                     centralDifference([&](double y) { return c.passiveForceLength(y); }, l)));
  }
  for (double tl = 0.99; tl < 1.06; tl += 0.003)
    worst = std::max(worst, std::abs(c.tendonForceLengthDerivative(tl) -
                                     centralDifference([&](double y) { return c.tendonForceLength(y); }, tl)) /
                                (1 + c.tendonForceLengthDerivative(tl)));
  for (double x = -1.0; x <= 1.0; x += 0.05)
    worst = std::max(worst, std::abs(DeGrooteFregly2016Curves::forceVelocityDerivative(x) -
                                     centralDifference(DeGrooteFregly2016Curves::forceVelocity, x)));
  EXPECT_LE(worst, 1e-8);
}

TEST(DeGrooteFregly2016Muscle, EquilibriumAndExplicitTendonDynamics) {
  const DeGrooteFregly2016Muscle m(gastroc());
  ASSERT_EQ(m.stateNames(), (std::vector<std::string>{"activation", "normalized_tendon_force"}));
  for (double a : {0.05, 0.5, 1.0})
    for (double L : {0.43, 0.45, 0.47}) {
      double z[2];
      m.defaultState(z);
      z[0] = a;
      m.equilibrate({L, 0.0, a}, z);
      MuscleOutput out;
      double zdot[2];
      m.calc(z, {L, 0.0, a}, out, zdot);
      // fibre and tendon balance, and at rest the tendon force stays
      EXPECT_NEAR(out.tendon_force,
                  (out.active_fiber_force + out.passive_fiber_force) * std::cos(out.pennation_angle),
                  1e-8 * 1500);
      EXPECT_NEAR(zdot[1], 0.0, 1e-6) << a << " " << L;
    }
  // the tendon-force rate is the tendon's lengthening rate through the tendon curve
  const double z[2] = {0.5, 0.4};
  MuscleOutput out;
  double zdot[2];
  m.calc(z, {0.45, 0.1, 0.5}, out, zdot);
  const auto& c = m.curves();
  const double tlN = c.tendonForceLengthInverse(0.4);
  const double v_at = out.fiber_velocity / std::cos(out.pennation_angle);
  EXPECT_NEAR(zdot[1], (0.1 - v_at) / 0.39 * c.tendonForceLengthDerivative(tlN), 1e-12);
  EXPECT_NEAR(out.tendon_length, 0.39 * tlN, 1e-15);
}

TEST(DeGrooteFregly2016Muscle, SmoothedActivationDynamics) {
  const DeGrooteFregly2016Muscle m(gastroc());
  for (double a : {0.1, 0.6})
    for (double u : {0.0, 0.3, 1.0}) {
      const double z[2] = {a, 0.3};
      MuscleOutput out;
      double zdot[2];
      m.calc(z, {0.45, 0, u}, out, zdot);
      const double tf = 0.5 + 1.5 * a, f = 0.5 * std::tanh(0.1 * (u - a));
      EXPECT_NEAR(zdot[0], ((f + 0.5) / (0.015 * tf) + (0.5 - f) * tf / 0.060) * (u - a), 1e-12);
    }
}

TEST(DeGrooteFregly2016Muscle, RigidTendonAndRefusedValues) {
  MuscleParameters p = gastroc();
  p.set("ignore_tendon_compliance", 1);
  const DeGrooteFregly2016Muscle m(p);
  ASSERT_EQ(m.stateNames(), std::vector<std::string>{"activation"});
  const double z[1] = {0.7};
  MuscleOutput out;
  double zdot[1];
  m.calc(z, {0.45, -0.2, 0.7}, out, zdot);
  EXPECT_NEAR(out.tendon_length, 0.39, 1e-15);
  EXPECT_NEAR(out.fiber_velocity, -0.2 * std::cos(out.pennation_angle), 1e-15);
  EXPECT_NEAR(out.tendon_force, (out.active_fiber_force + out.passive_fiber_force) * std::cos(out.pennation_angle),
              1e-10);
  const auto refuses = [](const std::string& key, double v) {
    MuscleParameters q = gastroc();
    q.set(key, v);
    try {
      makeMuscleModel("DeGrooteFregly2016Muscle", q);
    } catch (const MuscleParameterError& e) {
      return e.property() == key;
    }
    return false;
  };
  EXPECT_TRUE(refuses("active_force_width_scale", 0.5));
  EXPECT_TRUE(refuses("tendon_strain_at_one_norm_force", 0));
  EXPECT_TRUE(refuses("default_normalized_tendon_force", 6));
  EXPECT_TRUE(refuses("tendon_compliance_dynamics_mode", 1));
  EXPECT_FALSE(refuses("fiber_damping", 0.01));
}

}  // namespace
}  // namespace redmax::hill
