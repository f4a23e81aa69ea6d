// Hard cases of the Hill models, each with the failure it guards against:
//   - activation near zero: the fibre velocity divides by a fal (Thelen, Millard classic) or
//     solves with a vanishing active force; rates must stay finite, the fibre must give way;
//   - fibres at their minimum length: a fibre that would shorten further is held (rate 0, no
//     active force), one below it is read as at it;
//   - pennation near 90 degrees: F_T / cos(phi) grows without bound; the Deprecated models switch
//     to their stiff-tendon branch at 90 degrees;
//   - fibre lengths far outside the curves (as a long explicit trial stage gives them: arm26's
//     TRIlong reached -5.5 m in one rk45 stage): the Gaussian fal underflows to 0, so the
//     Deprecated force-velocity secant over [0.95, 0.95 + 1e-6] a fal Flen was 0/0 = NaN and
//     stopped a whole forward run; rates must stay finite at every finite state;
//   - very stiff tendons: the elastic tendon's equilibrium must approach the rigid tendon's as the
//     tendon stiffens (a model whose stiff limit is wrong would show it here first).
#include <gtest/gtest.h>

#include <cmath>

#include "core/muscles/hill/factory.hpp"
#include "core/muscles/hill/millard2012_equilibrium_muscle.hpp"
#include "core/muscles/hill/thelen2003_muscle.hpp"
#include "tests/core/muscles/hill/hill_test_util.hpp"

namespace redmax::hill {
namespace {

bool finiteOutput(const MuscleOutput& o, const double* zd, int n) {
  bool ok = std::isfinite(o.tendon_force) && std::isfinite(o.fiber_velocity) && std::isfinite(o.active_fiber_force) &&
            std::isfinite(o.passive_fiber_force) && std::isfinite(o.pennation_angle);
  for (int i = 0; i < n; ++i) ok = ok && std::isfinite(zd[i]);
  return ok;
}

TEST(HillHardCases, ActivationNearZeroKeepsRatesFiniteAndTheFibreGivesWay) {
  // TRIlong's properties read as each class with a fibre-length state; activation at 0, 1e-9
  // and 1e-3 (Thelen2003Muscle and Millard clamp it to minimum_activation 0.01)
  for (const std::string cls : {"Thelen2003Muscle", "Thelen2003Muscle_Deprecated", "Millard2012EquilibriumMuscle"}) {
    const auto m = makeMuscleModel(cls, test::triLong());
    const double l_opt = 0.134, l_s = 0.143;
    for (double a : {0.0, 1e-9, 1e-3})
      for (double lN : {0.6, 1.0, 1.4})
        for (double strain : {0.005, 0.02, 0.05}) {
          // a path that stretches the tendon by `strain` at this fibre length
          const double lf = lN * l_opt;
          const double phi = std::asin(std::min(0.99, l_opt * std::sin(0.20943951) / lf));
          const double L = l_s * (1 + strain) + lf * std::cos(phi);
          double z[2] = {a, lf}, zd[2];
          MuscleOutput out;
          m->calc(z, {L, 0.0, 0.0}, out, zd);
          ASSERT_TRUE(finiteOutput(out, zd, 2)) << cls << " a " << a << " lN " << lN << " e " << strain;
          // nearly no active force against a stretched tendon: the fibre lengthens (passive
          // force alone cannot hold a 2% or 5% tendon strain below lN 1.4)
          if (strain >= 0.02 && lN < 1.4) {
            EXPECT_GT(zd[1], 0.0) << cls << " a " << a << " lN " << lN;
          }
        }
  }
}

TEST(HillHardCases, FibreFarOutsideItsCurvesKeepsRatesFinite) {
  // the stage of arm26's F = 0.3 fibre-placement run (docs/forward.md §5): TRIlong at activation
  // 0.0100, fibre -5.465 m, path 0.292 m; then a sweep of absurd fibre lengths and paths.
  // Millard's curves have floors and linear ends: finite everywhere
  for (const std::string cls : {"Thelen2003Muscle", "Thelen2003Muscle_Deprecated", "Millard2012EquilibriumMuscle"}) {
    const auto m = makeMuscleModel(cls, test::triLong());
    for (double a : {0.0100137732, 0.5})
      for (double lf : {-5.46489121, -0.1, 1e-9, 3.0, 12.0})
        for (double L : {0.292, 0.5, 5.0})
          for (double speed : {0.0, -3.0}) {
            double z[2] = {a, lf}, zd[2];
            MuscleOutput out;
            m->calc(z, {L, speed, 0.05}, out, zd);
            // Thelen2003Muscle has no damping: where fal underflows its fibre rate's limit is
            // infinite (a named non-finite rate for the integrator), never NaN
            const bool ok = cls == "Thelen2003Muscle" ? !std::isnan(zd[0]) && !std::isnan(zd[1])
                                                      : std::isfinite(zd[0]) && std::isfinite(zd[1]);
            EXPECT_TRUE(ok) << cls << " a " << a << " l_f " << lf << " L " << L << ": rates " << zd[0] << ", "
                            << zd[1];
          }
  }
}

TEST(HillHardCases, FibreAtItsMinimumLengthIsHeld) {
  const auto m = makeMuscleModel("Thelen2003Muscle", test::triLong());
  const auto& th = dynamic_cast<const Thelen2003Muscle&>(*m);
  const double l_min = th.pennation().minFiberLength();
  // a short path (slack tendon), full excitation: the fibre would shorten; at and below l_min it
  // is held (OpenSim's clamp in calcMuscleLengthInfo and calcFiberVelocityInfo)
  const double L = 0.143 * 0.95 + 0.1 * l_min;
  for (double lf : {l_min, 0.5 * l_min, 1e-9}) {
    double z[2] = {1.0, lf}, zd[2];
    MuscleOutput out;
    m->calc(z, {L, 0.0, 1.0}, out, zd);
    ASSERT_TRUE(finiteOutput(out, zd, 2)) << lf;
    EXPECT_EQ(zd[1], 0.0) << lf;
    EXPECT_EQ(out.active_fiber_force, 0.0) << lf;
    EXPECT_EQ(out.fiber_length, l_min) << lf;
  }
  // just above it the fibre shortens again
  double z[2] = {1.0, 1.05 * l_min}, zd[2];
  MuscleOutput out;
  m->calc(z, {L, 0.0, 1.0}, out, zd);
  EXPECT_LT(zd[1], 0.0);
  // Millard: its equilibrium stops at its minimum length rather than failing
  const auto mil = makeMuscleModel("Millard2012EquilibriumMuscle", test::triLong());
  const auto& ml = dynamic_cast<const Millard2012EquilibriumMuscle&>(*mil);
  double zm[2] = {1.0, 0.1};
  mil->equilibrate({0.143 * 0.9, 0.0, 1.0}, zm);
  EXPECT_NEAR(zm[1], ml.minFiberLength(), 1e-12);
}

TEST(HillHardCases, PennationNearNinetyDegrees) {
  // Deprecated: a fibre as long as the muscle is wide is at 90 degrees; slack tendon: it stays;
  // pulled: the stiff-tendon velocity speed / (Vmax cos(phi')) of OpenSim's branch, finite
  MuscleParameters p = test::triLong();
  p.set("pennation_angle_at_optimal", 1.4);
  const auto dep = makeMuscleModel("Thelen2003Muscle_Deprecated", p);
  const double w = 0.134 * std::sin(1.4);
  for (double L : {0.1, 0.143 * 1.05 + w})
    for (double speed : {0.0, 0.3}) {
      double z[2] = {0.5, w}, zd[2];
      MuscleOutput out;
      dep->calc(z, {L, speed, 0.5}, out, zd);
      ASSERT_TRUE(finiteOutput(out, zd, 2)) << L << " " << speed;
      EXPECT_NEAR(out.pennation_angle, M_PI / 2, 1e-15);
    }
  // Thelen2003Muscle with pennation 1.4 rad at optimal and its maximum acos(0.001): near 90
  // degrees at short fibres F_T / cos(phi) is ~1000 F_T; rates finite, equilibrium found
  p.set("maximum_pennation_angle", std::acos(0.001));
  const auto th = makeMuscleModel("Thelen2003Muscle", p);
  const double l_min = dynamic_cast<const Thelen2003Muscle&>(*th).pennation().minFiberLength();
  for (double lf : {l_min, 1.0005 * l_min, 1.01 * l_min, 1.2 * l_min}) {
    for (double L : {0.143 * 1.02, 0.143 * 1.04}) {
      double z[2] = {0.5, lf}, zd[2];
      MuscleOutput out;
      th->calc(z, {L + lf * 0.05, 0.0, 0.5}, out, zd);
      ASSERT_TRUE(finiteOutput(out, zd, 2)) << lf << " " << L;
    }
  }
  double z[2] = {0.5, 0.1};
  EXPECT_NO_THROW(th->equilibrate({0.143 * 1.02 + 0.05, 0.0, 0.5}, z));
  EXPECT_GE(z[1], l_min);
}

TEST(HillHardCases, StiffTendonsConvergeToTheRigidTendon) {
  // Millard, elastic tendon with strain_at_one_norm_force e0 -> 0, against the same muscle with
  // ignore_tendon_compliance: the equilibrium tendon force converges, the difference about
  // bounded by 0.2 e0 (the tendon's share of the path length is ~ e0 l_s)
  MuscleParameters rigid = test::triLong();
  rigid.set("ignore_tendon_compliance", 1);
  const auto r = makeMuscleModel("Millard2012EquilibriumMuscle", rigid);
  const double L = 0.143 + 0.134 * 1.05 * std::cos(0.2);  // fibre near optimal length
  const double a = 0.8;
  MuscleOutput ro;
  double zr[1] = {a}, zdr[1];
  r->calc(zr, {L, 0.0, a}, ro, zdr);
  double previous = INFINITY;
  for (double e0 : {0.049, 0.01, 0.002, 0.0004}) {
    MuscleParameters p = test::triLong();
    p.set("TendonForceLengthCurve/strain_at_one_norm_force", e0);
    const auto m = makeMuscleModel("Millard2012EquilibriumMuscle", p);
    double z[2] = {a, 0.134}, zd[2];
    m->equilibrate({L, 0.0, a}, z);
    MuscleOutput out;
    m->calc(z, {L, 0.0, a}, out, zd);
    const double diff = std::abs(out.tendon_force - ro.tendon_force) / ro.tendon_force;
    std::printf("[ measured ] e0 %.4f: elastic %.4f N, rigid %.4f N, relative difference %.3e\n", e0,
                out.tendon_force, ro.tendon_force, diff);
    EXPECT_LT(diff, previous);
    // measured diff / e0: 0.13, 0.073, 0.029, 0.020 (faster than linear)
    EXPECT_LT(diff, 0.2 * e0);
    previous = diff;
  }
}

}  // namespace
}  // namespace redmax::hill
