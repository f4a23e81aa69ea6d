#include "core/dynamics/body_loads.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/dynamics/system.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

TEST(BodyLoads, PointForceIsNegativeGradientOfItsPotential) {
  ModelBuilder mb(scenes::randomTree(7, 41));
  mb.setGravity(Vec3::Zero());
  const Model m = mb.finalize();
  auto loads = std::make_shared<BodyLoads>();
  loads->point_forces.push_back({3, Vec3(0.1, -0.2, 0.3), Vec3(1.0, 2.0, -0.5)});
  loads->point_forces.push_back({6, Vec3(-0.3, 0.0, 0.2), Vec3(-2.0, 0.5, 1.5)});
  System with(m), without(m);
  with.addTerm(loads);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  State s = with.defaultState();
  s.q = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  DynamicsWorkspace ws(m), ws0(m);
  with.calcMassAndForce(s, ws);
  without.calcMassAndForce(s, ws0);
  const VecX f_load = ws.f - ws0.f;
  const double h = 1e-6;
  VecX fd(m.nr());
  for (int k = 0; k < m.nr(); ++k) {
    State sp = s, sm = s;
    sp.q[k] += h;
    sm.q[k] -= h;
    fd[k] = -(loads->potentialEnergy(m, sp, (calcKinematics(m, sp, ws.sk), ws.sk)) -
              loads->potentialEnergy(m, sm, (calcKinematics(m, sm, ws.sk), ws.sk))) / (2 * h);
  }
  EXPECT_TRUE(nearRel(f_load, fd, 1e-7));
  EXPECT_GT(f_load.norm(), 0.1);
}

TEST(BodyLoads, WrenchEqualsForcePairAndPointForceMatchesPointJacobian) {
  const Model m = scenes::randomTree(6, 77);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  State s;
  s.q = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  s.qdot = VecX::Zero(m.nr());
  SkeletonWorkspace ws(m);
  calcKinematics(m, s, ws);
  const int b = 5;
  const Vec3 x(0.2, 0.1, -0.3), F(0.5, -1.0, 2.0);
  BodyLoads pf;
  pf.point_forces.push_back({b, x, F});
  VecX f1 = VecX::Zero(m.nr());
  pf.addForce(m, s, ws, f1);
  MatX J(3, m.nr());
  pointJacobian(m, ws, b, x, J);
  EXPECT_TRUE(nearRel(f1, VecX(J.transpose() * F), 1e-13));
  // the same load as a wrench: force through the origin plus torque (x_w - o_w) x F
  BodyLoads bw;
  const Vec3 xw = transformPoint(ws.E_wi[b], x), ow = ws.E_wi[b].topRightCorner<3, 1>();
  bw.wrenches.push_back({b, (xw - ow).cross(F), F});
  VecX f2 = VecX::Zero(m.nr());
  bw.addForce(m, s, ws, f2);
  EXPECT_TRUE(nearRel(f2, f1, 1e-13));
}

TEST(JointSpringsDampers, StiffnessAndDampingAreForceDerivatives) {
  // with zero gravity and zero velocity, -df/dq = K and -df/dqdot = D exactly [D Eq. 4.81]
  ModelBuilder mb(scenes::randomTree(6, 12));
  mb.setGravity(Vec3::Zero());
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(0.1, 2.0);
  for (int k = 0; k < mb.nr(); ++k) {
    Coordinate& c = mb.coordinateAt(k);
    c.stiffness = 10 * u(rng);
    c.damping = u(rng);
    c.rest_value = u(rng) - 1.0;
  }
  const Model m = mb.finalize();
  System sys(m);
  State s = sys.defaultState();
  s.q.setConstant(0.3);
  DynamicsWorkspace ws(m);
  sys.calcMassAndForce(s, ws);
  sys.calcStiffnessDamping(s, ws);
  const double h = 1e-6;
  MatX Kfd(m.nr(), m.nr()), Dfd(m.nr(), m.nr());
  for (int k = 0; k < m.nr(); ++k) {
    State sp = s, sm = s;
    sp.q[k] += h;
    sm.q[k] -= h;
    DynamicsWorkspace wp(m), wm(m);
    sys.calcMassAndForce(sp, wp);
    sys.calcMassAndForce(sm, wm);
    Kfd.col(k) = -(wp.f - wm.f) / (2 * h);
    sp = s;
    sm = s;
    sp.qdot[k] += h;
    sm.qdot[k] -= h;
    sys.calcMassAndForce(sp, wp);
    sys.calcMassAndForce(sm, wm);
    Dfd.col(k) = -(wp.f - wm.f) / (2 * h);
  }
  EXPECT_TRUE(nearRel(ws.K, Kfd, 1e-7));
  EXPECT_TRUE(nearRel(ws.D, Dfd, 1e-7));
}

}  // namespace
}  // namespace redmax
