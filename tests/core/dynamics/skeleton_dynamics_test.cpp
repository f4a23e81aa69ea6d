#include "core/dynamics/skeleton_dynamics.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/dynamics/system.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

State randomState(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.q = VecX::NullaryExpr(n, [&] { return u(rng); });
  s.qdot = VecX::NullaryExpr(n, [&] { return 2.0 * u(rng); });
  return s;
}

class DynamicsSeeds : public ::testing::TestWithParam<int> {};

TEST_P(DynamicsSeeds, RecursiveNewtonEulerMatchesRedmaxRoute) {
  const Model m = scenes::randomTree(12, 500 + GetParam());
  System sys(m);
  std::mt19937 rng(GetParam());
  const State s = randomState(m.nr(), rng);
  const VecX qddot = randomState(m.nr(), rng).qdot;
  DynamicsWorkspace ws(m);
  const VecX tau_redmax = sys.inverseDynamics(s, qddot, ws);
  const VecX tau_rnea = inverseDynamicsRecursive(m, s, qddot);
  EXPECT_LE((tau_redmax - tau_rnea).norm(), 1e-10 * tau_rnea.norm());
}

TEST_P(DynamicsSeeds, ForwardInvertsInverse) {
  // System::forwardDynamics (REDMAX M and f, factorised) against the O(n) Newton-Euler pass, which
  // shares neither M nor f: the unactuated accelerations need zero generalized force
  const Model m = scenes::randomTree(12, 600 + GetParam());
  System sys(m);
  std::mt19937 rng(GetParam());
  const State s = randomState(m.nr(), rng);
  DynamicsWorkspace ws(m);
  const VecX qddot = sys.forwardDynamics(s, ws);
  const VecX tau = inverseDynamicsRecursive(m, s, qddot);
  // the scale: what the accelerations balance (gravity and velocity products, -f)
  const VecX tau_rest = inverseDynamicsRecursive(m, s, VecX::Zero(m.nr()));
  ASSERT_GT(tau_rest.norm(), 1e-3);
  EXPECT_LE(tau.norm(), 1e-10 * tau_rest.norm());
  // and the REDMAX route's own inverse dynamics at those accelerations
  EXPECT_LE(sys.inverseDynamics(s, qddot, ws).norm(), 1e-10 * tau_rest.norm());
  // the mass matrix forwardDynamics factorised, column by column from the recursive pass
  MatX M_rnea(m.nr(), m.nr());
  for (int i = 0; i < m.nr(); ++i)
    M_rnea.col(i) = inverseDynamicsRecursive(m, s, VecX::Unit(m.nr(), i)) - tau_rest;
  sys.calcMassAndForce(s, ws);
  EXPECT_LE((ws.M - M_rnea).norm(), 1e-10 * M_rnea.norm());
}

TEST_P(DynamicsSeeds, MassMatrixIsKineticEnergyHessian) {
  const Model m = scenes::randomTree(10, 700 + GetParam());
  System sys(m);
  std::mt19937 rng(GetParam());
  const State s = randomState(m.nr(), rng);
  DynamicsWorkspace ws(m);
  sys.calcMassAndForce(s, ws);
  EXPECT_NEAR(0.5 * s.qdot.dot(ws.M * s.qdot), sys.kineticEnergy(s, ws), 1e-12 * (1 + ws.M.norm()));
  EXPECT_TRUE(nearRel(ws.M, MatX(ws.M.transpose()), 1e-14));
}

TEST_P(DynamicsSeeds, ForceIsLagrangian) {
  // f_r = -dV/dq - (d/dt dT/dqdot - dT/dq) + M qddot ... checked via power: with no springs,
  // dE/dt = qdot . (f_r - quadratic terms) reduces to the identity  dE/dt = 0 for free motion.
  const Model m = scenes::randomTree(8, 800 + GetParam());
  System sys(m);
  std::mt19937 rng(GetParam());
  State s = randomState(m.nr(), rng);
  DynamicsWorkspace ws(m);
  const VecX qddot = sys.forwardDynamics(s, ws);
  // dE/dt by central differences along the exact flow to second order
  const double h = 1e-6;
  State sp = s, sm = s;
  sp.q += h * s.qdot + 0.5 * h * h * qddot;
  sp.qdot += h * qddot;
  sm.q -= h * s.qdot - 0.5 * h * h * qddot;
  sm.qdot -= h * qddot;
  auto E = [&](const State& x) { return sys.kineticEnergy(x, ws) + sys.potentialEnergy(x, ws); };
  const double dEdt = (E(sp) - E(sm)) / (2 * h);
  EXPECT_NEAR(dEdt, 0.0, 1e-6 * (1 + std::abs(E(s))));
}

INSTANTIATE_TEST_SUITE_P(Seeds, DynamicsSeeds, ::testing::Range(0, 5),
                         [](const ::testing::TestParamInfo<int>& i) { return "seed" + std::to_string(i.param); });

TEST(SkeletonDynamics, SinglePendulumAnalytic) {
  // rod of length L hinged at one end: I qddot = -m g (L/2) sin q
  ModelBuilder b;
  b.setGravity(Vec3(0, -9.81, 0));
  const double m = 2.0, L = 0.8;
  Mat3 I = Mat3::Zero();
  I(0, 0) = I(2, 2) = m * L * L / 12;
  I(1, 1) = 1e-3;
  b.addBody("rod", m, Vec3(0, -L / 2, 0), I, -1, "pin", Revolute{Vec3::UnitZ()});
  System sys(b.finalize());
  State s = sys.defaultState();
  s.q[0] = 0.4;
  s.qdot[0] = 1.3;
  DynamicsWorkspace ws(sys.model());
  const VecX qdd = sys.forwardDynamics(s, ws);
  EXPECT_NEAR(qdd[0], -m * 9.81 * L / 2 * std::sin(0.4) / (m * L * L / 3), 1e-12);
}

}  // namespace
}  // namespace redmax
