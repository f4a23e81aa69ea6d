// Cross-check of the core (REDMAX J_mr route and O(n) RNEA) against Simbody on random trees:
// body poses, mass matrix, inverse dynamics and forward accelerations agree to 1e-9 relative
// (|a - b| <= 1e-9 |b|), in core velocity space and, for Euler-angle Ball/Free mobilizers, also in
// Simbody's u space through u = T(q) qdot.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <set>
#include <string>

#include <Eigen/Dense>

#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/dynamics/system.hpp"
#include "core/skeleton/kinematics.hpp"
#include "plugin/simbody/model_to_simbody.hpp"
#include "validation/scenes/humanoid.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using simbody::SimbodyBuildOptions;
using simbody::SphericalAs;

constexpr double kTol = 1e-9;

// largest relative difference seen by relClose in the current test, printed at its end so the
// margin below 1e-9 is visible in the log
double g_worst = 0.0;
class CrosscheckLog : public ::testing::EmptyTestEventListener {
  void OnTestStart(const ::testing::TestInfo&) override { g_worst = 0.0; }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    if (g_worst > 0.0)
      std::printf("  [%s.%s] largest relative difference: %.3e\n", info.test_suite_name(), info.name(), g_worst);
  }
};
const bool g_log_installed = [] {
  ::testing::UnitTest::GetInstance()->listeners().Append(new CrosscheckLog);
  return true;
}();

// |a - b| <= tol |b|, with a readable failure message
template <class A, class B>
::testing::AssertionResult relClose(const A& a, const B& b, double tol) {
  const double err = (a - b).norm();
  const double ref = b.norm();
  if (tol <= kTol) g_worst = std::max(g_worst, err / ref);
  if (err <= tol * ref) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "relative difference " << err / ref << " > " << tol
                                       << " (|diff| = " << err << ", |ref| = " << ref << ")";
}

// random state: angles in [-1, 1] keep Euler-angle joints away from gimbal lock (|q2| < pi/2)
State randomState(const Model& m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.t = 0.0;
  s.q = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  s.qdot = VecX::NullaryExpr(m.nr(), [&] { return 2.0 * u(rng); });
  return s;
}

struct TreeCase {
  int n;
  std::uint32_t seed;
};
const TreeCase kTrees[] = {{5, 1}, {8, 2}, {10, 3}, {12, 4}, {15, 5}, {15, 6}, {7, 7}, {11, 8}};

std::string label(const TreeCase& c, SphericalAs mode) {
  return "tree n=" + std::to_string(c.n) + " seed=" + std::to_string(c.seed) +
         (mode == SphericalAs::Ball ? " (ball)" : " (gimbal)");
}

class Crosscheck : public ::testing::TestWithParam<SphericalAs> {};

TEST_P(Crosscheck, BodyPosesMatch) {
  for (const auto& c : kTrees) {
    const Model m = scenes::randomTree(c.n, c.seed, scenes::TreeJoints::SimbodyComparable);
    SimbodyBuildOptions opt;
    opt.spherical = GetParam();
    const auto sm = simbody::makeSimbodyModel(m, opt);
    std::mt19937 rng(c.seed);
    const State s = randomState(m, rng);
    SimTK::State sb = sm->default_state;
    simbody::setSimbodyState(*sm, m, s, sb);
    sm->system.realize(sb, SimTK::Stage::Velocity);
    SkeletonWorkspace ws(m);
    calcKinematics(m, s, ws);
    for (int i = 0; i < m.nb(); ++i) {
      const SimTK::Transform& X_GB = sm->mobods[i].getBodyTransform(sb);
      Mat4 E = Mat4::Identity();
      for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) E(r, k) = X_GB.R()[r][k];
        E(r, 3) = X_GB.p()[r];
      }
      EXPECT_TRUE(relClose(E, ws.E_wi[i], 1e-12)) << label(c, GetParam()) << " body " << i;
      // body twist: Simbody's spatial velocity (w; v of the origin) is in ground; the core's in body
      const SimTK::SpatialVec& V = sm->mobods[i].getBodyVelocity(sb);
      Vec6 phi_w;
      phi_w << V[0][0], V[0][1], V[0][2], V[1][0], V[1][1], V[1][2];
      const Mat3 R = ws.E_wi[i].topLeftCorner<3, 3>();
      Vec6 phi_core_w;
      phi_core_w << R * ws.phi[i].head<3>(), R * ws.phi[i].tail<3>();
      EXPECT_TRUE(relClose(phi_core_w, phi_w, 1e-12)) << label(c, GetParam()) << " body " << i;
    }
    // the state round trip core -> Simbody -> core is exact to round-off
    State back;
    simbody::getCoreState(*sm, m, sb, back);
    EXPECT_TRUE(relClose(back.q, s.q, 1e-14));
    EXPECT_TRUE(relClose(back.qdot, s.qdot, 1e-12));
  }
}

TEST_P(Crosscheck, MassMatrixMatches) {
  for (const auto& c : kTrees) {
    const Model m = scenes::randomTree(c.n, c.seed, scenes::TreeJoints::SimbodyComparable);
    SimbodyBuildOptions opt;
    opt.spherical = GetParam();
    const auto sm = simbody::makeSimbodyModel(m, opt);
    std::mt19937 rng(100 + c.seed);
    for (int trial = 0; trial < 3; ++trial) {
      const State s = randomState(m, rng);
      SkeletonWorkspace ws(m);
      calcKinematics(m, s, ws);
      MatX M_r;
      calcSkeletonMass(m, ws, M_r);
      const MatX M_sb = simbody::calcSimbodyMassCore(*sm, m, s);
      EXPECT_TRUE(relClose(M_r, M_sb, kTol)) << label(c, GetParam());
      // and in Simbody's own u space: M_u = T^-T M_r T^-1
      SimTK::State sb = sm->default_state;
      simbody::setSimbodyState(*sm, m, s, sb);
      sm->system.realize(sb, SimTK::Stage::Position);
      SimTK::Matrix M_u;
      sm->matter.calcM(sb, M_u);
      MatX T;
      simbody::calcVelocityMap(*sm, m, s, T);
      const MatX Tinv = T.inverse();
      EXPECT_TRUE(relClose(MatX(Tinv.transpose() * M_r * Tinv), simbody::fromSimTK(M_u), kTol))
          << label(c, GetParam());
    }
  }
}

TEST_P(Crosscheck, InverseDynamicsMatches) {
  for (const auto& c : kTrees) {
    const Model m = scenes::randomTree(c.n, c.seed, scenes::TreeJoints::SimbodyComparable);
    SimbodyBuildOptions opt;
    opt.spherical = GetParam();
    const auto sm = simbody::makeSimbodyModel(m, opt);
    System sys(m);
    DynamicsWorkspace ws(m);
    std::mt19937 rng(200 + c.seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 3; ++trial) {
      const State s = randomState(m, rng);
      const VecX qddot = VecX::NullaryExpr(m.nr(), [&] { return 3.0 * u(rng); });
      const VecX tau_sb = simbody::calcSimbodyInverseDynamicsCore(*sm, m, s, qddot);
      const VecX tau_redmax = sys.inverseDynamics(s, qddot, ws);
      const VecX tau_rnea = inverseDynamicsRecursive(m, s, qddot);
      EXPECT_TRUE(relClose(tau_redmax, tau_sb, kTol)) << label(c, GetParam()) << " REDMAX route";
      EXPECT_TRUE(relClose(tau_rnea, tau_sb, kTol)) << label(c, GetParam()) << " recursive";
      // also in u space: f_u = T^-T tau, straight from calcResidualForceIgnoringConstraints
      SimTK::State sb = sm->default_state;
      simbody::setSimbodyState(*sm, m, s, sb);
      sm->system.realize(sb, SimTK::Stage::Dynamics);
      MatX T, Tdot;
      simbody::calcVelocityMap(*sm, m, s, T, &Tdot);
      SimTK::Vector f_u;
      sm->matter.calcResidualForceIgnoringConstraints(
          sb, sm->system.getMobilityForces(sb, SimTK::Stage::Dynamics),
          sm->system.getRigidBodyForces(sb, SimTK::Stage::Dynamics),
          simbody::toSimTK(T * qddot + Tdot * s.qdot), f_u);
      const VecX f_core_u = T.transpose().partialPivLu().solve(tau_redmax);
      EXPECT_TRUE(relClose(f_core_u, simbody::fromSimTK(f_u), kTol)) << label(c, GetParam());
    }
  }
}

TEST_P(Crosscheck, ForwardAccelerationsMatch) {
  for (const auto& c : kTrees) {
    const Model m = scenes::randomTree(c.n, c.seed, scenes::TreeJoints::SimbodyComparable);
    SimbodyBuildOptions opt;
    opt.spherical = GetParam();
    const auto sm = simbody::makeSimbodyModel(m, opt);
    System sys(m);
    DynamicsWorkspace ws(m);
    std::mt19937 rng(300 + c.seed);
    for (int trial = 0; trial < 3; ++trial) {
      const State s = randomState(m, rng);
      const VecX qddot = sys.forwardDynamics(s, ws);
      const VecX qddot_sb = simbody::calcSimbodyForwardDynamicsCore(*sm, m, s);
      EXPECT_TRUE(relClose(qddot, qddot_sb, kTol)) << label(c, GetParam());
      // u space: udot = T qddot + Tdot qdot
      SimTK::State sb = sm->default_state;
      simbody::setSimbodyState(*sm, m, s, sb);
      sm->system.realize(sb, SimTK::Stage::Acceleration);
      MatX T, Tdot;
      simbody::calcVelocityMap(*sm, m, s, T, &Tdot);
      EXPECT_TRUE(relClose(VecX(T * qddot + Tdot * s.qdot), simbody::fromSimTK(sm->matter.getUDot(sb)), kTol))
          << label(c, GetParam());
    }
  }
}

// the benchmark humanoid (free pelvis, ball/universal/pin joints, 37 DoF) agrees as well
TEST_P(Crosscheck, HumanoidMatches) {
  const Model m = scenes::humanoid();
  SimbodyBuildOptions opt;
  opt.spherical = GetParam();
  const auto sm = simbody::makeSimbodyModel(m, opt);
  System sys(m);
  DynamicsWorkspace ws(m);
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    State s = randomState(m, rng);
    s.q = m.defaultQ() + 0.5 * s.q;
    const VecX qddot = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
    sys.calcMassAndForce(s, ws);
    EXPECT_TRUE(relClose(ws.M, simbody::calcSimbodyMassCore(*sm, m, s), kTol));
    const VecX tau_sb = simbody::calcSimbodyInverseDynamicsCore(*sm, m, s, qddot);
    EXPECT_TRUE(relClose(sys.inverseDynamics(s, qddot, ws), tau_sb, kTol));
    EXPECT_TRUE(relClose(inverseDynamicsRecursive(m, s, qddot), tau_sb, kTol));
    EXPECT_TRUE(relClose(sys.forwardDynamics(s, ws), simbody::calcSimbodyForwardDynamicsCore(*sm, m, s), kTol));
  }
}

INSTANTIATE_TEST_SUITE_P(SphericalModes, Crosscheck, ::testing::Values(SphericalAs::Gimbal, SphericalAs::Ball),
                         [](const auto& info) {
                           return std::string(info.param == SphericalAs::Ball ? "Ball" : "Gimbal");
                         });

// joint springs and dampers in the core against Force::MobilityLinearSpring / MobilityLinearDamper
// (Gimbal mode: every coordinate then has u = qdot, which the Simbody elements need)
TEST(CrosscheckSprings, JointSpringsAndDampersMatch) {
  for (const auto& c : kTrees) {
    const Model base = scenes::randomTree(c.n, c.seed, scenes::TreeJoints::SimbodyComparable);
    ModelBuilder edit(base);
    std::mt19937 rng(400 + c.seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    // every coordinate whose Simbody u is its qdot: all but the rotations of Free mobilizers
    const auto plain = simbody::makeSimbodyModel(base, {});
    int springs = 0;
    for (const auto& mm : plain->map) {
      for (int k = 0; k < mm.nq; ++k) {
        if (mm.kind == simbody::MobilizerKind::Free && k < 3) continue;
        Coordinate& cd = edit.coordinateAt(mm.q_index + k);
        cd.stiffness = 50.0 * u(rng);
        cd.damping = 2.0 * u(rng);
        cd.rest_value = u(rng) - 0.5;
        ++springs;
      }
    }
    ASSERT_GT(springs, 2);
    const Model m = edit.finalize();
    const auto sm = simbody::makeSimbodyModel(m, {});
    System sys(m), sys_free(base);
    DynamicsWorkspace ws(m), ws_free(base);
    for (int trial = 0; trial < 3; ++trial) {
      const State s = randomState(m, rng);
      const VecX qddot = sys.forwardDynamics(s, ws);
      EXPECT_TRUE(relClose(qddot, simbody::calcSimbodyForwardDynamicsCore(*sm, m, s), kTol))
          << label(c, SphericalAs::Gimbal);
      const VecX tau = sys.inverseDynamics(s, qddot, ws);
      const VecX tau_sb = simbody::calcSimbodyInverseDynamicsCore(*sm, m, s, qddot);
      // at the forward-dynamics accelerations the residual is zero up to round-off: compare with
      // the size of the spring/damper forces instead of the (tiny) residual
      const VecX spring = sys_free.inverseDynamics(s, qddot, ws_free) - tau;
      ASSERT_GT(spring.norm(), 1.0);
      EXPECT_LE((tau - tau_sb).norm(), kTol * spring.norm()) << label(c, SphericalAs::Gimbal);
      // and with arbitrary accelerations, where the springs are a visible part of tau
      const VecX qdd2 = VecX::NullaryExpr(m.nr(), [&] { return 4.0 * u(rng) - 2.0; });
      EXPECT_TRUE(relClose(inverseDynamicsRecursive(m, s, qdd2),
                           simbody::calcSimbodyInverseDynamicsCore(*sm, m, s, qdd2), kTol));
    }
  }
}

TEST(CrosscheckSprings, SpringOnBallRotationIsRejected) {
  ModelBuilder b("ball_spring");
  const int i = b.addBody("b", 1.0, Vec3(0.1, 0.2, 0.0), Mat3::Identity() * 0.1, -1, "ball", SphericalEuler{});
  b.coordinate(i, 1).stiffness = 10.0;
  const Model m = b.finalize();
  SimbodyBuildOptions opt;
  opt.spherical = SphericalAs::Ball;
  EXPECT_THROW((void)simbody::makeSimbodyModel(m, opt), simbody::SimbodyBuildError);
  opt.spherical = SphericalAs::Gimbal;  // u = qdot: fine
  EXPECT_NO_THROW((void)simbody::makeSimbodyModel(m, opt));
}

// the random trees exercise every mobilizer the mapping supports
TEST(CrosscheckCoverage, TreesUseEveryMobilizer) {
  std::set<simbody::MobilizerKind> seen;
  for (SphericalAs mode : {SphericalAs::Gimbal, SphericalAs::Ball}) {
    for (const auto& c : kTrees) {
      const Model m = scenes::randomTree(c.n, c.seed, scenes::TreeJoints::SimbodyComparable);
      SimbodyBuildOptions opt;
      opt.spherical = mode;
      // keep the model alive for the loop: a temporary in the range expression dies before it
      const auto sb = simbody::makeSimbodyModel(m, opt);
      for (const auto& mm : sb->map) seen.insert(mm.kind);
    }
  }
  using K = simbody::MobilizerKind;
  for (K k : {K::Weld, K::Pin, K::Slider, K::Gimbal, K::Ball, K::Universal, K::Free})
    EXPECT_TRUE(seen.count(k)) << "mobilizer kind " << static_cast<int>(k) << " never used";
}

TEST(CrosscheckErrors, UnmappableJointIsNamed) {
  ModelBuilder b("exp");
  b.addBody("b", 1.0, Vec3::Zero(), Mat3::Identity() * 0.1, -1, "expjoint", SphericalExp{});
  const Model m = b.finalize();
  try {
    (void)simbody::makeSimbodyModel(m, {});
    FAIL() << "expected SimbodyBuildError";
  } catch (const simbody::SimbodyBuildError& e) {
    EXPECT_NE(std::string(e.what()).find("expjoint"), std::string::npos) << e.what();
  }
}

// the comparison can fail: a 1e-6 relative change of one body's mass is visible far above 1e-9
TEST(CrosscheckSensitivity, PerturbedMassIsDetected) {
  const Model m = scenes::randomTree(10, 3, scenes::TreeJoints::SimbodyComparable);
  ModelBuilder edit(m);
  const Body& last = m.bodies()[m.nb() - 1];
  edit.setBodyMassProperties(m.nb() - 1, last.mass * (1.0 + 1e-6), last.com, last.inertia_com);
  const Model m2 = edit.finalize();
  const auto sm = simbody::makeSimbodyModel(m2, {});
  std::mt19937 rng(9);
  const State s = randomState(m, rng);
  SkeletonWorkspace ws(m);
  calcKinematics(m, s, ws);
  MatX M_r;
  calcSkeletonMass(m, ws, M_r);
  const MatX M_sb = simbody::calcSimbodyMassCore(*sm, m, s);
  EXPECT_FALSE(relClose(M_r, M_sb, kTol));
  EXPECT_TRUE(relClose(M_r, M_sb, 1e-5));
}

TEST(CrosscheckErrors, BadStateSizeIsRejected) {
  const Model m = scenes::randomTree(5, 1, scenes::TreeJoints::SimbodyComparable);
  const auto sm = simbody::makeSimbodyModel(m, {});
  State s;
  s.q = VecX::Zero(m.nr() + 1);
  s.qdot = VecX::Zero(m.nr() + 1);
  SimTK::State sb = sm->default_state;
  EXPECT_THROW(simbody::setSimbodyState(*sm, m, s, sb), std::invalid_argument);
}

TEST(CrosscheckErrors, InvalidInertiaIsReportedByBody) {
  ModelBuilder b("bad");
  Mat3 I = Mat3::Zero();
  I.diagonal() << 1.0, 1.0, 5.0;  // violates the triangle inequality
  b.addBody("wobbly", 1.0, Vec3::Zero(), I, -1, "pin", Revolute{Vec3::UnitZ()});
  const Model m = b.finalize();
  try {
    (void)simbody::makeSimbodyModel(m, {});
    FAIL() << "expected SimbodyBuildError";
  } catch (const simbody::SimbodyBuildError& e) {
    EXPECT_NE(std::string(e.what()).find("wobbly"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace redmax
