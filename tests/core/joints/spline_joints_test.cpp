// Spline joints: FD on every segment and beyond the range, continuity across segments, exact
// revolute/helical motion from frames on a screw, linear precision of the surface, bad input.
#include "core/joints/spline_joints.hpp"

#include <gtest/gtest.h>

#include "core/joints/joint.hpp"
#include "tests/core/joints/joint_test_util.hpp"

namespace redmax {
namespace {

using namespace redmax::test;

std::vector<Mat4> randomFrames(int n, std::mt19937& rng) {
  std::vector<Mat4> f{makeE(expSO3(Vec3(randomVecJ(3, rng))), Vec3(randomVecJ(3, rng)))};
  for (int i = 1; i < n; ++i)
    f.push_back(f.back() * makeE(expSO3(Vec3(randomVecJ(3, rng, -0.8, 0.8))), Vec3(randomVecJ(3, rng, -0.4, 0.4))));
  return f;
}

TEST(SplineCurve, FiniteDifferencesOnEverySegmentAndBeyond) {
  std::mt19937 rng(61);
  const Joint j = SplineCurve(randomFrames(7, rng));  // 4 segments, q in [0, 4]
  for (double q0 : {-0.6, 0.2, 0.7, 1.3, 1.8, 2.4, 2.9, 3.5, 3.95, 4.5}) {
    VecJ q(1), qd(1);
    q << q0;
    qd << -1.7;
    const JointKinematics k = calcJoint(j, q, qd);
    EXPECT_TRUE(isRigid(k.Q));
    EXPECT_TRUE(nearRel(bracket6(k.S.col(0)), fdBracketColumn(j, q, 0), kFdTol)) << q0;
    EXPECT_TRUE(nearRel(k.Sdot, fdSdot(j, q, qd), kFdTol)) << q0;
  }
}

TEST(SplineCurve, ContinuousAcrossSegments) {
  // uniform cubic B-splines are C2: Q, S and Sdot agree from both sides of each knot
  std::mt19937 rng(62);
  const Joint j = SplineCurve(randomFrames(6, rng));
  for (int knot = 1; knot <= 2; ++knot) {
    VecJ qa(1), qb(1), qd(1);
    qa << knot - 1e-12;
    qb << knot + 1e-12;
    qd << 0.9;
    const JointKinematics a = calcJoint(j, qa, qd), b = calcJoint(j, qb, qd);
    EXPECT_TRUE(nearRel(a.Q, b.Q, 1e-10));
    EXPECT_TRUE(nearRel(a.S, b.S, 1e-10));
    EXPECT_TRUE(nearRel(a.Sdot, b.Sdot, 1e-10));
  }
}

TEST(SplineCurve, FramesOnAScrewGiveExactScrewMotion) {
  // C_i = exp(i [xi]) with xi = (0, 0, a, 0, 0, d): every dC_i = xi, the cumulative weights sum
  // to 1 + u on each segment, so Q(q) = exp((q + 1) [xi]) exactly, S = xi and Sdot = 0.
  // With d = 0 this is a revolute joint about z scaled by a (the motion checked is the full
  // transform at 9 points over 3 segments and beyond, not only at the knots).
  for (double d : {0.0, 0.25}) {
    const double a = 0.4;
    Vec6 xi;
    xi << 0, 0, a, 0, 0, d;
    std::vector<Mat4> frames;
    for (int i = 0; i < 6; ++i) frames.push_back(expSE3(xi * i));
    const Joint j = SplineCurve(frames);
    for (double q0 : {-0.3, 0.0, 0.5, 1.0, 1.25, 2.0, 2.75, 3.0, 3.4}) {
      VecJ q(1), qd(1);
      q << q0;
      qd << 1.3;
      const JointKinematics k = calcJoint(j, q, qd);
      EXPECT_TRUE(nearRel(k.Q, expSE3(xi * (q0 + 1.0)), 1e-13)) << q0;
      EXPECT_TRUE(nearRel(Vec6(k.S.col(0)), xi, 1e-13)) << q0;
      EXPECT_TRUE(k.Sdot.isZero(1e-13)) << q0;
    }
  }
}

TEST(SplineCurve, RejectsBadControlFrames) {
  std::mt19937 rng(63);
  EXPECT_THROW(SplineCurve(randomFrames(3, rng)), JointError);
  std::vector<Mat4> f = randomFrames(5, rng);
  f[2](0, 0) += 0.1;  // not a rotation
  EXPECT_THROW(SplineCurve{f}, JointError);
  std::vector<Mat4> g(4, Mat4::Identity());
  g[2] = makeE(rotationAboutAxis(2, M_PI), Vec3::Zero());  // half turn: log ambiguous
  EXPECT_THROW(SplineCurve{g}, JointError);
}

TEST(SplineSurface, LinearControlValuesGiveLinearMotion) {
  // control values C(i, j) = i (x translation), j (y translation), 0.3 i (z rotation): by linear
  // precision f = q1 + 1, q2 + 1, 0.3 (q1 + 1), so Q = T(q1 + 1, q2 + 1, 0) R_z(0.3 (q1 + 1))
  std::array<Mat4, 6> C;
  for (auto& c : C) c.setZero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      C[0](i, j) = i;
      C[1](i, j) = j;
      C[5](i, j) = 0.3 * i;
    }
  const Joint sj = SplineSurface(C);
  std::mt19937 rng(64);
  for (int t = 0; t < 5; ++t) {
    const VecJ q = randomVecJ(2, rng, -0.2, 1.2), qd = randomVecJ(2, rng);
    const JointKinematics k = calcJoint(sj, q, qd);
    const Mat4 expect = makeE(rotationAboutAxis(2, 0.3 * (q[0] + 1)), Vec3(q[0] + 1, q[1] + 1, 0));
    EXPECT_TRUE(nearRel(k.Q, expect, 1e-14));
    for (int c = 0; c < 2; ++c) EXPECT_TRUE(nearRel(bracket6(k.S.col(c)), fdBracketColumn(sj, q, c), kFdTol));
    EXPECT_TRUE(nearRel(k.Sdot, fdSdot(sj, q, qd), kFdTol));
  }
  C[2](1, 1) = std::nan("");
  EXPECT_THROW(SplineSurface{C}, JointError);
}

TEST(SplineSurface, CoordinateDerivativesMatchDifferences) {
  std::mt19937 rng(65);
  std::array<Mat4, 6> C;
  for (auto& c : C) c = Mat4::Random();
  const SplineSurface s(C);
  for (int k = 0; k < 6; ++k) {
    const VecJ q = randomVecJ(2, rng, 0.0, 1.0);
    double f;
    Vec2 g;
    Eigen::Matrix2d H;
    s.evalCoordinate(k, q, f, g, H);
    for (int i = 0; i < 2; ++i) {
      VecJ qp = q, qm = q;
      qp[i] += kH;
      qm[i] -= kH;
      double fp, fm;
      Vec2 gp, gm;
      Eigen::Matrix2d Hp;
      s.evalCoordinate(k, qp, fp, gp, Hp);
      s.evalCoordinate(k, qm, fm, gm, Hp);
      EXPECT_NEAR(g[i], (fp - fm) / (2 * kH), kFdTol * (1 + std::abs(g[i])));
      EXPECT_TRUE(nearRel(Vec2(H.col(i)), Vec2((gp - gm) / (2 * kH)), kFdTol));
    }
  }
}

}  // namespace
}  // namespace redmax
