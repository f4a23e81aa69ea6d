// Function-based (OpenSim CustomJoint) joint: FD with coupled knee-like and multi-argument
// functions, equivalence with Euler/free joints, the Simbody-compatible mode (equal to exact for
// hip-like joints, different for a coordinate driving several rotations, the Constant quirk),
// and input validation.
#include "core/joints/function_based.hpp"

#include <gtest/gtest.h>

#include "core/joints/joint.hpp"
#include "tests/core/joints/joint_test_util.hpp"

namespace redmax {
namespace {

using namespace redmax::test;
using Mat3X2 = Eigen::Matrix<double, 3, 2>;

AxisFunctionPtr lin(double s, double c = 0.0) { return std::make_shared<const LinearFunction>(s, c); }
AxisFunctionPtr spline(std::vector<double> x, std::vector<double> y) {
  return std::make_shared<const SimmSpline>(std::move(x), std::move(y));
}
AxisFunctionPtr constant(double c) { return std::make_shared<const ConstantFunction>(c); }

// Rajagopal-style walker knee: the knee angle drives all three rotations and two translations
FunctionBased walkerKnee(bool compat = false) {
  const std::vector<double> kx{-2.0944, -1.5708, -1.0472, -0.5236, 0.0, 0.1745};
  std::array<TransformAxis, 6> ax;
  ax[0] = {Vec3(0, 0, 1), {0}, lin(1.0)};
  ax[1] = {Vec3(1, 0, 0), {0}, spline(kx, {0.08, 0.06, 0.03, 0.01, 0.0, -0.005})};
  ax[2] = {Vec3(0, 1, 0), {0}, spline(kx, {-0.25, -0.18, -0.1, -0.04, 0.0, 0.01})};
  ax[3] = {Vec3(1, 0, 0), {0}, spline(kx, {-0.0032, 0.00179, 0.00411, 0.0041, 0.00212, -0.001})};
  ax[4] = {Vec3(0, 1, 0), {0}, spline(kx, {-0.4226, -0.4082, -0.399, -0.3976, -0.3966, -0.395})};
  ax[5] = {Vec3(0, 0, 1), {}, constant(0.01)};
  return FunctionBased(1, ax, compat);
}

// pelvis/hip-like: rotation k depends on mobility k-1 only (nonlinearly here), translations mixed
FunctionBased hipLike(bool compat = false) {
  std::array<TransformAxis, 6> ax;
  ax[0] = {Vec3(0, 0, 1), {0}, spline({-1.5, -0.5, 0.3, 1.5}, {-1.4, -0.6, 0.4, 1.3})};
  ax[1] = {Vec3(1, 0.2, 0), {1}, lin(-0.9, 0.1)};
  ax[2] = {Vec3(0, 1, 0.3), {2}, std::make_shared<const PolynomialFunction>(std::vector<double>{0.2, 1.0, 0.0})};
  ax[3] = {Vec3(1, 0, 0), {0}, spline({-1.5, 0.0, 1.5}, {0.02, 0.0, 0.03})};
  ax[4] = {Vec3(0, 1, 0), {1, 2}, std::make_shared<const LinearFunction>(std::vector<double>{0.1, -0.05, 0.2})};
  ax[5] = {Vec3(0, 0, 1), {}, constant(-0.1)};
  return FunctionBased(3, ax, compat);
}

void expectFd(const Joint& j, const VecJ& q, const VecJ& qd) {
  const JointKinematics k = calcJoint(j, q, qd);
  EXPECT_TRUE(isRigid(k.Q));
  for (int c = 0; c < j.nq(); ++c)
    EXPECT_TRUE(nearRel(bracket6(k.S.col(c)), fdBracketColumn(j, q, c), kFdTol)) << "column " << c << " q " << q.transpose();
  EXPECT_TRUE(nearRel(k.Sdot, fdSdot(j, q, qd), kFdTol)) << "q " << q.transpose();
}

TEST(FunctionBased, KneeCouplingFiniteDifferences) {
  const Joint j = walkerKnee();
  std::mt19937 rng(81);
  for (int t = 0; t < 10; ++t) expectFd(j, randomVecJ(1, rng, -2.3, 0.4), randomVecJ(1, rng, -3, 3));
}

TEST(FunctionBased, MultiArgumentLinearFiniteDifferences) {
  std::array<TransformAxis, 6> ax;
  ax[0] = {Vec3(1, 0, 0), {0, 1}, std::make_shared<const LinearFunction>(std::vector<double>{0.7, -0.3, 0.1})};
  ax[1] = {Vec3(0, 1, 0), {1}, nullptr};  // default Linear(1, 0)
  ax[2] = {Vec3(0, 0, 1), {1, 0}, std::make_shared<const LinearFunction>(std::vector<double>{0.4, 0.9, 0.0})};
  ax[3] = {Vec3(1, 1, 0), {0}, spline({-1, 0, 1, 2}, {0.1, 0.0, 0.05, 0.2})};
  ax[4] = {Vec3(0, 1, 0), {}, nullptr};  // default Constant(0)
  ax[5] = {Vec3(0, 0.3, 1), {1, 0}, std::make_shared<const LinearFunction>(std::vector<double>{0.2, 0.5, 0.0})};
  const Joint j = FunctionBased(2, ax);
  std::mt19937 rng(82);
  for (int t = 0; t < 10; ++t) expectFd(j, randomVecJ(2, rng, -1.2, 1.2), randomVecJ(2, rng, -2, 2));
  expectFd(hipLike(), randomVecJ(3, rng), randomVecJ(3, rng));
}

TEST(FunctionBased, IdentityFunctionsEqualGimbalAndFreeJoints) {
  std::array<TransformAxis, 6> ax;
  for (int k = 0; k < 3; ++k) ax[k] = {Vec3::Unit(k), {k}, nullptr};
  for (int k = 0; k < 3; ++k) ax[3 + k] = {Vec3::Unit(k), {}, nullptr};
  const Joint gimbal = FunctionBased(3, ax);
  for (int k = 0; k < 3; ++k) ax[3 + k] = {Vec3::Unit(k), {3 + k}, nullptr};
  const Joint free = FunctionBased(6, ax);
  std::mt19937 rng(83);
  for (int t = 0; t < 5; ++t) {
    const VecJ q = randomVecJ(6, rng), qd = randomVecJ(6, rng);
    const JointKinematics a = calcJoint(free, q, qd), b = calcJoint(Free3D::opensim(), q, qd);
    EXPECT_TRUE(nearRel(a.Q, b.Q, 1e-14));
    EXPECT_TRUE(nearRel(a.S, b.S, 1e-14));
    EXPECT_TRUE(nearRel(a.Sdot, b.Sdot, 1e-14));
    const JointKinematics c = calcJoint(gimbal, q.head(3), qd.head(3));
    const JointKinematics d = calcJoint(SphericalEuler{EulerSequence::XYZ}, q.head(3), qd.head(3));
    EXPECT_TRUE(nearRel(c.Q, d.Q, 1e-14));
    EXPECT_TRUE(nearRel(c.S, d.S, 1e-14));
    EXPECT_TRUE(nearRel(c.Sdot, d.Sdot, 1e-14));
  }
}

TEST(FunctionBased, SimbodyCompatEqualsExactForHipLikeJoints) {
  const Joint exact = hipLike(false), compat = hipLike(true);
  std::mt19937 rng(84);
  for (int t = 0; t < 10; ++t) {
    const VecJ q = randomVecJ(3, rng), qd = randomVecJ(3, rng, -3, 3);
    const JointKinematics a = calcJoint(exact, q, qd), b = calcJoint(compat, q, qd);
    EXPECT_TRUE(nearRel(b.Q, a.Q, 1e-14));
    EXPECT_TRUE(nearRel(b.S, a.S, 1e-13));
    EXPECT_TRUE(nearRel(b.Sdot, a.Sdot, 1e-13));
  }
}

// Simbody's Wdot = [0, w_a x W_2, w_b x W_3] against the exact [0, w_1 x W_2, (w_1 + w_2) x W_3]
// (w_k = W_k thetadot_k, F frame) gives, for joints without Constant rotations,
//   (Sdot_compat - Sdot_exact) qdot = (R^T ((w_a - w_1) x w_2 + (w_b - w_1 - w_2) x w_3); 0)
// with w_a, w_b the angular velocities from mobility 0 alone and from all but mobility 2.
// Computed here directly from the functions, independently of the joint's code path.
Vec6 expectedCompatDifference(const FunctionBased& j, const VecJ& q, const VecJ& qd) {
  const int n = j.nq();
  const auto& ax = j.axes();
  double th[3];
  VecJ g[3];
  for (int k = 0; k < 3; ++k) {
    VecJ x(ax[k].coordinates.size());
    for (int i = 0; i < x.size(); ++i) x[i] = q[ax[k].coordinates[i]];
    th[k] = ax[k].function->value(x);
    const VecJ gs = ax[k].function->gradient(x);
    g[k] = VecJ::Zero(n);
    for (int i = 0; i < x.size(); ++i) g[k][ax[k].coordinates[i]] += gs[i];
  }
  const Mat3 R1 = rotationAxisAngle(ax[0].axis, th[0]), R2 = rotationAxisAngle(ax[1].axis, th[1]);
  const Vec3 W[3] = {ax[0].axis, R1 * ax[1].axis, R1 * R2 * ax[2].axis};
  VecJ u_a = VecJ::Zero(n), u_b = qd;
  u_a[0] = qd[0];
  if (n > 2) u_b[2] = 0.0;
  Vec3 w[3], w_a = Vec3::Zero(), w_b = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    w[k] = W[k] * g[k].dot(qd);
    w_a += W[k] * g[k].dot(u_a);
    w_b += W[k] * g[k].dot(u_b);
  }
  const Mat3 R = R1 * R2 * rotationAxisAngle(ax[2].axis, th[2]);
  Vec6 d;
  d << R.transpose() * ((w_a - w[0]).cross(w[1]) + (w_b - w[0] - w[1]).cross(w[2])), Vec3::Zero();
  return d;
}

// three coordinates, each driving more than one rotation
FunctionBased mixedThree(bool compat) {
  std::array<TransformAxis, 6> ax;
  ax[0] = {Vec3(0, 0, 1), {0, 2}, std::make_shared<const LinearFunction>(std::vector<double>{1.0, 0.3, 0.0})};
  ax[1] = {Vec3(1, 0, 0), {1, 2}, std::make_shared<const LinearFunction>(std::vector<double>{0.8, -0.4, 0.1})};
  ax[2] = {Vec3(0, 1, 0), {2, 0}, std::make_shared<const LinearFunction>(std::vector<double>{1.0, 0.5, 0.0})};
  for (int k = 0; k < 3; ++k) ax[3 + k] = {Vec3::Unit(k), {k}, spline({-2, 0, 2}, {0.1, -0.05 * k, 0.2})};
  return FunctionBased(3, ax, compat);
}

TEST(FunctionBased, SimbodyCompatDiffersWhenOneCoordinateDrivesSeveralRotations) {
  std::mt19937 rng(85);
  for (const auto& [exact, compat] : {std::pair{walkerKnee(false), walkerKnee(true)},
                                       std::pair{mixedThree(false), mixedThree(true)}}) {
    const int n = exact.nq();
    for (int t = 0; t < 10; ++t) {
      const VecJ q = randomVecJ(n, rng, -1.5, 0.1), qd = randomVecJ(n, rng, 1.0, 3.0);
      const JointKinematics a = calcJoint(exact, q, qd), b = calcJoint(compat, q, qd);
      EXPECT_TRUE(nearRel(b.Q, a.Q, 1e-15));
      EXPECT_TRUE(nearRel(b.S, a.S, 1e-13));  // H is exact; only the velocity terms differ
      EXPECT_GT((b.Sdot - a.Sdot).norm(), 1e-4 * a.Sdot.norm());
      EXPECT_TRUE(nearRel(Vec6((b.Sdot - a.Sdot) * qd), expectedCompatDifference(exact, q, qd), 1e-12));
    }
  }
  // the same formula vanishes for the hip-like joint (checked against exact in the test above)
  const FunctionBased hip = hipLike();
  const VecJ q = randomVecJ(3, rng), qd = randomVecJ(3, rng);
  EXPECT_LT(expectedCompatDifference(hip, q, qd).norm(), 1e-14);
}

TEST(FunctionBased, SimbodyCompatConstantRotationQuirk) {
  // Simbody builds W for H with Constant angles taken as 0: with a nonzero constant first
  // rotation, S differs from exact; with a zero constant it does not
  for (double c0 : {0.0, 0.4}) {
    std::array<TransformAxis, 6> ax;
    ax[0] = {Vec3(1, 0, 0), {}, constant(c0)};
    ax[1] = {Vec3(0, 1, 0), {0}, nullptr};
    ax[2] = {Vec3(0, 0, 1), {1}, nullptr};
    for (int k = 0; k < 3; ++k) ax[3 + k] = {Vec3::Unit(k), {}, nullptr};
    const Joint exact = FunctionBased(2, ax, false), compat = FunctionBased(2, ax, true);
    VecJ q(2), qd(2);
    q << 0.3, -0.5;
    qd << 1.0, 2.0;
    const JointKinematics a = calcJoint(exact, q, qd), b = calcJoint(compat, q, qd);
    EXPECT_TRUE(nearRel(b.Q, a.Q, 1e-15));
    const Mat3 R = a.Q.topLeftCorner<3, 3>();
    Mat3X2 quirkyW;  // [a2, R_y(q0) a3]: rotation 1 dropped from W
    quirkyW << Vec3::UnitY(), rotationAxisAngle(Vec3::UnitY(), q[0]) * Vec3::UnitZ();
    EXPECT_TRUE(nearRel(Mat3X2(b.S.topRows<3>()), Mat3X2(R.transpose() * quirkyW), 1e-14));
    if (c0 == 0.0) {
      EXPECT_TRUE(nearRel(b.S, a.S, 1e-14));
      EXPECT_TRUE(nearRel(b.Sdot, a.Sdot, 1e-14));
    } else {
      EXPECT_GT((b.S - a.S).norm(), 0.1);
    }
  }
}

TEST(FunctionBased, RejectsBadInput) {
  std::array<TransformAxis, 6> ok;
  for (int k = 0; k < 6; ++k) ok[k].axis = Vec3::Unit(k % 3);
  ok[0].coordinates = {0};
  EXPECT_NO_THROW(FunctionBased(1, ok));
  auto bad = ok;
  bad[1].axis = Vec3(2, 0, 0);  // parallel to rotation1
  EXPECT_THROW(FunctionBased(1, bad), JointError);
  bad = ok;
  bad[5].axis = Vec3(0, 1, 1e-7);  // parallel to translation2
  EXPECT_THROW(FunctionBased(1, bad), JointError);
  bad = ok;
  bad[2].coordinates = {1};  // index outside 0..nq-1
  EXPECT_THROW(FunctionBased(1, bad), JointError);
  bad = ok;
  bad[3].coordinates = {0, 0};  // two coordinates, no function
  EXPECT_THROW(FunctionBased(1, bad), JointError);
  bad = ok;
  bad[3].coordinates = {0};
  bad[3].function = std::make_shared<const LinearFunction>(std::vector<double>{1, 2, 3});  // 2 args
  EXPECT_THROW(FunctionBased(1, bad), JointError);
  bad = ok;
  bad[4].axis = Vec3(std::nan(""), 0, 1);
  EXPECT_THROW(FunctionBased(1, bad), JointError);
  EXPECT_THROW(FunctionBased(7, ok), JointError);
}

}  // namespace
}  // namespace redmax
