// RigidTendonMuscle and Schutte1993Muscle_Deprecated on analytic test curves (the Hill library
// takes its curves from outside, curve.hpp): their equations against closed forms derived here,
// the equilibrium residual within OpenSim's 0.01 N, and refused values. The spline curves that
// OpenSim's files give are checked in tests/converter/muscle_models_test.cpp.
#include "core/muscles/hill/rigid_tendon_muscle.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/muscles/hill/factory.hpp"
#include "tests/core/muscles/hill/hill_test_util.hpp"

namespace redmax::hill {
namespace {

using test::centralDifference;

// f(x) with its derivative, as a curve
class LambdaCurve final : public Curve {
 public:
  LambdaCurve(std::function<double(double)> f, std::function<double(double)> df)
      : f_(std::move(f)), df_(std::move(df)) {}
  double value(double x) const override { return f_(x); }
  double derivative(double x) const override { return df_(x); }
  std::string typeName() const override { return "test"; }

 private:
  std::function<double(double)> f_, df_;
};

CurvePtr gaussian() {  // active force-length
  return std::make_shared<LambdaCurve>([](double l) { return std::exp(-(l - 1) * (l - 1) / 0.45); },
                                       [](double l) { return -2 * (l - 1) / 0.45 * std::exp(-(l - 1) * (l - 1) / 0.45); });
}
CurvePtr quadraticAbove(double x0, double k) {  // passive / tendon: k (x - x0)^2 above x0
  return std::make_shared<LambdaCurve>([=](double x) { return x > x0 ? k * (x - x0) * (x - x0) : 0.0; },
                                       [=](double x) { return x > x0 ? 2 * k * (x - x0) : 0.0; });
}
CurvePtr hillForceVelocity() {  // 1.5 - 0.5 / (1 + v) style: any smooth increasing function
  return std::make_shared<LambdaCurve>([](double v) { return 1.0 + 0.5 * std::tanh(3 * v); },
                                       [](double v) { return 1.5 / std::pow(std::cosh(3 * v), 2); });
}

MuscleParameters base(const std::string& name) {
  MuscleParameters p;
  p.name = name;
  p.set("max_isometric_force", 500);
  p.set("optimal_fiber_length", 0.1);
  p.set("tendon_slack_length", 0.2);
  p.set("pennation_angle_at_optimal", 0.3);
  p.set("max_contraction_velocity", 10);
  return p;
}

MuscleParameters rigid() {
  MuscleParameters p = base("rigid");
  p.curves["active_force_length_curve"] = gaussian();
  p.curves["passive_force_length_curve"] = quadraticAbove(1.0, 4.0);
  p.curves["force_velocity_curve"] = hillForceVelocity();
  return p;
}

MuscleParameters schutte() {
  MuscleParameters p = base("schutte");
  p.set("damping", 0.05);
  p.curves["active_force_length_curve"] = gaussian();
  p.curves["tendon_force_length_curve"] = quadraticAbove(0.0, 1000.0);  // 1 at 3.2% strain
  return p;
}

TEST(RigidTendonMuscle, ForceIsTheFibresAlongTheRigidTendon) {
  const auto m = makeMuscleModel("RigidTendonMuscle", rigid());
  EXPECT_EQ(m->numStates(), 0);
  const double w = 0.1 * std::sin(0.3);
  for (double L : {0.26, 0.3, 0.33}) {
    for (double v : {-0.4, 0.0, 0.25}) {
      MuscleOutput out;
      m->calc(nullptr, {L, v, 0.7}, out, nullptr);
      // closed form: the fibre spans l - l_s at width w, the tendon stays at its slack length
      const double along = L - 0.2, lf = std::sqrt(along * along + w * w), cosphi = along / lf;
      const double lN = lf / 0.1, vN = v / (0.1 * 10);
      const double fal = std::exp(-(lN - 1) * (lN - 1) / 0.45);
      const double fpe = lN > 1 ? 4 * (lN - 1) * (lN - 1) : 0.0;
      const double fv = 1.0 + 0.5 * std::tanh(3 * vN);
      EXPECT_NEAR(out.fiber_length, lf, 1e-15);
      EXPECT_NEAR(std::cos(out.pennation_angle), cosphi, 1e-14);
      EXPECT_EQ(out.tendon_length, 0.2);
      EXPECT_EQ(out.fiber_velocity, v);  // OpenSim's: the path speed, not its projection
      EXPECT_NEAR(out.tendon_force, 500 * (0.7 * fal * fv + fpe) * cosphi, 1e-11);
      EXPECT_NEAR(m->inextensibleTendonActiveFiberForce({L, v, 0}, 0.7), 500 * 0.7 * fal * fv * cosphi, 1e-11);
    }
  }
  // the passive multiplier is clamped to [0, 10] (OpenSim 4's calcMuscleLengthInfo): 4 (lN - 1)^2 = 10
  // at lN = 2.58, so the force stops growing there
  MuscleOutput a, b;
  m->calc(nullptr, {0.2 + 0.35, 0, 0}, a, nullptr);
  m->calc(nullptr, {0.2 + 0.45, 0, 0}, b, nullptr);
  EXPECT_NEAR(a.passive_fiber_force, 5000, 1e-9);
  EXPECT_NEAR(b.passive_fiber_force, 5000, 1e-9);
}

TEST(RigidTendonMuscle, SlackPathAndUnpennatedFibre) {
  // a path shorter than the tendon: the fibre is as long as the muscle is wide, at 90 degrees,
  // and pulls nothing along the path (cos phi = 0); without pennation the fibre is the rest
  const auto m = makeMuscleModel("RigidTendonMuscle", rigid());
  MuscleOutput out;
  m->calc(nullptr, {0.15, 0, 1}, out, nullptr);
  EXPECT_NEAR(out.fiber_length, 0.1 * std::sin(0.3), 1e-16);
  EXPECT_NEAR(out.pennation_angle, M_PI / 2, 1e-15);
  EXPECT_EQ(out.tendon_force, 0.0);
  MuscleParameters p = rigid();
  p.set("pennation_angle_at_optimal", 0);
  const auto flat = makeMuscleModel("RigidTendonMuscle", p);
  flat->calc(nullptr, {0.3, 0, 1}, out, nullptr);
  EXPECT_NEAR(out.fiber_length, 0.1, 1e-16);
  EXPECT_EQ(out.pennation_angle, 0.0);
  EXPECT_NEAR(out.tendon_force, 500.0, 1e-12);  // fal(1) = 1, fv(0) = 1, fpe(1) = 0
}

TEST(Schutte1993Muscle, ActivationAndFibreVelocityClosedForms) {
  const auto m = makeMuscleModel("Schutte1993Muscle_Deprecated", schutte());
  const auto& s = dynamic_cast<const Schutte1993MuscleDeprecated&>(*m);
  ASSERT_EQ(m->stateNames(), (std::vector<std::string>{"activation", "fiber_length"}));
  // da/dt = (u - a)(7.667 u + 1.459854) / 0.1 rising, (u - a) 1.459854 / 0.1 falling (the defaults)
  double z[2] = {0.3, 0.1}, zd[2];
  MuscleOutput out;
  m->calc(z, {0.3, 0, 0.8}, out, zd);
  EXPECT_NEAR(zd[0], (0.8 - 0.3) * (7.667 * 0.8 + 1.459854) / 0.1, 1e-12);
  m->calc(z, {0.3, 0, 0.1}, out, zd);
  EXPECT_NEAR(zd[0], (0.1 - 0.3) * 1.459854 / 0.1, 1e-12);
  // The inverse force-velocity solves, with alpha = 0.13 kv / (kv + 1), kv = 0.15, damping d:
  //   shortening  Fv = Fa kv (1 + v) / (kv - v) + d v
  //   lengthening Fv = Fa (alpha + 1.4 v) / (alpha + v) + d v
  // (the quadratics of OpenSim's calcFiberVelocity, rearranged): check the velocity it returns
  const double kv = 0.15, alpha = 0.13 * kv / (kv + 1), d = 0.05;
  double worst = 0;
  for (double Fa : {0.2, 0.6, 1.0})
    for (double r = 0.02; r < 2.5; r += 0.07) {
      const double Fv = r * Fa;
      const double v = s.fiberVelocity(1.0, Fa, Fv);
      const double back = v <= 0 ? Fa * kv * (1 + v) / (kv - v) + d * v : Fa * (alpha + 1.4 * v) / (alpha + v) + d * v;
      worst = std::max(worst, std::abs(back - Fv));
      if (std::abs(Fv - Fa) > 1e-9) EXPECT_EQ(v > 0, Fv > Fa) << Fa << " " << Fv;
    }
  std::printf("[ measured ] Schutte inverse force-velocity residual %.2e\n", worst);
  EXPECT_LE(worst, 2e-14);  // measured 3.2e-15
  EXPECT_EQ(s.fiberVelocity(1.0, 0.6, 0.6), 0.0);
  // default passive curve: exp(8 (l - 1)) / exp(4), 1 at l = 1.5
  EXPECT_NEAR(s.passiveForce(1.5), 1.0, 1e-15);
  EXPECT_NEAR(s.passiveForce(1.0), std::exp(-4.0), 1e-16);
  EXPECT_EQ(s.tendonForce(-0.01), 0.0);
  EXPECT_NEAR(s.tendonForce(0.02), 1000 * 0.02 * 0.02, 1e-15);
}

TEST(Schutte1993Muscle, RatesFollowTheForceBalance) {
  // fibre rate = l_opt / time_scale * v(F_T / cos phi - F_PE), with the tendon from the path
  const auto m = makeMuscleModel("Schutte1993Muscle_Deprecated", schutte());
  const auto& s = dynamic_cast<const Schutte1993MuscleDeprecated&>(*m);
  for (double lf : {0.08, 0.1, 0.115}) {
    const double z[2] = {0.6, lf};
    double zd[2];
    MuscleOutput out;
    const double L = 0.3;
    m->calc(z, {L, 0.0, 0.6}, out, zd);
    const double phi = std::asin(0.1 * std::sin(0.3) / lf);
    const double tl = L - lf * std::cos(phi), e = (tl - 0.2) / 0.2;
    const double FT = e > 0 ? 1000 * e * e : 0.0;
    const double lN = lf / 0.1, fal = std::exp(-(lN - 1) * (lN - 1) / 0.45);
    const double fpe = std::exp(8 * (lN - 1)) / std::exp(4.0);
    const double v = s.fiberVelocity(0.6, fal, std::max(0.0, FT / std::cos(phi) - fpe));
    EXPECT_NEAR(out.tendon_force, 500 * FT, 1e-9);
    EXPECT_NEAR(zd[1], v * 0.1 / 0.1, 1e-12);
    EXPECT_NEAR(out.tendon_length, tl, 1e-15);
  }
}

TEST(Schutte1993Muscle, EquilibriumWithinOpenSimsLimit) {
  const auto m = makeMuscleModel("Schutte1993Muscle_Deprecated", schutte());
  double worst = 0, worst_rate = 0;
  for (double L : {0.28, 0.3, 0.32})
    for (double a : {0.05, 0.5, 1.0}) {
      double z[2] = {a, 0.0}, zd[2];
      m->equilibrate({L, 0, a}, z);
      MuscleOutput out;
      m->calc(z, {L, 0, a}, out, zd);
      // OpenSim's ERROR_LIMIT 0.01 N on |F_T - (a fal + fpe) F_max cos phi|
      const double lN = z[1] / 0.1, fal = std::exp(-(lN - 1) * (lN - 1) / 0.45);
      const double fpe = std::exp(8 * (lN - 1)) / std::exp(4.0);
      const double resid = out.tendon_force - (a * fal + fpe) * 500 * std::cos(out.pennation_angle);
      worst = std::max(worst, std::abs(resid));
      worst_rate = std::max(worst_rate, std::abs(zd[1]));
    }
  std::printf("[ measured ] Schutte equilibrium residual %.2e N, fibre rate %.2e m/s\n", worst, worst_rate);
  EXPECT_LE(worst, 0.01);  // OpenSim's ERROR_LIMIT
  // isometric: the fibre rate there is small against l_opt / time_scale = 1 m/s
  EXPECT_LE(worst_rate, 5e-5);  // measured 1.0e-5
}

TEST(Schutte1993Muscle, CurveDerivativesAreTheCurves) {
  // the interface carries each curve's own derivative; the test curves' against central differences
  for (const CurvePtr& c : {gaussian(), quadraticAbove(1.0, 4.0), hillForceVelocity()})
    for (double x : {-0.3, 0.4, 1.2, 1.7})
      EXPECT_NEAR(c->derivative(x), centralDifference([&](double t) { return c->value(t); }, x), 1e-8);
}

TEST(Schutte1993Muscle, RefusedValuesNameTheirProperty) {
  for (const char* key : {"time_scale", "damping", "activation2"}) {
    MuscleParameters p = schutte();
    p.set(key, 0.0);
    try {
      makeMuscleModel("Schutte1993Muscle_Deprecated", p);
      ADD_FAILURE() << key;
    } catch (const MuscleParameterError& e) {
      EXPECT_EQ(e.property(), key);
    }
  }
  // an absent curve with no spline factory to make its default
  MuscleParameters p = rigid();
  p.curves.erase("force_velocity_curve");
  try {
    makeMuscleModel("RigidTendonMuscle", p);
    ADD_FAILURE();
  } catch (const MuscleParameterError& e) {
    EXPECT_EQ(e.property(), "force_velocity_curve");
  }
}

}  // namespace
}  // namespace redmax::hill
