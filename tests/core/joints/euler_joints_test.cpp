// Euler-angle joints: every sequence against the product of elementary rotations, the
// dissertation's XZX and universal formulas, and the reported distance from gimbal lock.
#include "core/joints/euler_joints.hpp"

#include <gtest/gtest.h>

#include "tests/core/joints/joint_test_util.hpp"

namespace redmax {
namespace {

using namespace redmax::test;

Mat3 elementary(char axis, double angle) {
  return Eigen::AngleAxisd(angle, Vec3::Unit(axis - 'X')).toRotationMatrix();
}

TEST(SphericalEuler, EverySequenceIsTheProductOfElementaryRotations) {
  const char* names[12] = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX",
                           "XYX", "XZX", "YXY", "YZY", "ZXZ", "ZYZ"};
  std::mt19937 rng(21);
  for (int s = 0; s < 12; ++s) {
    const EulerSequence seq = parseEulerSequence(names[s]);
    EXPECT_EQ(eulerSequenceName(seq), names[s]);
    EXPECT_EQ(isProperEuler(seq), names[s][0] == names[s][2]);
    for (int t = 0; t < 5; ++t) {
      const VecJ q = randomVecJ(3, rng, -3.0, 3.0);
      // intrinsic: each rotation about the axis of the frame already rotated
      const Mat3 expect = elementary(names[s][0], q[0]) * elementary(names[s][1], q[1]) *
                          elementary(names[s][2], q[2]);
      const JointKinematics k = calcJoint(SphericalEuler{seq}, q);
      EXPECT_TRUE(nearRel(Mat3(k.Q.topLeftCorner<3, 3>()), expect, 1e-14)) << names[s];
      EXPECT_TRUE((k.Q.topRightCorner<3, 1>().isZero(0.0)));
      EXPECT_TRUE(k.S.bottomRows<3>().isZero(0.0));
    }
  }
}

TEST(SphericalEuler, XZXMatchesDissertationEquations) {
  // [D Eq. 4.31] R, [D Eq. 4.33] first column of S, [D Eq. 4.35] first two columns of Sdot
  const double q1 = 0.4, q2 = -1.1, q3 = 2.3, qd2 = 0.7, qd3 = -1.9;
  const double c1 = std::cos(q1), s1 = std::sin(q1), c2 = std::cos(q2), s2 = std::sin(q2),
               c3 = std::cos(q3), s3 = std::sin(q3);
  Mat3 R;
  R << c2, -s2 * c3, s2 * s3, c1 * s2, c1 * c2 * c3 - s1 * s3, -s1 * c3 - c1 * c2 * s3, s1 * s2,
      c1 * s3 + s1 * c2 * c3, c1 * c3 - s1 * c2 * s3;
  VecJ q(3), qd(3);
  q << q1, q2, q3;
  qd << 0.3, qd2, qd3;
  const JointKinematics k = calcJoint(SphericalEuler{EulerSequence::XZX}, q, qd);
  EXPECT_TRUE(nearRel(Mat3(k.Q.topLeftCorner<3, 3>()), R, 1e-15));
  EXPECT_TRUE(nearRel(Vec3(k.S.col(0).head<3>()), Vec3(c2, -s2 * c3, s2 * s3), 1e-15));
  const Vec3 sd1(-s2 * qd2, s3 * s2 * qd3 - c3 * c2 * qd2, c2 * s3 * qd2 + s2 * c3 * qd3);
  const Vec3 sd2(0.0, c3 * qd3, -s3 * qd3);
  EXPECT_TRUE(nearRel(Vec3(k.Sdot.col(0).head<3>()), sd1, 1e-15));
  EXPECT_TRUE(nearRel(Vec3(k.Sdot.col(1).head<3>()), sd2, 1e-15));
  EXPECT_TRUE(k.Sdot.col(2).isZero(0.0));
}

TEST(SphericalEuler, GimbalDistanceIsDeterminantOfS) {
  std::mt19937 rng(22);
  for (int s = 0; s < 12; ++s) {
    const SphericalEuler j{static_cast<EulerSequence>(s)};
    for (int t = 0; t < 5; ++t) {
      const VecJ q = randomVecJ(3, rng, -3.0, 3.0);
      const Mat3 Sr = calcJoint(j, q).S.topRows<3>();
      const double expect = isProperEuler(j.sequence) ? std::abs(std::sin(q[1])) : std::abs(std::cos(q[1]));
      EXPECT_NEAR(j.gimbalDistance(q), expect, 1e-15);
      EXPECT_NEAR(j.gimbalDistance(q), std::abs(Sr.determinant()), 1e-14);
    }
    // at the singularity S loses rank and the distance is 0
    VecJ q(3);
    q << 0.3, isProperEuler(j.sequence) ? 0.0 : M_PI / 2, -0.8;
    const Eigen::JacobiSVD<Mat3> svd(Mat3(calcJoint(j, q).S.topRows<3>()));
    EXPECT_LT(j.gimbalDistance(q), 1e-15);
    EXPECT_LT(svd.singularValues()[2], 1e-15);
    EXPECT_GT(svd.singularValues()[1], 0.5);
  }
}

TEST(SphericalEuler, ParseRejectsBadSequence) {
  EXPECT_EQ(parseEulerSequence("zyz"), EulerSequence::ZYZ);
  EXPECT_THROW(parseEulerSequence("XXY"), JointError);
  EXPECT_THROW(parseEulerSequence(""), JointError);
  try {
    parseEulerSequence("XQZ");
    FAIL();
  } catch (const JointError& e) {
    EXPECT_NE(std::string(e.what()).find("XQZ"), std::string::npos);
  }
}

TEST(Universal, MatchesDissertationAndXYZWithZeroThirdAngle) {
  std::mt19937 rng(23);
  for (int t = 0; t < 5; ++t) {
    const VecJ q = randomVecJ(2, rng, -3.0, 3.0), qd = randomVecJ(2, rng);
    const JointKinematics u = calcJoint(Universal{}, q, qd);
    const double c1 = std::cos(q[0]), s1 = std::sin(q[0]), c2 = std::cos(q[1]), s2 = std::sin(q[1]);
    Mat3 R;  // [D Eq. 4.37]
    R << c2, 0, s2, s1 * s2, c1, -s1 * c2, -c1 * s2, s1, c1 * c2;
    EXPECT_TRUE(nearRel(Mat3(u.Q.topLeftCorner<3, 3>()), R, 1e-15));
    Mat6X S = Mat6X::Zero(6, 2), Sdot = Mat6X::Zero(6, 2);  // [D Eq. 4.39-4.40]
    S.col(0).head<3>() << c2, 0, s2;
    S(1, 1) = 1;
    Sdot.col(0).head<3>() << -s2 * qd[1], 0, c2 * qd[1];
    EXPECT_TRUE(nearRel(u.S, S, 1e-15));
    EXPECT_TRUE(nearRel(u.Sdot, Sdot, 1e-15));
    // XYZ Euler with q3 = 0, qd3 = 0
    VecJ q3(3), qd3(3);
    q3 << q[0], q[1], 0.0;
    qd3 << qd[0], qd[1], 0.0;
    const JointKinematics e = calcJoint(SphericalEuler{EulerSequence::XYZ}, q3, qd3);
    EXPECT_TRUE(nearRel(e.Q, u.Q, 1e-15));
    EXPECT_TRUE(nearRel(Mat6X(e.S.leftCols(2)), u.S, 1e-15));
    EXPECT_TRUE(nearRel(Mat6X(e.Sdot.leftCols(2)), u.Sdot, 1e-15));
  }
}

}  // namespace
}  // namespace redmax
