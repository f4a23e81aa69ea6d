// Free joints: Free2D against [D Eq. 4.55] and the planar+revolute composite; Free3D in both
// factor orders against the composites of [D Eq. 4.56, 4.60], the coordinate layouts, and the
// OpenSim/Simbody FreeJoint convention.
#include "core/joints/free_joints.hpp"

#include <gtest/gtest.h>

#include "core/joints/joint.hpp"
#include "tests/core/joints/joint_test_util.hpp"

namespace redmax {
namespace {

using namespace redmax::test;

TEST(Free2D, MatchesDissertationAndComposite) {
  std::mt19937 rng(51);
  const Joint comp = Composite({Planar{}, Revolute{Vec3::UnitZ()}});
  for (int t = 0; t < 5; ++t) {
    const VecJ q = randomVecJ(3, rng, -3, 3), qd = randomVecJ(3, rng);
    const JointKinematics k = calcJoint(Free2D{}, q, qd);
    const Mat3 R2 = k.Q.topLeftCorner<3, 3>();
    Mat6X S = Mat6X::Zero(6, 3);  // [D Eq. 4.55]: rows of Q_2 in the translational rows
    S.block<3, 1>(3, 0) = R2.row(0).transpose();
    S.block<3, 1>(3, 1) = R2.row(1).transpose();
    S(2, 2) = 1;
    EXPECT_TRUE(nearRel(k.S, S, 1e-15));
    const JointKinematics c = calcJoint(comp, q, qd);
    EXPECT_TRUE(nearRel(k.Q, c.Q, 1e-15));
    EXPECT_TRUE(nearRel(k.S, c.S, 1e-15));
    EXPECT_TRUE(nearRel(k.Sdot, c.Sdot, 1e-15));
  }
}

TEST(Free3D, BothOrdersMatchCompositesAndFiniteDifferences) {
  std::mt19937 rng(52);
  for (FreeRotation rot : {FreeRotation::Exponential, FreeRotation::Euler}) {
    const Joint sph = rot == FreeRotation::Exponential ? Joint(SphericalExp{})
                                                       : Joint(SphericalEuler{EulerSequence::YZX});
    for (FreeOrder order : {FreeOrder::TranslationThenRotation, FreeOrder::RotationThenTranslation}) {
      const bool t_first = order == FreeOrder::TranslationThenRotation;
      const Joint comp = t_first ? Composite({Translational{}, sph}) : Composite({sph, Translational{}});
      // the layout whose coordinates follow the factor order equals the composite directly
      const FreeLayout natural = t_first ? FreeLayout::TranslationFirst : FreeLayout::RotationFirst;
      const Joint free{Free3D{rot, EulerSequence::YZX, order, natural}};
      for (int t = 0; t < 5; ++t) {
        const VecJ q = randomVecJ(6, rng, -1.5, 1.5), qd = randomVecJ(6, rng);
        const JointKinematics k = calcJoint(free, q, qd), c = calcJoint(comp, q, qd);
        EXPECT_TRUE(nearRel(k.Q, c.Q, 1e-14));
        EXPECT_TRUE(nearRel(k.S, c.S, 1e-14));
        EXPECT_TRUE(nearRel(k.Sdot, c.Sdot, 1e-14));
        for (int col = 0; col < 6; ++col)
          EXPECT_TRUE(nearRel(bracket6(k.S.col(col)), fdBracketColumn(free, q, col), kFdTol));
        EXPECT_TRUE(nearRel(k.Sdot, fdSdot(free, q, qd), kFdTol));
        // the other layout is the same joint with the coordinate blocks swapped
        const Joint swapped{Free3D{rot, EulerSequence::YZX, order,
                                   natural == FreeLayout::RotationFirst ? FreeLayout::TranslationFirst
                                                                         : FreeLayout::RotationFirst}};
        VecJ qs(6), qds(6);
        qs << q.tail(3), q.head(3);
        qds << qd.tail(3), qd.head(3);
        const JointKinematics s = calcJoint(swapped, qs, qds);
        EXPECT_TRUE(nearRel(s.Q, k.Q, 1e-15));
        EXPECT_TRUE(nearRel(Mat6X(s.S.leftCols(3)), Mat6X(k.S.rightCols(3)), 1e-15));
        EXPECT_TRUE(nearRel(Mat6X(s.Sdot.rightCols(3)), Mat6X(k.Sdot.leftCols(3)), 1e-15));
      }
    }
  }
}

TEST(Free3D, OpenSimLayout) {
  // q = (rx, ry, rz, tx, ty, tz), X_FM = (body-fixed XYZ, p expressed in F)
  VecJ q(6);
  q << 0.3, -0.7, 1.2, 0.5, -1.5, 2.0;
  const JointKinematics k = calcJoint(Free3D::opensim(), q);
  const Mat3 R = rotationAboutAxis(0, q[0]) * rotationAboutAxis(1, q[1]) * rotationAboutAxis(2, q[2]);
  EXPECT_TRUE(nearRel(k.Q, makeE(R, Vec3(0.5, -1.5, 2.0)), 1e-15));
  // translation rates are velocities in F: the linear body velocity is R^T pdot
  EXPECT_TRUE(nearRel(Mat3(k.S.block<3, 3>(3, 3)), Mat3(R.transpose()), 1e-15));
}

TEST(Free3D, ReparameterizeOnlyForExponential) {
  VecJ q(6), qd(6);
  q << 0.1, 0.2, 0.3, 5.0, 1.0, -2.0;  // rotation last in TranslationFirst layout
  qd << 1, 2, 3, 4, 5, 6;
  const Free3D fe{};
  const JointKinematics before = calcJoint(fe, q, qd);
  VecJ q1 = q, qd1 = qd;
  ASSERT_TRUE(fe.reparameterize(q1, qd1));
  EXPECT_EQ(q1.head(3), q.head(3));
  EXPECT_EQ(qd1.head(3), qd.head(3));
  const JointKinematics after = calcJoint(fe, q1, qd1);
  EXPECT_TRUE(nearRel(after.Q, before.Q, 1e-12));
  EXPECT_TRUE(nearRel(Vec6(after.S * qd1), Vec6(before.S * qd), 1e-12));
  Free3D fu{};
  fu.rotation = FreeRotation::Euler;
  VecJ q2 = q, qd2 = qd;
  EXPECT_FALSE(fu.reparameterize(q2, qd2));
  EXPECT_EQ(q2, q);
}

}  // namespace
}  // namespace redmax
