// calcInextensibleTendonActiveFiberForce per class (static optimization's use_muscle_physiology):
// closed forms at rest (the fibre velocity 0, so fv = 1 or the class's fv(0)), at half
// activation, with the fibre lengthening, and below the minimum fibre length.
#include <gtest/gtest.h>

#include <cmath>

#include "core/muscles/hill/degroote_fregly2016_muscle.hpp"
#include "core/muscles/hill/millard2012_equilibrium_muscle.hpp"
#include "core/muscles/hill/thelen2003_muscle.hpp"
#include "tests/core/muscles/hill/hill_test_util.hpp"

namespace redmax::hill {
namespace {

using test::triLong;  // arm26's TRIlong (pennated, so the pennation terms count)
constexpr double kFmax = 798.52, kLopt = 0.134, kLs = 0.143, kPhiOpt = 0.20943951;
const double kH = kLopt * std::sin(kPhiOpt);

// the rigid tendon's fibre: length and cos(pennation) at path length L
void rigidFibre(double L, double& lf, double& cos_phi) {
  lf = std::sqrt(kH * kH + (L - kLs) * (L - kLs));
  cos_phi = (L - kLs) / lf;
}

TEST(InextensibleTendonActiveFiberForce, Thelen2003MuscleClosedForms) {
  const Thelen2003Muscle m(triLong());
  for (double L : {0.25, 0.277, 0.30}) {
    double lf, c;
    rigidFibre(L, lf, c);
    const double fal = std::exp(-(lf / kLopt - 1) * (lf / kLopt - 1) / 0.5);  // KshapeActive 0.5
    EXPECT_NEAR(m.inextensibleTendonActiveFiberForce({L, 0.0, 0.0}, 1.0), kFmax * fal * c, 1e-10 * kFmax);
    EXPECT_NEAR(m.inextensibleTendonActiveFiberForce({L, 0.0, 0.0}, 0.5), 0.5 * kFmax * fal * c, 1e-10 * kFmax);
    // activation is clamped to [minimum_activation, 1]
    EXPECT_NEAR(m.inextensibleTendonActiveFiberForce({L, 0.0, 0.0}, 0.0), 0.01 * kFmax * fal * c, 1e-10 * kFmax);
    // lengthening at 0.1 m/s: fv is the multiplier whose velocity is v cos(phi) / (v_max l_opt)
    const double F = m.inextensibleTendonActiveFiberForce({L, 0.1, 0.0}, 1.0);
    const double fv = F / (kFmax * fal * c);
    EXPECT_GT(fv, 1.0);
    EXPECT_NEAR(m.curves().dlceN(1.0, fal, fal * fv), 0.1 * c / (10 * kLopt), 1e-6);
  }
  // at or below the minimum fibre length along the tendon: no force
  EXPECT_EQ(m.inextensibleTendonActiveFiberForce({kLs + 1e-4, 0.0, 0.0}, 1.0), 0.0);
}

TEST(InextensibleTendonActiveFiberForce, Thelen2003MuscleDeprecatedIsIsometricForceTimesGenericFv) {
  const Thelen2003MuscleDeprecated m(triLong());
  for (double L : {0.25, 0.277, 0.30}) {
    for (double v : {0.0, -0.2, 0.3}) {
      double z[2] = {1.0, 0.0};
      m.equilibrate({L, v, 1.0}, z);
      MuscleOutput out;
      double zdot[2];
      m.calc(z, {L, v, 1.0}, out, zdot);
      const double nv = -std::cos(kPhiOpt) * v / (10 * kLopt);
      const double fv = 1.8 - 1.8 / (1.0 + std::exp((0.04 - nv) / 0.18));
      EXPECT_NEAR(m.inextensibleTendonActiveFiberForce({L, v, 0.0}, 1.0), out.tendon_force * fv, 1e-9 * kFmax)
          << L << " " << v;
    }
  }
  // a path shorter than the tendon's slack length carries nothing
  EXPECT_EQ(m.inextensibleTendonActiveFiberForce({0.1, 0.0, 0.0}, 1.0), 0.0);
}

TEST(InextensibleTendonActiveFiberForce, Millard2012PennationAtNormalizedLengthAsOpenSim) {
  const Millard2012EquilibriumMuscle m(triLong());
  for (double L : {0.25, 0.277, 0.30}) {
    double lf, c;
    rigidFibre(L, lf, c);
    const double lceN = lf / kLopt;
    // OpenSim's calcActiveFiberForceAlongTendon evaluates the pennation at lceN (not l_f)
    const double cos_n = std::sqrt(1.0 - (kH / lceN) * (kH / lceN));
    const double fal = m.activeForceLengthCurve().value(lceN);
    EXPECT_NEAR(m.inextensibleTendonActiveFiberForce({L, 0.0, 0.0}, 1.0),
                kFmax * fal * m.forceVelocityCurve().value(0.0) * cos_n, 1e-10 * kFmax);
    const double vN = 0.2 * c / (10 * kLopt);
    EXPECT_NEAR(m.inextensibleTendonActiveFiberForce({L, 0.2, 0.0}, 0.5),
                kFmax * 0.5 * fal * m.forceVelocityCurve().value(vN) * cos_n, 1e-10 * kFmax);
  }
  EXPECT_EQ(m.inextensibleTendonActiveFiberForce({kLs + 1e-4, 0.0, 0.0}, 1.0), 0.0);
}

TEST(InextensibleTendonActiveFiberForce, DeGrooteFregly2016AlongTheFibre) {
  const DeGrooteFregly2016Muscle m(triLong());
  for (double L : {0.25, 0.277, 0.30}) {
    double lf, c;
    rigidFibre(L, lf, c);
    const auto& k = m.curves();
    const double vN = -0.15 * c / (10 * kLopt);
    EXPECT_NEAR(m.inextensibleTendonActiveFiberForce({L, -0.15, 0.0}, 0.7),
                kFmax * 0.7 * k.activeForceLength(lf / kLopt) * k.forceVelocity(vN), 1e-10 * kFmax);
  }
}

}  // namespace
}  // namespace redmax::hill
