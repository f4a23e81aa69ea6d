// Thelen 2003's curves as OpenSim computes them: against the paper's equations evaluated here
// independently [Thelen 2003, Eqs. 1-5], and every derivative against central differences.
#include "core/muscles/hill/thelen2003_curves.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/core/muscles/hill/hill_test_util.hpp"

namespace redmax::hill {
namespace {

using test::centralDifference;
using test::nearRel;

TEST(Thelen2003Curves, MatchThePapersEquations) {
  const Thelen2003Curves c;  // OpenSim 4 defaults: e0 0.04, e0M 0.6, gamma 0.45, kPE 5, Af 0.25, Flen 1.4
  double worst = 0;
  for (double l = 0.3; l <= 1.9; l += 0.05) {
    // Eq. 3 (active) and Eq. 2 (passive, zero below the optimal length in OpenSim 4)
    const double fal = std::exp(-(l - 1) * (l - 1) / 0.45);
    const double fpe = l > 1 ? (std::exp(5.0 * (l - 1) / 0.6) - 1) / (std::exp(5.0) - 1) : 0.0;
    worst = std::max({worst, std::abs(c.fal(l) - fal), std::abs(c.fpe(l) - fpe)});
  }
  EXPECT_LE(worst, 1e-15);
  // Eq. 1: the tendon is 1 at e0, 0.33 at the toe strain, C1 there; eToe is the paper's 0.609 e0
  const double eT = c.toeStrain();
  EXPECT_NEAR(eT / 0.04, 0.609, 5e-4);
  EXPECT_NEAR(c.fse(1 + eT), 0.33, 5e-15);
  EXPECT_NEAR(c.fse(1.04), 1.0, 1e-14);
  EXPECT_NEAR(0.33 / (std::exp(3.0) - 1) * 3 / eT * std::exp(3.0), c.linearStiffness(), 1e-12);
  EXPECT_EQ(c.fse(0.99), 0.0);
  const double e = 0.5 * eT;
  EXPECT_NEAR(c.fse(1 + e), 0.33 * (std::exp(3 * e / eT) - 1) / (std::exp(3.0) - 1), 1e-15);
  // Eq. 5: v = (0.25 + 0.75 a)(F - a fl)/b, b = a fl + F/Af shortening,
  // b = (2 + 2/Af)(a fl Flen - F)/(Flen - 1) lengthening
  const double a = 0.6, fl = 0.8, afl = a * fl;
  for (double F : {0.05, 0.2, 0.4, 0.48}) {
    const double v = (0.25 + 0.75 * a) * (F - afl) / (afl + F / 0.25);
    EXPECT_NEAR(c.dlceN(a, fl, F), v, 1e-15) << F;
  }
  for (double F : {0.5, 0.55, 0.6}) {
    const double v = (0.25 + 0.75 * a) * (F - afl) / ((2 + 2 / 0.25) * (afl * 1.4 - F) / (1.4 - 1));
    EXPECT_NEAR(c.dlceN(a, fl, F), v, 1e-15) << F;
  }
  // isometric at F = a fl; the maximum shortening velocity at F = 0 is -(0.25 + 0.75 a)
  EXPECT_EQ(c.dlceN(a, fl, afl), 0.0);
  EXPECT_NEAR(c.dlceN(a, fl, 0.0), -(0.25 + 0.75 * a), 1e-15);
}

TEST(Thelen2003Curves, ExtrapolateLinearlyBeyondTheCurve) {
  const Thelen2003Curves c;
  const double a = 0.3, fl = 0.9, afl = a * fl;
  const double F1 = 0.95 * afl * 1.4;  // the eccentric threshold
  // continuous at both ends, with the curve's slope there (one-sided difference inside)
  for (double F0 : {0.0, F1}) {
    EXPECT_NEAR(c.dlceN(a, fl, F0 - 1e-12), c.dlceN(a, fl, F0 + 1e-12), 1e-10);
    const double inside = F0 == 0.0 ? F0 + 1e-7 : F0 - 1e-7;
    const double slope_in = (c.dlceN(a, fl, inside) - c.dlceN(a, fl, F0)) / (inside - F0);
    const double outside = F0 == 0.0 ? F0 - 0.1 : F0 + 0.1;
    EXPECT_NEAR(c.dDlceNDaFalFv(a, fl, outside), slope_in, 1e-5 * (1 + std::abs(slope_in))) << F0;
  }
  // and straight outside: equal second differences vanish
  const double x = F1 + 0.2;
  EXPECT_NEAR(c.dlceN(a, fl, x + 0.1) - 2 * c.dlceN(a, fl, x) + c.dlceN(a, fl, x - 0.1), 0.0, 1e-13);
}

TEST(Thelen2003Curves, DerivativesMatchCentralDifferences) {
  const Thelen2003Curves c;
  double worst = 0;
  for (double l = 0.31; l <= 1.9; l += 0.037) {
    worst = std::max(worst, std::abs(c.dfalDlceN(l) - centralDifference([&](double x) { return c.fal(x); }, l)));
    worst = std::max(worst, std::abs(c.dfpeDlceN(l) - centralDifference([&](double x) { return c.fpe(x); }, l)) /
                                (1 + c.dfpeDlceN(l)));
  }
  for (double t = 0.991; t <= 1.08; t += 0.0017) {
    if (std::abs(t - 1) < 1e-5 || std::abs(t - 1 - c.toeStrain()) < 1e-5) continue;  // kinks
    worst = std::max(worst, std::abs(c.dfseDtlN(t) - centralDifference([&](double x) { return c.fse(x); }, t)) /
                                (1 + c.dfseDtlN(t)));
  }
  for (double a : {0.01, 0.3, 1.0})
    for (double F = -0.2; F <= 2.0; F += 0.0531) {
      const double d = c.dDlceNDaFalFv(a, 0.7, F);
      const double fd = centralDifference([&](double x) { return c.dlceN(a, 0.7, x); }, F, 1e-7);
      worst = std::max(worst, std::abs(d - fd) / (1 + std::abs(d)));
    }
  EXPECT_LE(worst, 2e-7);
}

TEST(Thelen2003Curves, ForceVelocityInverseInvertsTheCurve) {
  const Thelen2003Curves c;
  for (double a : {0.01, 0.5, 1.0})
    for (double v : {-1.2, -0.5, -0.01, 0.0, 0.05, 0.3, 2.0}) {
      const double fv = c.fvInverse(a, 0.8, v, 1e-12, 100);
      if (v < -(0.25 + 0.75 * a))
        EXPECT_EQ(fv, 0.0) << a << " " << v;  // faster than v_max(a): OpenSim floors fv at 0
      else
        EXPECT_NEAR(c.dlceN(a, 0.8, a * 0.8 * fv), v, 1e-11) << a << " " << v;
    }
}

TEST(Thelen2003DeprecatedCurves, MatchThe2xEquationsAndDerivatives) {
  const Thelen2003DeprecatedCurves c;  // e0 0.033, gamma 0.5, kPE 4, damping 0.05, Af 0.3, Flen 1.8
  EXPECT_NEAR(c.active(1.3), std::exp(-0.09 / 0.5), 1e-16);
  EXPECT_NEAR(c.passive(1.3), std::exp(4 * 0.3 / 0.6) / std::exp(4.0), 1e-16);
  EXPECT_NEAR(c.passive(1.6), 1.0, 1e-15);  // 1 at 1 + e0M, then linear
  EXPECT_NEAR(c.passive(1.7), 1.0 + 0.1 * 4 / 0.6, 1e-14);
  const double eT = 0.609 * 0.033;
  EXPECT_NEAR(c.tendon(0.0), 0.001, 1e-16);  // the 0.001 (1 + e) floor
  EXPECT_NEAR(c.tendon(eT), 0.333333 + 0.001 * (1 + eT), 1e-12);
  EXPECT_NEAR(c.tendon(0.033), 1.712 / 0.033 * (0.033 - eT) + 0.333333 + 0.001 * 1.033, 1e-12);
  // Fv = a fl: no velocity; Fv = 0: (0 - Fa)/(Fa + damping)
  EXPECT_EQ(c.fiberVelocity(0.5, 0.9, 0.45), 0.0);
  EXPECT_NEAR(c.fiberVelocity(0.5, 0.9, 0.0), -0.45 / (0.45 + 0.05), 1e-15);
  double worst = 0;
  for (double l = 0.4; l <= 1.9; l += 0.031) {
    worst = std::max(worst, std::abs(c.dActive(l) - centralDifference([&](double x) { return c.active(x); }, l)));
    worst = std::max(worst, std::abs(c.dPassive(l) - centralDifference([&](double x) { return c.passive(x); }, l)));
  }
  for (double e = -0.01; e < 0.05; e += 0.0013) {
    if (std::abs(e) < 1e-5 || std::abs(e - eT) < 1e-5) continue;
    worst = std::max(worst, std::abs(c.dTendon(e) - centralDifference([&](double x) { return c.tendon(x); }, e)) /
                                (1 + c.dTendon(e)));
  }
  EXPECT_LE(worst, 1e-7);
  // the velocity is continuous across its three branch points
  const double Fa = 0.4;
  for (double F : {0.0, Fa, 0.95 * Fa * 1.8})
    EXPECT_NEAR(c.fiberVelocity(1.0, Fa, F - 1e-11), c.fiberVelocity(1.0, Fa, F + 1e-11), 1e-8) << F;
}

}  // namespace
}  // namespace redmax::hill
