// J_mr against forward kinematics and Jdot_mr against J_mr, by central differences
// (docs/design.md §8: every analytic derivative gets an FD test).
#include "core/skeleton/kinematics.hpp"

#include <gtest/gtest.h>

#include <random>

#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

State randomState(const Model& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.q = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  s.qdot = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  return s;
}

class KinematicsFd : public ::testing::TestWithParam<int> {};

TEST_P(KinematicsFd, JmrMatchesPoseDifferences) {
  const Model m = scenes::randomTree(8, 100 + GetParam());
  std::mt19937 rng(GetParam());
  const State s = randomState(m, rng);
  SkeletonWorkspace ws(m);
  calcKinematics(m, s, ws);
  // twist of body i along qdot: [phi_i] = E_wi^-1 dE_wi/dt, by central differences in time
  const double h = 1e-6;
  std::vector<Mat4> Ep, Em;
  calcBodyPoses(m, s.q + h * s.qdot, Ep);
  calcBodyPoses(m, s.q - h * s.qdot, Em);
  const VecX phi = ws.J_mr * s.qdot;
  for (int i = 0; i < m.nb(); ++i) {
    const Vec6 fd = unbracket6(inverseE(ws.E_wi[i]) * (Ep[i] - Em[i]) / (2 * h));
    EXPECT_TRUE(nearRel(Vec6(phi.segment<6>(6 * i)), fd, 1e-6)) << "body " << i;
    EXPECT_TRUE(nearRel(ws.phi[i], fd, 1e-6)) << "body " << i;
  }
}

TEST_P(KinematicsFd, JdotMatchesJacobianDifferences) {
  const Model m = scenes::randomTree(8, 200 + GetParam());
  std::mt19937 rng(GetParam());
  const State s = randomState(m, rng);
  SkeletonWorkspace ws(m), wp(m), wm(m);
  calcKinematics(m, s, ws);
  const double h = 1e-6;
  State sp = s, sm = s;
  sp.q += h * s.qdot;
  sm.q -= h * s.qdot;
  calcKinematics(m, sp, wp);
  calcKinematics(m, sm, wm);
  const MatX fd = (wp.J_mr - wm.J_mr) / (2 * h);
  EXPECT_TRUE(nearRel(ws.Jdot_mr, fd, 1e-6));
}

TEST_P(KinematicsFd, JmrZeroOutsideAncestors) {
  const Model m = scenes::randomTree(10, 300 + GetParam());
  std::mt19937 rng(GetParam());
  SkeletonWorkspace ws(m);
  calcKinematics(m, randomState(m, rng), ws);
  for (int i = 0; i < m.nb(); ++i)
    for (int a = 0; a < m.nb(); ++a)
      if (!m.isAncestor(a, i) && m.joints()[a].nq > 0) {
        EXPECT_EQ(ws.J_mr.block(6 * i, m.joints()[a].q_index, 6, m.joints()[a].nq).norm(), 0.0);
      }
}

INSTANTIATE_TEST_SUITE_P(Seeds, KinematicsFd, ::testing::Range(0, 5),
                         [](const ::testing::TestParamInfo<int>& i) { return "seed" + std::to_string(i.param); });

TEST(Kinematics, DoublePendulumTipPosition) {
  const Model m = scenes::doublePendulum(1.0, 1.0);
  State s;
  s.q = Vec2(0.3, -0.7);
  s.qdot = Vec2(0, 0);
  SkeletonWorkspace ws(m);
  calcKinematics(m, s, ws);
  const Vec3 tip = pointPosition(ws, 1, Vec3(0, -1, 0));
  const Vec3 expect(std::sin(0.3) + std::sin(0.3 - 0.7), -std::cos(0.3) - std::cos(0.3 - 0.7), 0);
  EXPECT_TRUE(nearRel(tip, expect, 1e-14));
}

}  // namespace
}  // namespace redmax
