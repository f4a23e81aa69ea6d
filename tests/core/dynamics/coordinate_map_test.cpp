// Hyper-reduced coordinates [D Sec. 4.6.2, Eq. 4.84-4.86]: the map's Jacobians against finite
// differences, and a System on q_R against the same mechanism with the couplings enforced as
// constraints (same accelerations, same trajectories), including the dissertation's chain whose
// joint angles are all equal.
#include <gtest/gtest.h>

#include <random>

#include "constraint_scenes.hpp"
#include "core/dynamics/constraints/coordinate_coupler.hpp"
#include "core/dynamics/coordinate_map.hpp"
#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/joints/spherical_exp.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

// f(x0, x1) = sin(x0) x1 + 0.3 x0^2
ConstraintFunctionPtr nonlinear2() {
  return makeConstraintFunction(
      2, [](const VecX& x) { return std::sin(x[0]) * x[1] + 0.3 * x[0] * x[0]; },
      [](const VecX& x) { return VecX((VecX(2) << std::cos(x[0]) * x[1] + 0.6 * x[0], std::sin(x[0])).finished()); },
      [](const VecX& x) {
        MatX H(2, 2);
        H << -std::sin(x[0]) * x[1] + 0.6, std::cos(x[0]), std::cos(x[0]), 0.0;
        return H;
      });
}
// g(x) = 0.5 sin(x) + 0.2 x^2
ConstraintFunctionPtr nonlinear1() {
  return makeConstraintFunction1([](double x) { return 0.5 * std::sin(x) + 0.2 * x * x; },
                                 [](double x) { return 0.5 * std::cos(x) + 0.4 * x; },
                                 [](double x) { return -0.5 * std::sin(x) + 0.4; });
}
// an OpenSim-style spline through a few knots (as the converter builds for couplers)
ConstraintFunctionPtr spline() {
  return std::make_shared<SimmSpline>(std::vector<double>{-2.0, -1.0, 0.0, 0.8, 2.0},
                                      std::vector<double>{0.3, -0.2, 0.1, 0.6, 0.4});
}

VecX randomVec(int n, std::mt19937& rng, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return VecX::NullaryExpr(n, [&] { return scale * u(rng); });
}

/// dependents over a model with >= 7 coordinates: 2 <- (0, 5), 4 <- 2 (a chain), 6 <- 1 (spline)
CoordinateMap makeTestMap(const Model& m) {
  CoordinateMap map(m);
  map.addDependent(4, {2}, nonlinear1(), 0.7);   // added before its argument becomes dependent
  map.addDependent(2, {0, 5}, nonlinear2(), 1.3);
  map.addDependent(6, {1}, spline(), -0.8);
  return map;
}

TEST(CoordinateMap, JacobiansMatchFiniteDifferences) {
  const Model m = scenes::revoluteChain(8);
  const CoordinateMap map = makeTestMap(m);
  ASSERT_EQ(map.nR(), 5);
  EXPECT_EQ(map.independent(), (std::vector<int>{0, 1, 3, 5, 7}));
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const VecX qR = randomVec(5, rng, 1.5), qdR = randomVec(5, rng, 2.0);
    VecX q, qd;
    MatX J, Jdot;
    map.calc(qR, qdR, q, qd, J, Jdot);
    // values: pass-through and the chain through the functions
    EXPECT_EQ(map.reduce(q), qR);
    EXPECT_NEAR(q[2], 1.3 * nonlinear2()->value(VecJ((VecJ(2) << q[0], q[5]).finished())), 1e-15);
    EXPECT_NEAR(q[4], 0.7 * nonlinear1()->value(VecJ::Constant(1, q[2])), 1e-15);
    EXPECT_TRUE(nearRel(qd, VecX(J * qdR), 1e-14));
    // J_rR = dq_r/dq_R and Jdot_rR = dJ_rR/dt along qdot_R, central differences h = 1e-6
    const double h = 1e-6;
    MatX J_fd(8, 5);
    for (int j = 0; j < 5; ++j) {
      VecX qp, qm;
      map.calcPosition(qR + h * VecX::Unit(5, j), qp);
      map.calcPosition(qR - h * VecX::Unit(5, j), qm);
      J_fd.col(j) = (qp - qm) / (2 * h);
    }
    EXPECT_TRUE(nearRel(J, J_fd, 1e-6));
    VecX a, b;
    MatX Jp, Jm, d1, d2;
    map.calc(qR + h * qdR, qdR, a, b, Jp, d1);
    map.calc(qR - h * qdR, qdR, a, b, Jm, d2);
    EXPECT_TRUE(nearRel(Jdot, MatX((Jp - Jm) / (2 * h)), 1e-6));
  }
}

TEST(CoordinateMap, RejectsBadDependenciesAndStaysUsable) {
  const Model m = scenes::revoluteChain(4);
  CoordinateMap map(m);
  map.addDependent(1, {0}, nonlinear1());
  EXPECT_THROW(map.addDependent(0, {1}, nonlinear1()), ModelError);      // cycle 0 <- 1 <- 0
  EXPECT_THROW(map.addDependent(1, {2}, nonlinear1()), ModelError);      // already dependent
  EXPECT_THROW(map.addDependent(2, {2}, nonlinear1()), ModelError);      // itself
  EXPECT_THROW(map.addDependent(4, {0}, nonlinear1()), ModelError);      // out of range
  EXPECT_THROW(map.addDependent(2, {0, 3, 0}, nonlinear1()), ModelError);  // repeated argument
  EXPECT_THROW(map.addDependent(2, {0}, nonlinear2()), ModelError);      // 2-argument function
  EXPECT_THROW(map.addDependent(2, {0}, nullptr), ModelError);
  EXPECT_EQ(map.nR(), 3);  // unchanged by the failed attempts
  VecX q;
  EXPECT_THROW(map.calcPosition(VecX::Zero(4), q), ModelError);          // wrong size
  map.calcPosition(VecX::Ones(3), q);
  EXPECT_TRUE(q.allFinite());
  // a constant of no arguments (OpenSim Constant) is accepted for any argument list
  map.addDependent(3, {2}, std::make_shared<ConstantFunction>(0.25));
  map.calcPosition(VecX::Ones(2), q);
  EXPECT_EQ(q[3], 0.25);
  System sys(scenes::revoluteChain(5));
  EXPECT_THROW(sys.setCoordinateMap(std::make_shared<CoordinateMap>(map)), ModelError);  // 4 vs 5 coordinates
}

TEST(CoordinateMap, IdentityMapChangesNothing) {
  const Model m = scenes::randomTree(8, 31);
  System plain(m), mapped(m);
  mapped.setCoordinateMap(std::make_shared<CoordinateMap>(m));
  std::mt19937 rng(3);
  State s;
  s.q = randomVec(m.nr(), rng);
  s.qdot = randomVec(m.nr(), rng);
  DynamicsWorkspace w1(m), w2(m);
  EXPECT_TRUE(nearRel(mapped.forwardDynamics(s, w2), plain.forwardDynamics(s, w1), 1e-14));
  EXPECT_NEAR(mapped.kineticEnergy(s, w2), plain.kineticEnergy(s, w1), 1e-14);
}

/// a System on q_R and the same model with the couplings as CoordinateCouplers
struct MappedAndConstrained {
  Model m;
  std::shared_ptr<CoordinateMap> map;
  System mapped, constrained;
  explicit MappedAndConstrained(const Model& model)
      : m(model), map(std::make_shared<CoordinateMap>(makeTestMap(model))), mapped(model), constrained(model) {
    mapped.setCoordinateMap(map);
    constrained.addConstraint(std::make_shared<CoordinateCoupler>(m, 4, std::vector<int>{2}, nonlinear1(), 0.7));
    constrained.addConstraint(std::make_shared<CoordinateCoupler>(m, 2, std::vector<int>{0, 5}, nonlinear2(), 1.3));
    constrained.addConstraint(std::make_shared<CoordinateCoupler>(m, 6, std::vector<int>{1}, spline(), -0.8));
  }
};

class MappedVsConstrained : public ::testing::TestWithParam<int> {};

TEST_P(MappedVsConstrained, SameAccelerationsEnergiesAndForces) {
  // random trees may carry any joint type; the couplings act on their first coordinates
  Model model = scenes::randomTree(9, 1200 + GetParam());
  ASSERT_GE(model.nr(), 7);
  MappedAndConstrained mc(model);
  const int nR = mc.map->nR();
  std::mt19937 rng(GetParam());
  State sR;
  sR.t = 0.1;
  sR.q = randomVec(nR, rng);
  sR.qdot = randomVec(nR, rng, 2.0);
  const State sr = mc.mapped.expandState(sR);
  EXPECT_EQ(mc.mapped.reduceState(sr).q, sR.q);
  DynamicsWorkspace wm(mc.m), wc(mc.m);
  // hyper-reduced accelerations mapped back: qddot_r = J qddot_R + Jdot qdot_R [D Eq. 4.84]
  const VecX aR = mc.mapped.forwardDynamics(sR, wm);
  ASSERT_EQ(aR.size(), nR);
  const VecX ar_mapped = wm.J_rR * aR + wm.Jdot_rR * sR.qdot;
  const VecX ar_constrained = mc.constrained.forwardDynamics(sr, wc);
  EXPECT_TRUE(nearRel(ar_mapped, ar_constrained, 1e-9)) << (ar_mapped - ar_constrained).norm();
  // M_R = J^T M_r J with M_r of the plain skeleton [D Eq. 4.86]
  EXPECT_TRUE(nearRel(wm.M, MatX(wm.J_rR.transpose() * wc.M * wm.J_rR), 1e-12));
  // energies of the expanded state
  EXPECT_NEAR(mc.mapped.kineticEnergy(sR, wm), mc.constrained.kineticEnergy(sr, wc), 1e-12 * (1 + mc.constrained.kineticEnergy(sr, wc)));
  EXPECT_NEAR(mc.mapped.potentialEnergy(sR, wm), mc.constrained.potentialEnergy(sr, wc), 1e-12 * (1 + std::abs(mc.constrained.potentialEnergy(sr, wc))));
  EXPECT_NEAR(0.5 * sR.qdot.dot(wm.M * sR.qdot), mc.mapped.kineticEnergy(sR, wm), 1e-12 * (1 + wm.M.norm()));
  // inverse dynamics in q_R is J^T of the skeleton's: tau_R = J^T (M_r qddot_r - f_r)
  const VecX qddR = randomVec(nR, rng);
  const VecX tauR = mc.mapped.inverseDynamics(sR, qddR, wm);
  const VecX qddr = wm.J_rR * qddR + wm.Jdot_rR * sR.qdot;
  System plain(model);
  const VecX taur = plain.inverseDynamics(sr, qddr, wc);
  EXPECT_TRUE(nearRel(tauR, VecX(wm.J_rR.transpose() * taur), 1e-10));
  const VecX taur_rnea = inverseDynamicsRecursive(model, sr, qddr);
  EXPECT_TRUE(nearRel(tauR, VecX(wm.J_rR.transpose() * taur_rnea), 1e-9));
}

INSTANTIATE_TEST_SUITE_P(Seeds, MappedVsConstrained, ::testing::Range(0, 4),
                         [](const ::testing::TestParamInfo<int>& i) { return "seed" + std::to_string(i.param); });

TEST(MappedVsConstrained, SameTrajectoryAndTheCoupledCoordinateFollowsF) {
  // 8-link 3D chain, RK4 h = 1e-3 for 2 s: constrained (Baumgarte) vs hyper-reduced
  const Model model = scenes::revoluteChain(8);
  MappedAndConstrained mc(model);
  mc.constrained.stabilization.alpha = mc.constrained.stabilization.beta = 20.0;
  std::mt19937 rng(11);
  State sR;
  sR.q = randomVec(mc.map->nR(), rng, 0.8);
  sR.qdot = randomVec(mc.map->nR(), rng, 1.0);
  State sr = mc.mapped.expandState(sR);
  DynamicsWorkspace wm(mc.m), wc(mc.m);
  double max_state = 0, max_follow_c = 0, max_follow_m = 0, max_dE = 0;
  const double E0 = mc.mapped.kineticEnergy(sR, wm) + mc.mapped.potentialEnergy(sR, wm);
  auto follow = [&](const State& s) {
    // |q_2 - 1.3 f(q_0, q_5)|, |q_4 - 0.7 g(q_2)|, |q_6 + 0.8 spline(q_1)|
    const double e1 = std::abs(s.q[2] - 1.3 * nonlinear2()->value(VecJ((VecJ(2) << s.q[0], s.q[5]).finished())));
    const double e2 = std::abs(s.q[4] - 0.7 * nonlinear1()->value(VecJ::Constant(1, s.q[2])));
    const double e3 = std::abs(s.q[6] + 0.8 * spline()->value(VecJ::Constant(1, s.q[1])));
    return std::max({e1, e2, e3});
  };
  for (int k = 0; k < 2000; ++k) {
    testing::rk4Step(mc.mapped, sR, 1e-3, wm);
    testing::rk4Step(mc.constrained, sr, 1e-3, wc);
    const State er = mc.mapped.expandState(sR);
    max_state = std::max({max_state, (er.q - sr.q).norm(), (er.qdot - sr.qdot).norm()});
    max_follow_c = std::max(max_follow_c, follow(sr));
    max_follow_m = std::max(max_follow_m, follow(er));
    max_dE = std::max(max_dE, std::abs(mc.mapped.kineticEnergy(sR, wm) + mc.mapped.potentialEnergy(sR, wm) - E0));
  }
  EXPECT_LE(max_state, 1e-7);
  EXPECT_LE(max_follow_c, 1e-8);
  EXPECT_LE(max_follow_m, 1e-14);
  EXPECT_LE(max_dE, 1e-8 * std::abs(E0));
  std::printf("coupled chain rk4 2 s: |state mapped - constrained| %.2e, coupling residual %.2e (constrained) "
              "%.2e (mapped), energy error %.2e J of %.1f J\n",
              max_state, max_follow_c, max_follow_m, max_dE, E0);

  // semi-implicit Euler over 0.5 s: the constrained run (velocity-level rows + projection) and
  // the hyper-reduced run are two first-order discretisations of the same motion, so their
  // difference must shrink like h
  auto eulerDifference = [&](double h, double& max_follow) {
    State eR;
    std::mt19937 r2(11);
    eR.q = randomVec(mc.map->nR(), r2, 0.8);
    eR.qdot = randomVec(mc.map->nR(), r2, 1.0);
    State er = mc.mapped.expandState(eR);
    mc.constrained.stabilization = {};
    double max_diff = 0;
    max_follow = 0;
    const long n = std::lround(0.5 / h);
    for (long k = 0; k < n; ++k) {
      testing::eulerStep(mc.mapped, eR, h, wm);
      testing::eulerStep(mc.constrained, er, h, wc);
      mc.constrained.projectPositions(er, wc, 1e-13);
      mc.constrained.projectVelocities(er, wc);
      max_follow = std::max(max_follow, follow(er));
      max_diff = std::max(max_diff, (mc.mapped.expandState(eR).q - er.q).norm());
    }
    return max_diff;
  };
  double follow1 = 0, follow2 = 0;
  const double d1 = eulerDifference(1e-3, follow1);
  const double d2 = eulerDifference(5e-4, follow2);
  EXPECT_LE(std::max(follow1, follow2), 1e-12);
  EXPECT_LE(d1, 2e-2);
  EXPECT_LE(d2, 0.6 * d1);
  std::printf("coupled chain euler 0.5 s: |q mapped - constrained| %.2e (h = 1e-3), %.2e (h = 5e-4); coupling "
              "residual %.2e\n",
              d1, d2, std::max(follow1, follow2));
}

TEST(HyperReduced, AllJointAnglesEqualIsOneDegreeOfFreedom) {
  // [D Sec. 4.6.2]: a chain whose joint angles are all equal, qdot_r = (1 ... 1)^T qdot_R
  const int n = 6;
  const Model model = scenes::revoluteChain(n);
  auto map = std::make_shared<CoordinateMap>(model);
  System constrained(model), mapped(model);
  for (int k = 1; k < n; ++k) {
    map->addDependent(k, {0}, makeLinearFunction({1.0}));
    constrained.addConstraint(std::make_shared<CoordinateCoupler>(model, k, std::vector<int>{0}, makeLinearFunction({1.0})));
  }
  mapped.setCoordinateMap(map);
  ASSERT_EQ(mapped.ndof(), 1);
  DynamicsWorkspace wm(model), wc(model);
  State sR;
  sR.q = VecX::Constant(1, 0.4);
  sR.qdot = VecX::Constant(1, -0.7);
  mapped.calcMassAndForce(sR, wm);
  EXPECT_TRUE(nearRel(wm.J_rR, MatX(MatX::Ones(n, 1)), 0.0));
  EXPECT_EQ(wm.Jdot_rR.norm(), 0.0);
  // M_R is the sum of all entries of M_r
  System plain(model);
  const State sr = mapped.expandState(sR);
  plain.calcMassAndForce(sr, wc);
  EXPECT_NEAR(wm.M(0, 0), wc.M.sum(), 1e-12 * wc.M.norm());
  // accelerations agree with the constrained chain
  const VecX aR = mapped.forwardDynamics(sR, wm);
  const VecX ar = constrained.forwardDynamics(sr, wc);
  EXPECT_TRUE(nearRel(VecX::Constant(n, aR[0]), ar, 1e-10));
  // and the 1-DOF simulation conserves energy (RK4, 2 s)
  const double E0 = mapped.kineticEnergy(sR, wm) + mapped.potentialEnergy(sR, wm);
  double max_dE = 0;
  for (int k = 0; k < 2000; ++k) {
    testing::rk4Step(mapped, sR, 1e-3, wm);
    max_dE = std::max(max_dE, std::abs(mapped.kineticEnergy(sR, wm) + mapped.potentialEnergy(sR, wm) - E0));
  }
  EXPECT_LE(max_dE, 1e-8);
}

TEST(HyperReduced, ChartSwitchOnlyOnFreeIndependentJoints) {
  // an exponential-coordinate ball joint (independent) and a hinge coupled to a third hinge
  ModelBuilder b("ball_and_hinges");
  const Mat3 I = Vec3(0.1, 0.2, 0.3).asDiagonal();
  const int ball = b.addBody("ball", 1.0, Vec3(0, -0.3, 0), I, -1, "ball_joint", SphericalExp{});
  const int h1 = b.addBody("h1", 1.0, Vec3(0, -0.2, 0), I, ball, "h1_joint", Revolute{}, makeTranslation(Vec3(0, -0.5, 0)));
  b.addBody("h2", 1.0, Vec3(0, -0.2, 0), I, h1, "h2_joint", Revolute{}, makeTranslation(Vec3(0, -0.5, 0)));
  const Model m = b.finalize();
  ASSERT_EQ(m.nr(), 5);
  auto map = std::make_shared<CoordinateMap>(m);
  map->addDependent(4, {3}, nonlinear1());
  System sys(m);
  sys.setCoordinateMap(map);
  State s;
  s.q = VecX(4);
  s.q << 4.0, 2.5, -1.0, 0.3;  // |ball q| = 4.8 > 1.5 pi: must switch chart
  s.qdot = VecX(4);
  s.qdot << 0.3, -0.2, 0.5, 1.1;
  std::vector<Mat4> E0, E1;
  const State r0 = sys.expandState(s);
  calcBodyPoses(m, r0.q, E0);
  DynamicsWorkspace ws(m);
  const double T0 = sys.kineticEnergy(s, ws);
  EXPECT_EQ(sys.reparameterize(s), 1);
  EXPECT_LT(s.q.head(3).norm(), 1.6);
  EXPECT_EQ(s.q[3], 0.3);
  calcBodyPoses(m, sys.expandState(s).q, E1);
  for (int i = 0; i < m.nb(); ++i) EXPECT_TRUE(nearRel(E1[i], E0[i], 1e-12));
  EXPECT_NEAR(sys.kineticEnergy(s, ws), T0, 1e-12 * (1 + T0));
  // a ball whose coordinate drives a dependent may not switch
  auto map2 = std::make_shared<CoordinateMap>(m);
  map2->addDependent(4, {0}, nonlinear1());
  System sys2(m);
  sys2.setCoordinateMap(map2);
  State s2;
  s2.q = VecX(4);
  s2.q << 4.0, 2.5, -1.0, 0.3;
  s2.qdot = VecX::Zero(4);
  EXPECT_EQ(sys2.reparameterize(s2), 0);
}

}  // namespace
}  // namespace redmax
