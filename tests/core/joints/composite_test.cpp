// Composite joints: nesting is associative, the product of part transforms, FD through the typed
// suite; too many coordinates is an error.
#include "core/joints/composite.hpp"

#include <gtest/gtest.h>

#include "core/joints/joint.hpp"
#include "tests/core/joints/joint_test_util.hpp"

namespace redmax {
namespace {

using namespace redmax::test;

void expectSame(const Joint& a, const Joint& b, std::mt19937& rng) {
  ASSERT_EQ(a.nq(), b.nq());
  for (int t = 0; t < 5; ++t) {
    const VecJ q = randomVecJ(a.nq(), rng), qd = randomVecJ(a.nq(), rng);
    const JointKinematics ka = calcJoint(a, q, qd), kb = calcJoint(b, q, qd);
    EXPECT_TRUE(nearRel(ka.Q, kb.Q, 1e-13));
    EXPECT_TRUE(nearRel(ka.S, kb.S, 1e-13));
    EXPECT_TRUE(nearRel(ka.Sdot, kb.Sdot, 1e-13));
  }
}

TEST(Composite, NestedEqualsFlattened) {
  std::mt19937 rng(41);
  const Joint A = Revolute{Vec3(1, 2, -1).normalized()};
  const Joint B = Revolute{Vec3(0.2, 0.1, 1).normalized()};
  const Joint C = Prismatic{Vec3(0.3, -1, 0.2).normalized()};
  const Joint D = SphericalEuler{EulerSequence::ZXZ};
  const Joint flat = Composite({A, B, C, D});
  expectSame(flat, Composite({A, Composite({B, Composite({C, D})})}), rng);
  expectSame(flat, Composite({Composite({A, B}), Composite({C, D})}), rng);
  expectSame(flat, Composite({Composite({Composite({A, B}), C}), D}), rng);
}

TEST(Composite, TransformIsProductOfParts) {
  std::mt19937 rng(42);
  const Joint A = SphericalExp{}, B = Prismatic{Vec3::UnitY()}, C = Revolute{Vec3::UnitX()};
  const Joint comp = Composite({A, B, C});
  const VecJ q = randomVecJ(5, rng);
  const Mat4 expect = calcJoint(A, q.segment(0, 3)).Q * calcJoint(B, q.segment(3, 1)).Q *
                      calcJoint(C, q.segment(4, 1)).Q;
  EXPECT_TRUE(nearRel(calcJoint(comp, q).Q, expect, 1e-15));
  // the last part's columns are its own S [D Eq. 4.48]
  EXPECT_TRUE(nearRel(Vec6(calcJoint(comp, q).S.col(4)), Vec6(calcJoint(C, q.segment(4, 1)).S.col(0)), 0.0));
}

TEST(Composite, EmptyIsFixedAndTooManyCoordinatesThrows) {
  const JointKinematics k = calcJoint(Composite{}, VecJ(0));
  EXPECT_EQ(k.S.cols(), 0);
  EXPECT_TRUE(k.Q.isIdentity(0.0));
  EXPECT_THROW(Composite({SphericalExp{}, Translational{}, Revolute{}}), JointError);
}

TEST(Composite, ReparameterizePassesThroughToParts) {
  std::mt19937 rng(43);
  const Joint comp = Composite({Prismatic{Vec3::UnitZ()}, SphericalExp{}});
  VecJ q(4), qd = randomVecJ(4, rng);
  q << 0.3, 4.0, 3.0, 2.0;  // |r| = 5.39 > 1.5 pi
  const JointKinematics before = calcJoint(comp, q, qd);
  const VecJ qd0 = qd;
  ASSERT_TRUE(comp.reparameterize(q, qd));
  EXPECT_EQ(q[0], 0.3);
  EXPECT_EQ(qd[0], qd0[0]);
  const JointKinematics after = calcJoint(comp, q, qd);
  EXPECT_TRUE(nearRel(after.Q, before.Q, 1e-12));
  EXPECT_TRUE(nearRel(Vec6(after.S * qd), Vec6(before.S * qd0), 1e-12));
}

}  // namespace
}  // namespace redmax
