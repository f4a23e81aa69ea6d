// Thelen2003Muscle and Thelen2003Muscle_Deprecated: equilibrium, minimum fibre length, activation
// dynamics, the outputs' consistency and the parameter checks OpenSim makes.
#include "core/muscles/hill/thelen2003_muscle.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/muscles/hill/factory.hpp"
#include "tests/core/muscles/hill/hill_test_util.hpp"

namespace redmax::hill {
namespace {

using test::nearRel;

using test::triLong;

TEST(Thelen2003Muscle, EquilibrateBalancesFibreAndTendon) {
  const Thelen2003Muscle m(triLong());
  const auto& c = m.curves();
  const double F_max = 798.52, l_opt = 0.134;
  double worst = 0;
  for (double a : {0.01, 0.2, 1.0})
    for (double L : {0.25, 0.27, 0.29, 0.31, 0.33}) {
      double z[2] = {a, 0.1};
      m.equilibrate({L, 0.0, a}, z);
      ASSERT_GE(z[1], m.pennation().minFiberLength());
      // the balance OpenSim's initMuscleState solves, with fv = 1 at rest, evaluated here
      const double lceN = z[1] / l_opt;
      const double phi = std::asin(l_opt * std::sin(0.20943951) / z[1]);
      const double tl = L - z[1] * std::cos(phi);
      const double Ft = c.fse(tl / 0.143) * F_max;
      const double Fm = (a * c.fal(lceN) + c.fpe(lceN)) * F_max * std::cos(phi);
      worst = std::max(worst, std::abs(Ft - Fm));
      // and the model's outputs agree: at rest the fibre does not move
      MuscleOutput out;
      double zdot[2];
      m.calc(z, {L, 0.0, a}, out, zdot);
      EXPECT_NEAR(out.tendon_force, Ft, 1e-9 * F_max);
      EXPECT_NEAR(out.tendon_force, (out.active_fiber_force + out.passive_fiber_force) * std::cos(out.pennation_angle),
                  1e-9 * F_max);
      EXPECT_NEAR(zdot[1], 0.0, 1e-6) << a << " " << L;
      EXPECT_NEAR(out.pennation_angle, phi, 1e-12);
    }
  EXPECT_LE(worst, 1.5e-8 * F_max);
}

TEST(Thelen2003Muscle, FibreStaysAtOrAboveItsMinimumLength) {
  const Thelen2003Muscle m(triLong());
  const double l_min = m.pennation().minFiberLength();
  // phi_max = acos(0.1): l_min = l_opt sin(phi_opt) / sin(phi_max)
  EXPECT_NEAR(l_min, 0.134 * std::sin(0.20943951) / std::sin(std::acos(0.1)), 1e-15);
  // a path so short that the tendon alone is longer: the fibre sits at its minimum
  double z[2] = {0.5, 0.1};
  m.equilibrate({0.15, 0.0, 0.5}, z);
  EXPECT_GE(z[1], l_min);
  // a state below the minimum is read at the minimum, and a shortening fibre there is held
  const double zs[2] = {0.5, 0.5 * l_min};
  MuscleOutput out;
  double zdot[2];
  m.calc(zs, {0.16, -1.0, 0.5}, out, zdot);
  EXPECT_EQ(out.fiber_length, l_min);
  EXPECT_GE(zdot[1], 0.0);
  EXPECT_NEAR(out.pennation_angle, std::acos(0.1), 1e-12);
}

TEST(Thelen2003Muscle, ActivationDynamicsFollowThelen2003) {
  const Thelen2003Muscle m(triLong());
  const double ta = 0.01, td = 0.04;
  for (double a : {0.0, 0.01, 0.3, 0.9, 1.2})
    for (double u : {0.0, 0.2, 1.0}) {
      const double ac = std::clamp(a, 0.01, 1.0);
      const double tau = u > ac ? ta * (0.5 + 1.5 * ac) : td / (0.5 + 1.5 * ac);
      double z[2] = {a, 0.134}, zdot[2];
      MuscleOutput out;
      m.calc(z, {0.3, 0.0, u}, out, zdot);
      EXPECT_NEAR(zdot[0], (u - ac) / tau, 1e-12 * (1 + std::abs(zdot[0]))) << a << " " << u;
      EXPECT_EQ(out.activation, ac);  // clamped to [minimum_activation, 1]
    }
  // the rate is continuous in the excitation where it switches time constant: both sides -> 0
  double z[2] = {0.4, 0.134}, d1[2], d2[2];
  MuscleOutput out;
  m.calc(z, {0.3, 0, 0.4 + 1e-9}, out, d1);
  m.calc(z, {0.3, 0, 0.4 - 1e-9}, out, d2);
  EXPECT_NEAR(d1[0], 0.0, 1e-6);
  EXPECT_NEAR(d2[0], 0.0, 1e-6);
}

TEST(Thelen2003Muscle, FibreVelocityReproducesTheTendonForce) {
  // calc solves F_T / cos(phi) - F_PE = a fal fv(v) for v: the forward curve at that v gives back F_T
  const Thelen2003Muscle m(triLong());
  const auto& c = m.curves();
  for (double L : {0.26, 0.3, 0.32})
    for (double lf : {0.09, 0.12, 0.15}) {
      const double z[2] = {0.4, lf};
      MuscleOutput out;
      double zdot[2];
      m.calc(z, {L, 0.1, 0.4}, out, zdot);
      const double fal = c.fal(lf / 0.134);
      const double F = out.tendon_force / 798.52 / std::cos(out.pennation_angle) - c.fpe(lf / 0.134);
      EXPECT_TRUE(nearRel(out.normalized_fiber_velocity, c.dlceN(0.4, fal, F), 1e-14));
      EXPECT_TRUE(nearRel(zdot[1], out.normalized_fiber_velocity * 10 * 0.134, 1e-14));
    }
}

TEST(Thelen2003MuscleDeprecated, EquilibrateWithinOpenSimsLimit) {
  const Thelen2003MuscleDeprecated m(triLong());
  const auto& c = m.curves();
  for (double a : {0.05, 0.5, 1.0})
    for (double L : {0.26, 0.29, 0.32}) {
      double z[2] = {a, 0.0};
      m.equilibrate({L, 0.0, a}, z);
      const double phi = std::asin(0.134 * std::sin(0.20943951) / z[1]);
      const double tl = L - z[1] * std::cos(phi);
      const double Ft = c.tendon((tl - 0.143) / 0.143) * 798.52;
      const double Fm = (a * c.active(z[1] / 0.134) + c.passive(z[1] / 0.134)) * 798.52 * std::cos(phi);
      EXPECT_LE(std::abs(Ft - Fm), 0.01) << a << " " << L;  // OpenSim's ERROR_LIMIT, N
      EXPECT_GT(std::abs(Ft - Fm), 0.0);
      MuscleOutput out;
      double zdot[2];
      m.calc(z, {L, 0.0, a}, out, zdot);
      EXPECT_NEAR(out.tendon_force, Ft, 1e-9 * 798.52);
      // balanced to 0.01 N: the fibre creeps at most a little
      EXPECT_LT(std::abs(zdot[1]), 1e-3);
    }
}

TEST(Thelen2003MuscleDeprecated, DerivativesFollowThe2xCode) {
  const Thelen2003MuscleDeprecated m(triLong());
  const auto& c = m.curves();
  const double l_opt = 0.134, a = 0.3, u = 0.7, lf = 0.12, L = 0.3;
  const double z[2] = {a, lf};
  MuscleOutput out;
  double zdot[2];
  m.calc(z, {L, 0.2, u}, out, zdot);
  // activation: (u - a)/tau_a rising, no activation dependence in the time constant
  EXPECT_NEAR(zdot[0], (u - a) / 0.01, 1e-12);
  m.calc(z, {L, 0.2, 0.1}, out, zdot);
  EXPECT_NEAR(zdot[0], (0.1 - a) / 0.04, 1e-12);
  // fibre: the velocity-dependent force through the inverted force-velocity curve, scaled by
  // Vmax(a) = (Vmax0 + a (Vmax - Vmax0)) l_opt
  const double ca = std::cos(std::asin(std::sin(0.20943951) / (lf / l_opt)));
  const double ntl = L / l_opt - lf / l_opt * ca, rest = 0.143 / l_opt;
  const double Ft = c.tendon((ntl - rest) / rest);
  const double v = c.fiberVelocity(a, c.active(lf / l_opt), Ft / ca - c.passive(lf / l_opt));
  EXPECT_NEAR(zdot[1], v * (5 + a * 5) * l_opt, 1e-13);
  EXPECT_NEAR(out.fiber_velocity, zdot[1], 0);
  EXPECT_NEAR(out.tendon_force, Ft * 798.52, 1e-10);
  EXPECT_NEAR(out.tendon_force, (out.active_fiber_force + out.passive_fiber_force) * std::cos(out.pennation_angle),
              1e-9);
}

TEST(MuscleFactory, BuildsByClassAndRefusesBadValues) {
  EXPECT_EQ(makeMuscleModel("Thelen2003Muscle", triLong())->className(), "Thelen2003Muscle");
  EXPECT_EQ(makeMuscleModel("Thelen2003Muscle_Deprecated", triLong())->numStates(), 2);
  try {
    makeMuscleModel("NoSuchMuscle", triLong());
    FAIL() << "an unknown class must throw";
  } catch (const MuscleModelError& e) {
    EXPECT_NE(std::string(e.what()).find("NoSuchMuscle"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("Thelen2003Muscle"), std::string::npos);  // lists the known
  }
  const auto refuses = [](const std::string& cls, const std::string& key, double v) {
    MuscleParameters p = triLong();
    p.set(key, v);
    try {
      makeMuscleModel(cls, p);
    } catch (const MuscleParameterError& e) {
      return e.property() == key;
    }
    return false;
  };
  for (const char* cls : {"Thelen2003Muscle", "Thelen2003Muscle_Deprecated"}) {
    EXPECT_TRUE(refuses(cls, "optimal_fiber_length", -0.1)) << cls;
    EXPECT_TRUE(refuses(cls, "optimal_fiber_length", 0.0)) << cls;
    EXPECT_TRUE(refuses(cls, "pennation_angle_at_optimal", 1.6)) << cls;
    EXPECT_TRUE(refuses(cls, "Flen", 1.0)) << cls;
    EXPECT_TRUE(refuses(cls, "ignore_tendon_compliance", 1)) << cls;
  }
  EXPECT_TRUE(refuses("Thelen2003Muscle", "minimum_activation", 0.001));
  EXPECT_TRUE(refuses("Thelen2003Muscle", "min_control", 0.0));  // below minimum_activation
  EXPECT_TRUE(refuses("Thelen2003Muscle", "fv_linear_extrap_threshold", 0.5));
  EXPECT_TRUE(refuses("Thelen2003Muscle", "maximum_pennation_angle", 2.0));
  EXPECT_FALSE(refuses("Thelen2003Muscle", "Flen", 1.5));
  // defaults: Thelen2003Muscle's min_control is its minimum activation
  EXPECT_EQ(makeMuscleModel("Thelen2003Muscle", triLong())->minControl(), 0.01);
  EXPECT_EQ(makeMuscleModel("Thelen2003Muscle_Deprecated", triLong())->minControl(), 0.0);
}

}  // namespace
}  // namespace redmax::hill

namespace redmax::hill {
namespace {

// hard cases of the 2.x code: pennation at 90 degrees (a fibre no longer than its width) takes
// OpenSim's stiff-tendon branch; activation below 1e-6 is raised to 1e-6 in the velocity only
TEST(Thelen2003MuscleDeprecated, NinetyDegreePennationAndNearZeroActivation) {
  const Thelen2003MuscleDeprecated m(triLong());
  const double l_opt = 0.134, width = l_opt * std::sin(0.20943951);
  const double z[2] = {0.3, 0.9 * width};  // sin(phi) >= 1: phi = pi/2
  MuscleOutput out;
  double zdot[2];
  m.calc(z, {0.30, 0.2, 0.3}, out, zdot);
  EXPECT_EQ(out.pennation_angle, M_PI / 2);
  // OpenSim: h = l_MT / l_opt - l_s (a normalized length minus metres), w = l_opt sin(phi_opt)
  const double h = 0.30 / l_opt - 0.143;
  const double new_nfl = std::sqrt(h * h + width * width) / l_opt;
  const double new_ca = std::cos(std::asin(std::min(1.0, std::sin(0.20943951) / new_nfl)));
  const double vmax = (5 + 0.3 * 5) * l_opt;
  EXPECT_NEAR(zdot[1], 0.2 / (vmax * new_ca) * vmax, 1e-12);
  EXPECT_TRUE(std::isfinite(out.tendon_force));
  // (the 2.x tendon never carries zero force, 0.001 (1 + strain) even when slack, so OpenSim's
  // "tendon force zero: fibre at rest" branch at 90 degrees is taken only at strain -1)

  // activation 0: the velocity uses 1e-6, the activation rate the state itself
  const double z0[2] = {0.0, 0.12};
  m.calc(z0, {0.28, 0.0, 0.0}, out, zdot);
  EXPECT_EQ(zdot[0], 0.0);
  EXPECT_TRUE(std::isfinite(zdot[1]));
  const double z1[2] = {1e-6, 0.12};
  double zdot1[2];
  m.calc(z1, {0.28, 0.0, 0.0}, out, zdot1);
  // (Vmax differs with a; the normalized velocity does not)
  EXPECT_NEAR(zdot[1] / (5.0 * l_opt), zdot1[1] / ((5 + 1e-6 * 5) * l_opt), 1e-12);
}

}  // namespace
}  // namespace redmax::hill
