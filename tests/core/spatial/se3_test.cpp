#include "core/spatial/se3.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <random>

namespace redmax {
namespace {

class Se3Test : public ::testing::Test {
 protected:
  std::mt19937 rng_{42};
  std::uniform_real_distribution<double> u_{-1.0, 1.0};
  Vec3 rvec() { return Vec3(u_(rng_), u_(rng_), u_(rng_)); }
  Vec6 rtwist() {
    Vec6 p;
    p << rvec(), rvec();
    return p;
  }
  Mat4 rpose() { return makeE(expSO3(rvec() * 2.0), rvec()); }
};

TEST_F(Se3Test, SkewIsCrossProduct) {
  for (int k = 0; k < 10; ++k) {
    const Vec3 a = rvec(), b = rvec();
    EXPECT_TRUE(nearRel(skew(a) * b, a.cross(b), 1e-15));
    EXPECT_TRUE(nearRel(unskew(skew(a)), a, 1e-15));
  }
}

TEST_F(Se3Test, InverseAndAdjointInverse) {
  for (int k = 0; k < 10; ++k) {
    const Mat4 E = rpose();
    EXPECT_TRUE(nearRel(E * inverseE(E), Mat4::Identity(), 1e-14));
    EXPECT_TRUE(nearRel(Ad(E) * AdInv(E), Mat6::Identity(), 1e-14));
    EXPECT_TRUE(nearRel(AdInv(E), Ad(inverseE(E)), 1e-14));
  }
}

TEST_F(Se3Test, RotationTranslationProductsEqualTheSixBySixMatrices) {
  // adjointTimes & co. (the recursions' inner loops) against Ad, AdInv, ad as matrices
  for (int k = 0; k < 20; ++k) {
    const Mat4 E = rpose();
    const Mat3 R = E.topLeftCorner<3, 3>();
    const Vec3 p = E.topRightCorner<3, 1>();
    const Vec6 a = rtwist(), b = rtwist();
    EXPECT_TRUE(nearRel(adjointTimes(R, p, a), Vec6(Ad(E) * a), 1e-15));
    EXPECT_TRUE(nearRel(adjointInvTimes(R, p, a), Vec6(AdInv(E) * a), 1e-15));
    EXPECT_TRUE(nearRel(adjointInvTransposeTimes(R, p, a), Vec6(AdInv(E).transpose() * a), 1e-15));
    EXPECT_TRUE(nearRel(adTimes(a, b), Vec6(ad(a) * b), 1e-15));
    EXPECT_TRUE(nearRel(adTransposeTimes(a, b), Vec6(ad(a).transpose() * b), 1e-15));
  }
}

TEST_F(Se3Test, RotationAboutAUnitAxisEqualsTheExponential) {
  // rotationUnitAxis's direct Rodrigues form against expSO3 (its Taylor branch included)
  double worst = 0.0;
  for (double angle : {0.0, 1e-9, -3e-5, 2e-4, 0.7, -2.5, 3.14159, 6.0})
    for (int k = 0; k < 5; ++k) {
      const Vec3 axis = rvec().normalized();
      const Mat3 R = rotationUnitAxis(axis, angle);
      worst = std::max(worst, (R - expSO3(axis * angle)).cwiseAbs().maxCoeff());
      EXPECT_LE((R * R.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-15);
    }
  EXPECT_LE(worst, 1e-15);
  EXPECT_EQ(rotationUnitAxis(Vec3::UnitX(), 0.0), Mat3::Identity());
  EXPECT_EQ(rotationAxisAngle(Vec3::UnitX(), 0.0), Mat3::Identity());
}

TEST_F(Se3Test, AdjointTransformsTwistBracket) {
  // [Ad(E) phi] = E [phi] E^-1
  for (int k = 0; k < 10; ++k) {
    const Mat4 E = rpose();
    const Vec6 phi = rtwist();
    EXPECT_TRUE(nearRel(bracket6(Ad(E) * phi), Mat4(E * bracket6(phi) * inverseE(E)), 1e-13));
  }
}

TEST_F(Se3Test, AddotMatchesFiniteDifference) {
  // E(t) = E0 exp([phi] t): dAd/dt = Ad(E) ad(phi) [D Eq. 3.19-3.20]
  const double h = 1e-6;
  for (int k = 0; k < 10; ++k) {
    const Mat4 E = rpose();
    const Vec6 phi = rtwist();
    const Mat6 fd = (Ad(E * expSE3(phi * h)) - Ad(E * expSE3(-phi * h))) / (2 * h);
    EXPECT_TRUE(nearRel(Addot(E, phi), fd, 1e-8));
  }
}

TEST_F(Se3Test, AdIsLieBracket) {
  // ad(a) b = unbracket([a][b] - [b][a])
  for (int k = 0; k < 10; ++k) {
    const Vec6 a = rtwist(), b = rtwist();
    const Mat4 A = bracket6(a), B = bracket6(b);
    EXPECT_TRUE(nearRel(ad(a) * b, unbracket6(A * B - B * A), 1e-14));
  }
}

TEST_F(Se3Test, GammaGivesPointVelocity) {
  // a point x on a body with twist phi moves at R Gamma(x) phi [D Eq. 3.13]
  const double h = 1e-6;
  const Mat4 E = rpose();
  const Vec6 phi = rtwist();
  const Vec3 x = rvec();
  const Vec3 fd = (transformPoint(E * expSE3(phi * h), x) - transformPoint(E * expSE3(-phi * h), x)) / (2 * h);
  EXPECT_TRUE(nearRel(Vec3(E.topLeftCorner<3, 3>() * Gamma(x) * phi), fd, 1e-8));
}

TEST_F(Se3Test, ExpLogSO3RoundTripIncludingNearZeroAndNearPi) {
  std::vector<double> angles = {0.0, 1e-12, 1e-8, 1e-5, 1e-3, 0.5, 2.0, 3.0,
                                M_PI - 1e-3, M_PI - 1e-6, M_PI - 1e-9, M_PI};
  for (double th : angles) {
    for (int k = 0; k < 5; ++k) {
      const Vec3 axis = rvec().normalized();
      const Vec3 w = axis * th;
      const Mat3 R = expSO3(w);
      EXPECT_NEAR((R * R.transpose() - Mat3::Identity()).norm(), 0.0, 1e-14);
      EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
      const Vec3 w2 = logSO3(R);
      // at exactly pi the sign of the axis is ambiguous: compare rotations
      EXPECT_TRUE(nearRel(expSO3(w2), R, 1e-12)) << "angle " << th;
      if (th < M_PI - 1e-6) {
        EXPECT_TRUE(nearRel(w2, w, 1e-9)) << "angle " << th;
      }
    }
  }
}

TEST_F(Se3Test, ExpSO3MatchesSeriesOnBothSidesOfTaylorSwitch) {
  // the closed form and the Taylor branch (|w| < 1e-4) both match the matrix-exponential series
  const Vec3 axis = rvec().normalized();
  for (double th : {1e-4 * (1 - 1e-9), 1e-4 * (1 + 1e-9), 1e-7, 0.3}) {
    const Mat3 W = skew(axis * th);
    Mat3 sum = Mat3::Identity(), term = Mat3::Identity();
    for (int n = 1; n < 20; ++n) {
      term = term * W / n;
      sum += term;
    }
    EXPECT_TRUE(nearRel(expSO3(axis * th), sum, 1e-15)) << th;
  }
}

TEST_F(Se3Test, ExpLogSE3RoundTrip) {
  for (int k = 0; k < 20; ++k) {
    Vec6 phi = rtwist();
    phi.head<3>() *= 2.5;
    if (phi.head<3>().norm() >= M_PI) continue;
    EXPECT_TRUE(nearRel(logSE3(expSE3(phi)), phi, 1e-10));
  }
  Vec6 small;
  small << 1e-10, -2e-10, 3e-11, 0.5, -0.2, 0.1;
  EXPECT_TRUE(nearRel(logSE3(expSE3(small)), small, 1e-12));
}

TEST_F(Se3Test, ExpSE3MatchesMatrixExponentialSeries) {
  // compare with a truncated series of the 4x4 matrix exponential
  for (int k = 0; k < 5; ++k) {
    const Vec6 phi = rtwist() * 0.7;
    const Mat4 B = bracket6(phi);
    Mat4 sum = Mat4::Identity(), term = Mat4::Identity();
    for (int n = 1; n < 30; ++n) {
      term = term * B / n;
      sum += term;
    }
    EXPECT_TRUE(nearRel(expSE3(phi), sum, 1e-13));
  }
}

TEST_F(Se3Test, SpatialInertiaGivesKineticEnergyOfPointMasses) {
  // a cloud of point masses: sum 1/2 m |v|^2 equals 1/2 phi^T M phi with M from mass, com, I_c
  std::vector<std::pair<double, Vec3>> pts;
  for (int k = 0; k < 7; ++k) pts.push_back({0.1 + std::abs(u_(rng_)), rvec()});
  double m = 0;
  Vec3 c = Vec3::Zero();
  for (auto& [mi, x] : pts) {
    m += mi;
    c += mi * x;
  }
  c /= m;
  Mat3 Ic = Mat3::Zero();
  for (auto& [mi, x] : pts) {
    const Vec3 r = x - c;
    Ic += mi * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
  }
  const Mat6 M = spatialInertia(m, c, Ic);
  const Vec6 phi = rtwist();
  double T = 0;
  for (auto& [mi, x] : pts) T += 0.5 * mi * (Gamma(x) * phi).squaredNorm();
  EXPECT_NEAR(0.5 * phi.dot(M * phi), T, 1e-13);
}

}  // namespace
}  // namespace redmax
