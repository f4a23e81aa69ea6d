// Exponential coordinates: the limits |q| -> 0, the neighbourhood of |q| = pi, the dissertation's
// derivative formula, and the chart switch.
#include "core/joints/spherical_exp.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "tests/core/joints/joint_test_util.hpp"

namespace redmax {
namespace {

using namespace redmax::test;
constexpr double kPi = std::numbers::pi;

VecJ along(const Vec3& dir, double len) { return VecJ(dir.normalized() * len); }

// [D Eq. 4.43-4.44]: Gallego and Yezzi's derivative, an independent formula for S
Mat3 gallegoYezziS(const Vec3& q) {
  const Mat3 R = expSO3(q);
  Mat3 S;
  for (int i = 0; i < 3; ++i) {
    const Mat3 dR = (q[i] * skew(q) + skew(skew(q) * (Mat3::Identity() - R) * Vec3::Unit(i))) / q.squaredNorm() * R;
    S.col(i) = unskew(R.transpose() * dR);
  }
  return S;
}

void expectFd(const VecJ& q, const VecJ& qd) {
  const Joint j = SphericalExp{};
  const JointKinematics k = calcJoint(j, q, qd);
  for (int c = 0; c < 3; ++c)
    EXPECT_TRUE(nearRel(bracket6(k.S.col(c)), fdBracketColumn(j, q, c), kFdTol)) << "|q| = " << q.norm();
  EXPECT_TRUE(nearRel(k.Sdot, fdSdot(j, q, qd), kFdTol)) << "|q| = " << q.norm();
  EXPECT_TRUE(isRigid(k.Q));
}

TEST(SphericalExp, MatchesGallegoYezziFormula) {
  std::mt19937 rng(31);
  for (int t = 0; t < 10; ++t) {
    const Vec3 q = randomVecJ(3, rng, -2.0, 2.0);
    const JointKinematics k = calcJoint(SphericalExp{}, q);
    EXPECT_TRUE(nearRel(Mat3(k.S.topRows<3>()), gallegoYezziS(q), 1e-13));
    EXPECT_TRUE(nearRel(Mat3(k.Q.topLeftCorner<3, 3>()), expSO3(q), 1e-15));
  }
}

TEST(SphericalExp, LimitsNearZero) {
  std::mt19937 rng(32);
  const Vec3 dir = randomVecJ(3, rng), qd = randomVecJ(3, rng);
  // exactly zero: S = I, Sdot = -[qdot]/2 (first-order term of S = I - [q]/2 + ...)
  const JointKinematics k0 = calcJoint(SphericalExp{}, VecJ::Zero(3), VecJ(qd));
  EXPECT_TRUE(nearRel(Mat3(k0.S.topRows<3>()), Mat3::Identity(), 1e-16));
  EXPECT_TRUE(nearRel(Mat3(k0.Sdot.topRows<3>()), Mat3(-0.5 * skew(qd)), 1e-16));
  for (double len : {1e-9, 1e-5, 0.0999, 0.1001}) {
    const VecJ q = along(dir, len);
    expectFd(q, VecJ(qd));
    // second-order Taylor expansion of S: error O(|q|^3)
    const Mat3 taylor = Mat3::Identity() - 0.5 * skew(q) + skew(q) * skew(q) / 6.0;
    EXPECT_TRUE(nearRel(Mat3(calcJoint(SphericalExp{}, q).S.topRows<3>()), taylor, 0.1 * std::pow(len, 3) + 1e-16));
  }
}

TEST(SphericalExp, WellConditionedNearPi) {
  std::mt19937 rng(33);
  for (int t = 0; t < 3; ++t) {
    const Vec3 dir = randomVecJ(3, rng), qd = randomVecJ(3, rng);
    for (double len : {kPi - 1e-7, kPi, kPi + 1e-3}) {
      const VecJ q = along(dir, len);
      expectFd(q, VecJ(qd));
      const Eigen::JacobiSVD<Mat3> svd(Mat3(calcJoint(SphericalExp{}, q).S.topRows<3>()));
      const Vec3 sv = svd.singularValues();  // a copy: GCC 12 misreads the SVD's storage as uninitialized
      const double cond = sv[0] / sv[2];
      EXPECT_LT(cond, kPi / 2 + 1e-3) << len;  // singular values 1 and sin(th/2)/(th/2)
    }
  }
}

TEST(SphericalExp, ReparameterizeKeepsRotationAndTwist) {
  std::mt19937 rng(34);
  for (int t = 0; t < 5; ++t) {
    const Vec3 dir = randomVecJ(3, rng);
    for (double len : {1.51 * kPi, 1.9 * kPi, 2 * kPi - 1e-3, 2.4 * kPi}) {
      VecJ q = along(dir, len), qd = randomVecJ(3, rng, -2.0, 2.0);
      const JointKinematics before = calcJoint(SphericalExp{}, q, qd);
      const Vec3 twist0 = before.S.topRows<3>() * qd;
      ASSERT_TRUE(SphericalExp{}.reparameterize(q, qd)) << len;
      const JointKinematics after = calcJoint(SphericalExp{}, q, qd);
      EXPECT_TRUE(nearRel(after.Q, before.Q, 1e-12)) << len;
      EXPECT_TRUE(nearRel(Vec3(after.S.topRows<3>() * qd), twist0, 1e-12)) << len;
      EXPECT_NEAR(q.norm(), std::abs(len - 2 * kPi), 1e-12);
      EXPECT_LT(q.norm(), 0.5 * kPi);
      // the new state is inside the band, so the switch does not fire again
      EXPECT_FALSE(SphericalExp{}.reparameterize(q, qd));
    }
  }
  // below the threshold nothing changes
  VecJ q = along(Vec3(1, 2, 3), 1.4 * kPi), qd = randomVecJ(3, rng);
  const VecJ q0 = q, qd0 = qd;
  EXPECT_FALSE(SphericalExp{}.reparameterize(q, qd));
  EXPECT_EQ(q, q0);
  EXPECT_EQ(qd, qd0);
}

}  // namespace
}  // namespace redmax
