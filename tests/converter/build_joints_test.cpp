// Joints for converted OpenSim models: the Ellipsoid and Reversed core joints (S against
// differences of Q, Sdot against differences of S, central differences h = 1e-6, relative 1e-6),
// and makeCoreJoint's X_FM for every OpenSim joint type against the table of
// docs/opensim_compatibility.md §3.2 written out independently here (to 1e-14).
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "converter/build/build_core_model.hpp"
#include "tests/core/joints/joint_test_util.hpp"

namespace redmax::osim {
namespace {

using namespace redmax::test;
constexpr double kPi = std::numbers::pi;

Mat3 Rx(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }
Mat3 Ry(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }
Mat3 Rz(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }
Mat4 pose(const Mat3& R, const Vec3& p = Vec3::Zero()) { return makeE(R, p); }

void expectFd(const Joint& j, std::mt19937& rng, double range = 1.2) {
  for (int t = 0; t < 6; ++t) {
    const VecJ q = randomVecJ(j.nq(), rng, -range, range);
    const VecJ qdot = randomVecJ(j.nq(), rng, -2.0, 2.0);
    const JointKinematics k = calcJoint(j, q, qdot);
    EXPECT_TRUE(isRigid(k.Q)) << j.typeName();
    for (int c = 0; c < j.nq(); ++c) {
      const Mat4 fd = fdBracketColumn(j, q, c);
      EXPECT_TRUE(nearRel(bracket6(k.S.col(c)), fd, kFdTol))
          << j.typeName() << " column " << c << "\nS  = " << k.S.col(c).transpose()
          << "\nfd = " << unbracket6(fd).transpose();
    }
    EXPECT_TRUE(nearRel(k.Sdot, fdSdot(j, q, qdot), kFdTol))
        << j.typeName() << "\n" << k.Sdot << "\nvs\n" << fdSdot(j, q, qdot);
  }
}

TEST(BuildJoints, EllipsoidPoseIsSimbodysAndDerivativesMatchDifferences) {
  const Ellipsoid e{Vec3(0.3, -0.12, 0.07)};
  const Vec3 q(0.4, -0.7, 1.1);
  const Mat3 R = Rx(q[0]) * Ry(q[1]) * Rz(q[2]);
  const Vec3 n = R.col(2);
  const Mat4 Q = calcJoint(Joint(e), q).Q;
  EXPECT_TRUE(nearRel(Q, pose(R, Vec3(0.3 * n.x(), -0.12 * n.y(), 0.07 * n.z())), 1e-15));
  std::mt19937 rng(5);
  expectFd(Joint(e), rng);
  expectFd(Joint(Ellipsoid{Vec3(0.2, 0.2, 0.2)}), rng);
}

TEST(BuildJoints, ReversedInvertsTheTransformAndKeepsDerivativesExact) {
  // a reversed pin about a is a pin about -a
  const Vec3 a = Vec3(0.3, -0.5, 0.8).normalized();
  const VecJ q = VecJ::Constant(1, 0.77), qdot = VecJ::Constant(1, -1.3);
  const JointKinematics kr = calcJoint(Joint(Reversed(Joint(Revolute{a}))), q, qdot);
  const JointKinematics kn = calcJoint(Joint(Revolute{-a}), q, qdot);
  EXPECT_TRUE(nearRel(kr.Q, kn.Q, 1e-15));
  EXPECT_TRUE(nearRel(kr.S, kn.S, 1e-15));
  EXPECT_TRUE(nearRel(kr.Sdot, kn.Sdot, 1e-15));
  // every joint type the builder uses, reversed
  std::mt19937 rng(6);
  std::array<TransformAxis, 6> axes;
  axes[0].axis = Vec3(1, 0.2, 0);
  axes[0].coordinates = {0};
  axes[1].axis = Vec3(0, 1, 0.3);
  axes[1].coordinates = {1};
  axes[1].function = std::make_shared<const SimmSpline>(std::vector<double>{-2, -1, 0, 1, 2},
                                                        std::vector<double>{-1, 0.2, 0.1, 0.8, 1.5});
  axes[2].axis = Vec3(0, 0, 1);
  axes[3].coordinates = {1};
  axes[3].function = std::make_shared<const PolynomialFunction>(std::vector<double>{0.1, -0.2, 0.05});
  axes[4].axis = Vec3(0, 1, 0);
  axes[4].coordinates = {0};
  axes[5].axis = Vec3(0, 0, 1);
  for (const Joint& j : {Joint(Revolute{Vec3::UnitZ()}), Joint(Prismatic{Vec3::UnitX()}),
                         Joint(Universal{}), Joint(SphericalEuler{EulerSequence::XYZ}),
                         Joint(Free3D::opensim()), Joint(Ellipsoid{Vec3(0.1, 0.2, 0.3)}),
                         Joint(FunctionBased(2, axes, false)), Joint(FunctionBased(2, axes, true))}) {
    const Joint r = Reversed(j);
    EXPECT_EQ(r.nq(), j.nq());
    const VecJ qq = randomVecJ(j.nq(), rng);
    EXPECT_TRUE(nearRel(calcJoint(r, qq).Q * calcJoint(j, qq).Q, Mat4::Identity(), 1e-14));
    // Simbody-compatible S/Sdot are not derivatives of Q: FD only for exact joints
    const auto* fb = std::get_if<FunctionBased>(&j.v);
    if (fb == nullptr || !fb->simbody_compat) expectFd(r, rng);
  }
  EXPECT_EQ(Joint(Reversed(Joint(Universal{}))).typeName(), "reversed_universal");
}

// X_FM of every OpenSim joint type, written out from the table of semantics 3.2
TEST(BuildJoints, CoreJointsReproduceOpenSimsXFM) {
  ModelDescription d;
  d.source_file = "t.osim";
  auto joint = [&](JointKind kind, int n) {
    JointDesc j;
    j.name = "j";
    j.type = "J";
    j.kind = kind;
    for (int k = 0; k < n; ++k) j.coordinates.push_back(k);
    return j;
  };
  const double a = 0.3, b = -0.8, c = 1.2, x = 0.15, y = -0.4, z = 0.9;
  auto QFM = [&](const JointDesc& j, const VecJ& q) {
    return calcJoint(makeCoreJoint(d, j, false).joint, q).Q;
  };
  EXPECT_TRUE(nearRel(QFM(joint(JointKind::Weld, 0), VecJ()), Mat4::Identity(), 0.0));
  EXPECT_TRUE(nearRel(QFM(joint(JointKind::Pin, 1), VecJ::Constant(1, a)), pose(Rz(a)), 1e-15));
  EXPECT_TRUE(nearRel(QFM(joint(JointKind::Slider, 1), VecJ::Constant(1, x)),
                      makeTranslation(Vec3(x, 0, 0)), 1e-15));
  EXPECT_TRUE(nearRel(QFM(joint(JointKind::Universal, 2), Vec2(a, b)), pose(Rx(a) * Ry(b)), 1e-15));
  EXPECT_TRUE(nearRel(QFM(joint(JointKind::Gimbal, 3), Vec3(a, b, c)), pose(Rx(a) * Ry(b) * Rz(c)), 1e-15));
  EXPECT_TRUE(nearRel(QFM(joint(JointKind::Ball, 3), Vec3(a, b, c)), pose(Rx(a) * Ry(b) * Rz(c)), 1e-15));
  VecJ q6(6);
  q6 << a, b, c, x, y, z;
  EXPECT_TRUE(nearRel(QFM(joint(JointKind::Free, 6), q6), pose(Rx(a) * Ry(b) * Rz(c), Vec3(x, y, z)), 1e-15));
  EXPECT_TRUE(nearRel(QFM(joint(JointKind::Planar, 3), Vec3(a, x, y)), pose(Rz(a), Vec3(x, y, 0)), 1e-15));
  JointDesc e = joint(JointKind::Ellipsoid, 3);
  e.radii = Vec3(0.2, 0.3, 0.4);
  const Mat3 R = Rx(a) * Ry(b) * Rz(c);
  EXPECT_TRUE(nearRel(QFM(e, Vec3(a, b, c)),
                      pose(R, Vec3(0.2 * R(0, 2), 0.3 * R(1, 2), 0.4 * R(2, 2))), 1e-15));
  // a coordinate count that does not fit the joint type is an error, not a crash
  EXPECT_THROW(makeCoreJoint(d, joint(JointKind::Pin, 2), false), ConvertError);
  EXPECT_THROW(makeCoreJoint(d, joint(JointKind::Unsupported, 0), false), ConvertError);
}

// Simbody's ScapulothoracicJoint chain composed step by step (Ellipsoid with swapped radii
// between F C and C, then a pin about the winging axis through its origin, then the child frame)
TEST(BuildJoints, ScapulothoracicEqualsSimbodysChain) {
  ModelDescription d;
  d.source_file = "t.osim";
  JointDesc j;
  j.name = "scapulothoracic";
  j.type = "ScapulothoracicJoint";
  j.kind = JointKind::Scapulothoracic;
  j.coordinates = {0, 1, 2, 3};
  j.radii = Vec3(0.07, 0.15, 0.08);
  j.winging_origin = Vec2(-0.05, 0.01);
  j.winging_direction = 0.6;
  const CoreJoint cj = makeCoreJoint(d, j, false);
  ASSERT_EQ(cj.joint.nq(), 4);
  std::mt19937 rng(8);
  for (int t = 0; t < 5; ++t) {
    const VecJ q = randomVecJ(4, rng);
    // expected: C X_e(q0..2) C^-1 W Rz(q3) W^-1 with W's rotation built another way (any
    // rotation whose z axis is the winging direction)
    const Mat3 C = Rz(kPi / 2);
    const Vec3 rad(0.15, 0.07, 0.08);
    const Mat3 Re = Rx(q[0]) * Ry(q[1]) * Rz(q[2]);
    const Mat4 Xe = pose(Re, rad.cwiseProduct(Vec3(Re.col(2))));
    const Vec3 dir(-std::sin(0.6), std::cos(0.6), 0.0);
    const Mat3 Rw = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), dir).toRotationMatrix();
    const Mat4 W = pose(Rw, Vec3(-0.05, 0.01, 0.0));
    const Mat4 expected = pose(C) * Xe * pose(C.transpose()) * W * pose(Rz(q[3])) * inverseE(W);
    const Mat4 got = cj.F_post * calcJoint(cj.joint, q).Q * inverseE(cj.M_post);
    EXPECT_TRUE(nearRel(got, expected, 1e-14)) << got << "\nvs\n" << expected;
  }
  expectFd(cj.joint, rng);
}

}  // namespace
}  // namespace redmax::osim
