// Bilateral constraints [D Sec. 4.6.4]: finite-difference checks of every constraint type, the
// four-bar loop closure (point and hinge-point versions) in simulation, redundant rows in the
// KKT solve, and a weld holding two floating bodies together while they fall and spin.
#include <gtest/gtest.h>

#include <random>

#include "constraint_scenes.hpp"
#include "core/dynamics/constraints/coordinate_coupler.hpp"
#include "core/dynamics/constraints/point_constraint.hpp"
#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/constraints/weld_constraint.hpp"
#include "core/integrators/integrator.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using testing::evalConstraint;
using testing::FourBar;

State randomState(int n, std::mt19937& rng, double t = 0.37) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.t = t;
  s.q = VecX::NullaryExpr(n, [&] { return u(rng); });
  s.qdot = VecX::NullaryExpr(n, [&] { return 2.0 * u(rng); });
  return s;
}

// f(x0, x1) = sin(x0) x1 + 0.3 x0^2 with exact derivatives
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

// q_p(t) = 0.4 sin(2 t + 0.3) + 0.1
ConstraintFunctionPtr sinusoid() {
  return makeConstraintFunction1([](double t) { return 0.4 * std::sin(2 * t + 0.3) + 0.1; },
                                 [](double t) { return 0.8 * std::cos(2 * t + 0.3); },
                                 [](double t) { return -1.6 * std::sin(2 * t + 0.3); });
}

// FD tolerance for h = 1e-6 central differences (truncation ~1e-12, round-off ~1e-10)
constexpr double kFdTol = 1e-6;

void expectDerivativesMatch(const Constraint& c, const Model& m, const State& s, const VecX& a,
                            bool check_position_jacobian) {
  SCOPED_TRACE(c.name());
  const auto e = evalConstraint(c, m, s);
  if (check_position_jacobian) {
    // G = dC/dq and vel_err = dC/dt along (qdot, t)
    EXPECT_TRUE(nearRel(e.G, testing::fdPositionJacobian(c, m, s), kFdTol))
        << "G\n" << e.G << "\nfd\n" << testing::fdPositionJacobian(c, m, s);
    EXPECT_TRUE(nearRel(e.vel_err, testing::fdPositionRate(c, m, s), kFdTol));
  }
  // d/dt vel_err = G qddot - rhs for any qddot: the acceleration-level row is exact
  EXPECT_TRUE(nearRel(testing::fdVelocityRate(c, m, s, a), e.G * a - e.rhs, kFdTol));
  if (!c.isPrescribed()) {
    // time-independent: rhs = -Gdot qdot with Gdot from differencing G along qdot, vel_err = G qdot
    EXPECT_TRUE(nearRel(e.rhs, -testing::fdGdotQdot(c, m, s), kFdTol));
    EXPECT_TRUE(nearRel(e.vel_err, e.G * s.qdot, 1e-12));
  }
}

class ConstraintFd : public ::testing::TestWithParam<int> {};

TEST_P(ConstraintFd, EveryTypeMatchesFiniteDifferences) {
  const Model m = scenes::randomTree(8, 900 + GetParam());
  std::mt19937 rng(GetParam());
  const State s = randomState(m.nr(), rng);
  const VecX a = randomState(m.nr(), rng).qdot;
  ASSERT_GE(m.nr(), 3);
  std::vector<std::shared_ptr<Constraint>> cs;
  cs.push_back(std::make_shared<PointConstraint>(m, 6, Vec3(0.2, -0.1, 0.3), 3, Vec3(-0.3, 0.1, 0.05)));
  cs.push_back(std::make_shared<PointConstraint>(m, -1, Vec3(0.5, 0.2, -0.1), 7, Vec3(0.1, 0.4, 0.0)));
  cs.push_back(std::make_shared<HingePointConstraint>(m, 5, Vec3(0.1, 0.2, 0.3), 2, Vec3(0.0, -0.2, 0.1), -1,
                                                      Vec3(0.2, 0.3, 1.0)));
  cs.push_back(std::make_shared<HingePointConstraint>(m, 7, Vec3(0.1, 0.2, 0.3), -1, Vec3(0.0, -0.2, 0.1), 4,
                                                      Vec3(1.0, -0.5, 0.2)));
  cs.push_back(std::make_shared<CoordinateCoupler>(m, 1, std::vector<int>{m.nr() - 1, 0}, nonlinear2(), 1.3));
  cs.push_back(std::make_shared<PrescribedCoordinate>(m, 2, sinusoid()));
  for (const auto& c : cs) expectDerivativesMatch(*c, m, s, a, true);
}

TEST_P(ConstraintFd, WeldMatchesFiniteDifferences) {
  const Model m = scenes::randomTree(8, 950 + GetParam());
  std::mt19937 rng(100 + GetParam());
  const State s = randomState(m.nr(), rng);
  const VecX a = randomState(m.nr(), rng).qdot;
  // frames chosen so that the weld holds at s.q: E_bg = E_wb^-1 E_wa E_af
  std::vector<Mat4> E;
  calcBodyPoses(m, s.q, E);
  const Mat4 E_af = makeE(expSO3(Vec3(0.3, -0.7, 0.5)), Vec3(0.2, 0.1, -0.3));
  const int A = 6, B = 2;
  const Mat4 E_bg = inverseE(E[B]) * E[A] * E_af;
  const WeldConstraint weld(m, A, E_af, B, E_bg);
  EXPECT_LE(evalConstraint(weld, m, s).pos_err.norm(), 1e-12);
  // at the satisfied configuration G = dC/dq and vel_err = dC/dt hold exactly
  expectDerivativesMatch(weld, m, s, a, true);
  // and the acceleration rows are exact anywhere
  const State s2 = randomState(m.nr(), rng);
  expectDerivativesMatch(weld, m, s2, a, false);
  // welding to the world
  const WeldConstraint to_world(m, A, E_af, -1, E[A] * E_af);
  expectDerivativesMatch(to_world, m, s, a, true);
}

INSTANTIATE_TEST_SUITE_P(Seeds, ConstraintFd, ::testing::Range(0, 4),
                         [](const ::testing::TestParamInfo<int>& i) { return "seed" + std::to_string(i.param); });

TEST(FourBar, ClosedConfigurationSatisfiesBothVersions) {
  const FourBar fb;
  const PointConstraint pc(fb.model, fb.rocker_body, fb.tip_rocker(), -1, fb.pivot_world());
  const HingePointConstraint hc(fb.model, fb.rocker_body, fb.tip_rocker(), -1, fb.pivot_world(), -1, Vec3::UnitZ());
  for (double q1 : {0.0, 0.7, 2.0, -1.3}) {
    State s;
    s.q = fb.closedQ(q1);
    s.qdot = fb.closedQdot(s.q, 1.7);
    for (const Constraint* c : {static_cast<const Constraint*>(&pc), static_cast<const Constraint*>(&hc)}) {
      const auto e = evalConstraint(*c, fb.model, s);
      EXPECT_LE(e.pos_err.norm(), 1e-12) << c->name();
      EXPECT_LE(e.vel_err.norm(), 1e-12) << c->name();
    }
  }
}

TEST(FourBar, RedundantPointRowsGiveTheHingeAccelerations) {
  // The 3-row point constraint closing a planar loop has an all-zero z row, so G M^-1 G^T is
  // singular; solveKKT's complete orthogonal decomposition must give the same accelerations as
  // the 2-row hinge version [D Eq. 4.97-4.98] and satisfy the constraint.
  const FourBar fb;
  System s3(fb.model), s2(fb.model);
  s3.addConstraint(std::make_shared<PointConstraint>(fb.model, fb.rocker_body, fb.tip_rocker(), -1, fb.pivot_world()));
  s2.addConstraint(std::make_shared<HingePointConstraint>(fb.model, fb.rocker_body, fb.tip_rocker(), -1,
                                                          fb.pivot_world(), -1, Vec3::UnitZ()));
  DynamicsWorkspace w3(fb.model), w2(fb.model);
  for (double q1 : {0.3, 1.9, -2.5}) {
    State s;
    s.q = fb.closedQ(q1);
    s.qdot = fb.closedQdot(s.q, -2.1);
    const VecX a3 = s3.forwardDynamics(s, w3);
    const VecX a2 = s2.forwardDynamics(s, w2);
    ASSERT_TRUE(a3.allFinite());
    ASSERT_TRUE(w3.lambda.allFinite());
    EXPECT_TRUE(nearRel(a3, a2, 1e-10)) << a3.transpose() << " vs " << a2.transpose();
    EXPECT_LE((w3.G * a3 - w3.rhs).norm(), 1e-10 * (1 + w3.rhs.norm()));
    // equations of motion with the multipliers: M qddot + G^T lambda = f
    EXPECT_LE((w3.M * a3 + w3.G.transpose() * w3.lambda - w3.f).norm(), 1e-10 * (1 + w3.f.norm()));
    // the redundant row carries no force (minimum-norm multiplier)
    EXPECT_LE(std::abs(w3.lambda[2]), 1e-10 * (1 + w3.lambda.norm()));
  }
}

TEST(Kkt, DuplicatedRowsSplitTheMultiplier) {
  const Model m = scenes::randomTree(6, 77);
  const auto c = std::make_shared<CoordinateCoupler>(m, 1, std::vector<int>{0, 2}, nonlinear2(), 0.8);
  System one(m), two(m);
  one.addConstraint(c);
  two.addConstraint(c);
  two.addConstraint(c);
  std::mt19937 rng(5);
  const State s = randomState(m.nr(), rng);
  DynamicsWorkspace w1(m), w2(m);
  const VecX a1 = one.forwardDynamics(s, w1);
  const VecX a2 = two.forwardDynamics(s, w2);
  EXPECT_TRUE(nearRel(a2, a1, 1e-10));
  ASSERT_EQ(w2.lambda.size(), 2);
  EXPECT_NEAR(w2.lambda[0], 0.5 * w1.lambda[0], 1e-9 * (1 + std::abs(w1.lambda[0])));
  EXPECT_NEAR(w2.lambda[1], 0.5 * w1.lambda[0], 1e-9 * (1 + std::abs(w1.lambda[0])));
}

TEST(Kkt, SingularMassFallsBackToTheFullSystem) {
  // M = diag(2, 0): the second coordinate is massless but fixed by the constraint x1 = x0 + ...
  MatX M = MatX::Zero(2, 2);
  M(0, 0) = 2.0;
  MatX G(1, 2);
  G << -1.0, 1.0;
  VecX a(2), b(1);
  a << 4.0, 1.0;
  b << 0.5;
  VecX lambda;
  const VecX x = System::solveKKT(M, G, a, b, &lambda);
  // rows: 2 x0 - l = 4, l = 1, -x0 + x1 = 0.5
  ASSERT_EQ(lambda.size(), 1);
  EXPECT_NEAR(lambda[0], 1.0, 1e-12);
  EXPECT_NEAR(x[0], 2.5, 1e-12);
  EXPECT_NEAR(x[1], 3.0, 1e-12);
}

// Simulates the four-bar with the library's semi-implicit Euler (velocity-level constraints)
// plus a position and velocity projection after every step; returns the largest position
// error after projection and fills the largest drift before it.
struct FourBarRun {
  double max_err_after = 0.0, max_drift_before = 0.0, energy_drift = 0.0, max_kinetic = 0.0;
  std::vector<VecX> q;
};
FourBarRun runFourBar(const std::shared_ptr<const Constraint>& c, const FourBar& fb, double duration, double dt) {
  System sys(fb.model);
  sys.addConstraint(c);
  auto euler = makeIntegrator("euler", IntegratorOptions{.dt = dt});
  DynamicsWorkspace ws(fb.model);
  State s;
  s.q = fb.closedQ(0.4);
  s.qdot = fb.closedQdot(s.q, 0.0);
  const double E0 = sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
  FourBarRun r;
  const long n = std::lround(duration / dt);
  for (long k = 0; k < n; ++k) {
    euler->advance(sys, s, s.t + dt);
    sys.calcMassAndForce(s, ws);
    sys.calcConstraints(s, ws);
    r.max_drift_before = std::max(r.max_drift_before, ws.pos_err.lpNorm<Eigen::Infinity>());
    r.max_err_after = std::max(r.max_err_after, sys.projectPositions(s, ws, 1e-13));
    sys.projectVelocities(s, ws);
    const double T = sys.kineticEnergy(s, ws);
    const double E = T + sys.potentialEnergy(s, ws);
    r.max_kinetic = std::max(r.max_kinetic, T);
    r.energy_drift = std::max(r.energy_drift, std::abs(E - E0));
    r.q.push_back(s.q);
  }
  return r;
}

TEST(FourBar, EulerWithProjectionKeepsTheLoopClosed) {
  const FourBar fb;
  const auto point = std::make_shared<PointConstraint>(fb.model, fb.rocker_body, fb.tip_rocker(), -1, fb.pivot_world());
  const auto hinge = std::make_shared<HingePointConstraint>(fb.model, fb.rocker_body, fb.tip_rocker(), -1,
                                                            fb.pivot_world(), -1, Vec3::UnitZ());
  const FourBarRun r3 = runFourBar(point, fb, 5.0, 1e-3);
  const FourBarRun r2 = runFourBar(hinge, fb, 5.0, 1e-3);
  EXPECT_LE(r3.max_err_after, 1e-8);
  EXPECT_LE(r2.max_err_after, 1e-8);
  // the per-step drift that the projection removes is small but real (O(h^2))
  EXPECT_GT(r2.max_drift_before, 0.0);
  EXPECT_LE(r2.max_drift_before, 1e-3);
  // the mechanism moved through a good part of its cycle, and both versions agree
  double swing = 0;
  for (const VecX& q : r2.q) swing = std::max(swing, std::abs(q[0] - r2.q.front()[0]));
  EXPECT_GT(swing, 0.5);
  double diff = 0;
  for (size_t k = 0; k < r2.q.size(); ++k) diff = std::max(diff, (r3.q[k] - r2.q[k]).norm());
  EXPECT_LE(diff, 1e-8);
  // symplectic Euler with projection: bounded energy error, O(h): below 1% of the motion's
  // largest kinetic energy
  EXPECT_GT(r2.max_kinetic, 1.0);
  EXPECT_LE(r2.energy_drift, 1e-2 * r2.max_kinetic);
  std::printf("four-bar euler h=1e-3, 5 s: max |C| after projection %.2e (point) %.2e (hinge), drift per step "
              "%.2e, 3-row vs 2-row %.2e, energy error %.2e J (max kinetic %.2f J)\n",
              r3.max_err_after, r2.max_err_after, r2.max_drift_before, diff, r2.energy_drift, r2.max_kinetic);
}

TEST(FourBar, Rk4WithBaumgarteStaysClosedWithoutProjection) {
  const FourBar fb;
  System sys(fb.model);
  sys.addConstraint(std::make_shared<HingePointConstraint>(fb.model, fb.rocker_body, fb.tip_rocker(), -1,
                                                           fb.pivot_world(), -1, Vec3::UnitZ()));
  sys.stabilization.alpha = 20.0;
  sys.stabilization.beta = 20.0;
  DynamicsWorkspace ws(fb.model);
  State s;
  s.q = fb.closedQ(0.4);
  s.qdot = fb.closedQdot(s.q, 0.0);
  const double E0 = sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
  double max_err = 0, max_dE = 0;
  for (int k = 0; k < 5000; ++k) {
    testing::rk4Step(sys, s, 1e-3, ws);
    sys.calcMassAndForce(s, ws);
    sys.calcConstraints(s, ws);
    max_err = std::max(max_err, ws.pos_err.lpNorm<Eigen::Infinity>());
    max_dE = std::max(max_dE, std::abs(sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws) - E0));
  }
  EXPECT_LE(max_err, 1e-8);
  EXPECT_LE(max_dE, 1e-6);
  std::printf("four-bar rk4 h=1e-3 + Baumgarte(20, 20), 5 s: max |C| %.2e, energy error %.2e J\n", max_err, max_dE);
}

TEST(FourBar, ProjectionFindsTheLoopFromAnOpenGuess) {
  const FourBar fb;
  System sys(fb.model);
  sys.addConstraint(std::make_shared<PointConstraint>(fb.model, fb.rocker_body, fb.tip_rocker(), -1, fb.pivot_world()));
  DynamicsWorkspace ws(fb.model);
  State s;
  s.q = fb.closedQ(0.9) + Vec3(0.0, 0.05, -0.04);
  s.qdot = VecX::Zero(3);
  EXPECT_LE(sys.projectPositions(s, ws, 1e-13, 20), 1e-13);
}

TEST(Weld, HoldsTwoFloatingBodiesTogetherWhileFalling) {
  ModelBuilder b("welded_pair");
  b.setGravity(Vec3(0, -9.81, 0));
  const int A = testing::addFloatingBody(b, "a", 2.0, Vec3(0.1, 0.0, 0.05),
                                         Vec3(0.02, 0.03, 0.04).asDiagonal());
  const int B = testing::addFloatingBody(b, "b", 1.0, Vec3(0.0, 0.2, 0.0),
                                         Vec3(0.05, 0.01, 0.03).asDiagonal());
  const Model m = b.finalize();
  ASSERT_EQ(m.nr(), 12);
  const Mat4 E_af = makeE(rotationAxisAngle(Vec3(1, 1, 0).normalized(), 0.4), Vec3(0.3, 0.1, -0.2));
  const Mat4 E_bg = makeE(rotationAxisAngle(Vec3(0, 0, 1), -0.3), Vec3(-0.1, 0.2, 0.05));

  // consistent start: A at a generic pose, B where the weld puts it; velocities: A spins and
  // moves, B follows after a velocity projection
  State s0;
  s0.q = VecX::Zero(12);
  s0.q.head(6) << 0.1, 1.0, -0.2, 0.2, -0.3, 0.4;
  std::vector<Mat4> E;
  calcBodyPoses(m, s0.q, E);
  s0.q.tail(6) = testing::floatingCoordinates(E[A] * E_af * inverseE(E_bg));
  s0.qdot = VecX::Zero(12);
  s0.qdot.head(6) << 0.5, 2.0, 0.0, 0.8, -0.6, 1.0;

  auto makeSystem = [&] {
    System sys(m);
    sys.addConstraint(std::make_shared<WeldConstraint>(m, A, E_af, B, E_bg));
    return sys;
  };
  auto comOf = [&](const State& s) {
    std::vector<Mat4> Ew;
    calcBodyPoses(m, s.q, Ew);
    return Vec3((2.0 * transformPoint(Ew[A], m.bodies()[A].com) + 1.0 * transformPoint(Ew[B], m.bodies()[B].com)) / 3.0);
  };

  System sys = makeSystem();
  DynamicsWorkspace ws(m);
  {
    sys.calcMassAndForce(s0, ws);
    sys.calcConstraints(s0, ws);
    ASSERT_LE(ws.pos_err.norm(), 1e-12);
  }
  EXPECT_LE(sys.projectVelocities(s0, ws), 1e-12);
  // the centre of mass of the pair must fall freely: c(t) = c0 + v0 t + g t^2 / 2
  const double h = 1e-4;
  const Vec3 c0 = comOf(s0);
  State sp = s0, sm = s0;
  sp.q += h * s0.qdot;
  sm.q -= h * s0.qdot;
  const Vec3 v0 = (comOf(sp) - comOf(sm)) / (2 * h);
  const Vec3 g(0, -9.81, 0);

  // (1) RK4 on the KKT accelerations with Baumgarte stabilisation: exact free fall
  {
    sys.stabilization.alpha = sys.stabilization.beta = 20.0;
    State s = s0;
    double max_err = 0, max_com = 0;
    for (int k = 0; k < 1000; ++k) {
      testing::rk4Step(sys, s, 1e-3, ws);
      sys.calcMassAndForce(s, ws);
      sys.calcConstraints(s, ws);
      max_err = std::max(max_err, ws.pos_err.lpNorm<Eigen::Infinity>());
      max_com = std::max(max_com, (comOf(s) - (c0 + v0 * s.t + 0.5 * g * s.t * s.t)).norm());
    }
    EXPECT_LE(max_err, 1e-8);
    EXPECT_LE(max_com, 1e-7);
    std::printf("weld rk4 1 s: max weld error %.2e, centre of mass vs free fall %.2e m\n", max_err, max_com);
    sys.stabilization = {};
  }
  // (2) the library's Euler with projection: weld exact, free fall to O(h)
  {
    auto euler = makeIntegrator("euler", IntegratorOptions{.dt = 1e-3});
    State s = s0;
    double max_err = 0, max_com = 0;
    for (int k = 0; k < 1000; ++k) {
      euler->advance(sys, s, s.t + 1e-3);
      max_err = std::max(max_err, sys.projectPositions(s, ws, 1e-13));
      sys.projectVelocities(s, ws);
      max_com = std::max(max_com, (comOf(s) - (c0 + v0 * s.t + 0.5 * g * s.t * s.t)).norm());
    }
    EXPECT_LE(max_err, 1e-8);
    EXPECT_LE(max_com, 2e-2);
    // the pair actually fell
    EXPECT_LT(comOf(s).y(), c0.y() - 3.0);
    std::printf("weld euler 1 s: max weld error %.2e, centre of mass vs free fall %.2e m\n", max_err, max_com);
  }
}

TEST(BadInput, ConstructorsRejectWhatCannotWork) {
  const FourBar fb;
  const Model& m = fb.model;
  EXPECT_THROW(PointConstraint(m, 5, Vec3::Zero(), -1, Vec3::Zero()), ModelError);
  EXPECT_THROW(PointConstraint(m, -2, Vec3::Zero(), 0, Vec3::Zero()), ModelError);
  EXPECT_THROW(PointConstraint(m, 1, Vec3::Zero(), 1, Vec3::Zero()), ModelError);
  EXPECT_THROW(PointConstraint(m, 1, Vec3(NAN, 0, 0), 0, Vec3::Zero()), ModelError);
  EXPECT_THROW(HingePointConstraint(m, 2, Vec3::Zero(), -1, Vec3::Zero(), -1, Vec3::Zero()), ModelError);
  EXPECT_THROW(HingePointConstraint(m, 2, Vec3::Zero(), -1, Vec3::Zero(), 3, Vec3::UnitZ()), ModelError);
  Mat4 sheared = Mat4::Identity();
  sheared(0, 1) = 0.3;
  EXPECT_THROW(WeldConstraint(m, 0, sheared, 1, Mat4::Identity()), ModelError);
  EXPECT_THROW(WeldConstraint(m, 0, Mat4::Identity(), 0, Mat4::Identity()), ModelError);
  EXPECT_THROW(CoordinateCoupler(m, 1, {0}, nonlinear2()), ModelError);           // 2-argument f, 1 coordinate
  EXPECT_THROW(CoordinateCoupler(m, 1, {1, 0}, nonlinear2()), ModelError);        // dependent among independents
  EXPECT_THROW(CoordinateCoupler(m, 3, {0, 1}, nonlinear2()), ModelError);        // out of range
  EXPECT_THROW(CoordinateCoupler(m, 2, {0, 0}, nonlinear2()), ModelError);        // repeated
  EXPECT_THROW(CoordinateCoupler(m, 2, {0, 1}, nullptr), ModelError);
  EXPECT_THROW(PrescribedCoordinate(m, 3, sinusoid()), ModelError);
  EXPECT_THROW(PrescribedCoordinate(m, 0, nonlinear2()), ModelError);             // not a function of time
  EXPECT_THROW(PrescribedCoordinate::makeLocked(m, -1, 0.0), ModelError);
  EXPECT_THROW(makeConstraintFunction(0, nullptr, nullptr, nullptr), std::invalid_argument);
  System sys(m);
  EXPECT_THROW(sys.addConstraint(nullptr), ModelError);
  // a constraint built for another model is refused at evaluation, not read out of bounds
  const Model other = scenes::randomTree(6, 3);
  sys.addConstraint(std::make_shared<PointConstraint>(other, 5, Vec3::Zero(), -1, Vec3::Zero()));
  DynamicsWorkspace ws(m);
  EXPECT_THROW(sys.forwardDynamics(sys.defaultState(), ws), ModelError);
}

}  // namespace
}  // namespace redmax
