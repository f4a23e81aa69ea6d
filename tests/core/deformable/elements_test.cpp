// Element kernels against finite differences: the spring [D Eq. 4.88-4.89] and the co-rotated
// tetrahedron, whose stiffness includes the exact derivative of the polar rotation.
#include <gtest/gtest.h>

#include <random>

#include "core/deformable/elements.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {
namespace {

constexpr double kH = 1e-6;

TEST(DeformableElements, SpringForceAndStiffnessMatchDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  int compared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 x0(u(rng), u(rng), u(rng)), x1(u(rng), u(rng), u(rng));
    const double L = 0.3 + 0.5 * (u(rng) + 1), k = 50.0;
    Vec3 f0;
    Mat3 H;
    springEnergyForce(x0, x1, L, k, &f0, &H);
    Vec3 g;  // -dV/dx0
    Mat3 Hfd;
    for (int c = 0; c < 3; ++c) {
      Vec3 p = x0, m = x0;
      p[c] += kH;
      m[c] -= kH;
      g[c] = -(springEnergyForce(p, x1, L, k, nullptr, nullptr) - springEnergyForce(m, x1, L, k, nullptr, nullptr)) / (2 * kH);
      Vec3 fp, fm;
      springEnergyForce(p, x1, L, k, &fp, nullptr);
      springEnergyForce(m, x1, L, k, &fm, nullptr);
      Hfd.col(c) = -(fp - fm) / (2 * kH);
    }
    EXPECT_TRUE(nearRel(f0, g, 1e-8)) << f0.transpose() << " vs " << g.transpose();
    EXPECT_TRUE(nearRel(H, Hfd, 1e-7)) << H << "\nvs\n" << Hfd;
    ++compared;
  }
  EXPECT_EQ(compared, 20);
}

TEST(DeformableElements, PolarRotationDerivativeMatchesDifferences) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  int compared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Mat3 F = expSO3(Vec3(u(rng), u(rng), u(rng)) * 2.0) * (Mat3::Identity() + 0.4 * Mat3::Random());
    if (F.determinant() < 0.1) continue;
    ++compared;
    Mat3 R, S;
    polarRotation(F, R, S);
    EXPECT_LE((R.transpose() * R - Mat3::Identity()).norm(), 1e-13);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-13);
    EXPECT_LE((S - S.transpose()).norm(), 1e-12);
    EXPECT_LE((R * S - F).norm(), 1e-12 * F.norm());
    // dP along a random dF against differences of P (P contains R: this checks dR)
    const Mat3 dF = Mat3::Random();
    const double mu = 3.0, lambda = 7.0;
    Mat3 Pp, Pm;
    corotatedEnergyStress(F + kH * dF, mu, lambda, &Pp);
    corotatedEnergyStress(F - kH * dF, mu, lambda, &Pm);
    const Mat3 dP = corotatedStressDifferential(R, S, dF, mu, lambda);
    EXPECT_TRUE(nearRel(dP, Mat3((Pp - Pm) / (2 * kH)), 1e-7)) << dP << "\nvs\n" << (Pp - Pm) / (2 * kH);
    // P = dPsi/dF
    const double dpsi = (corotatedEnergyStress(F + kH * dF, mu, lambda, nullptr) -
                         corotatedEnergyStress(F - kH * dF, mu, lambda, nullptr)) / (2 * kH);
    Mat3 P;
    corotatedEnergyStress(F, mu, lambda, &P);
    EXPECT_NEAR((P.array() * dF.array()).sum(), dpsi, 1e-7 * (1 + std::abs(dpsi)));
  }
  EXPECT_GE(compared, 10);  // the determinant filter must leave most trials, not skip them all
}

TEST(DeformableElements, TetForceAndStiffnessMatchDifferencesUnderLargeRotation) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const std::array<Vec3, 4> X = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  Mat3 Dm;
  Dm << X[1] - X[0], X[2] - X[0], X[3] - X[0];
  const Mat3 Dm_inv = Dm.inverse();
  const double V0 = 1.0 / 6.0, mu = 2.0, lambda = 5.0;
  for (int trial = 0; trial < 10; ++trial) {
    const Mat3 R = expSO3(Vec3(u(rng), u(rng), u(rng)) * 2.5);
    std::array<Vec3, 4> x;
    for (int a = 0; a < 4; ++a) x[a] = R * (X[a] + 0.2 * Vec3(u(rng), u(rng), u(rng))) + Vec3(1, 2, 3);
    Eigen::Matrix<double, 12, 1> f;
    Eigen::Matrix<double, 12, 12> K;
    tetEnergyForce(x, Dm_inv, V0, mu, lambda, &f, &K);
    Eigen::Matrix<double, 12, 1> g;
    Eigen::Matrix<double, 12, 12> Kfd;
    for (int j = 0; j < 12; ++j) {
      auto xp = x, xm = x;
      xp[j / 3][j % 3] += kH;
      xm[j / 3][j % 3] -= kH;
      Eigen::Matrix<double, 12, 1> fp, fm;
      const double Vp = tetEnergyForce(xp, Dm_inv, V0, mu, lambda, &fp, nullptr);
      const double Vm = tetEnergyForce(xm, Dm_inv, V0, mu, lambda, &fm, nullptr);
      g[j] = -(Vp - Vm) / (2 * kH);
      Kfd.col(j) = -(fp - fm) / (2 * kH);
    }
    EXPECT_TRUE(nearRel(f, g, 1e-7)) << f.transpose() << "\n" << g.transpose();
    EXPECT_TRUE(nearRel(MatX(K), MatX(Kfd), 1e-7)) << (K - Kfd).norm();
    EXPECT_LE((K - K.transpose()).norm(), 1e-10 * K.norm());
    // rigid motions carry no force
    std::array<Vec3, 4> xr;
    for (int a = 0; a < 4; ++a) xr[a] = R * X[a] + Vec3(1, 2, 3);
    EXPECT_LE(std::abs(tetEnergyForce(xr, Dm_inv, V0, mu, lambda, &f, nullptr)), 1e-14);
    EXPECT_LE(f.norm(), 1e-13);
  }
}

}  // namespace
}  // namespace redmax
