// Prescribed points: maximal-coordinate inverse dynamics [D Sec. 4.6.5, Eq. 4.109-4.110]. The
// constraint's G and rhs against differences, and its multipliers (the world force the
// prescription applies at the point) against inverse dynamics in analytic cases.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "constraint_scenes.hpp"
#include "core/dynamics/constraints/prescribed_point.hpp"
#include "core/dynamics/system.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "validation/scenes/deformable_scenes.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using testing::evalConstraint;

// a point on a tilted ellipse plus a drift along z, with exact derivatives
PointSample ellipse(double t) {
  PointSample p;
  const double w = 1.7;
  p.x = Vec3(0.3 * std::cos(w * t), 0.2 * std::sin(w * t) + 0.1 * t, 0.05 * t * t);
  p.v = Vec3(-0.3 * w * std::sin(w * t), 0.2 * w * std::cos(w * t) + 0.1, 0.1 * t);
  p.a = Vec3(-0.3 * w * w * std::cos(w * t), -0.2 * w * w * std::sin(w * t), 0.1);
  return p;
}

class PrescribedPointFd : public ::testing::TestWithParam<int> {};

TEST_P(PrescribedPointFd, JacobianAndRhsMatchDifferences) {
  const Model m = scenes::randomTree(8, 1700 + GetParam());
  std::mt19937 rng(GetParam());
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.t = 0.37 + GetParam();
  s.q = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  s.qdot = VecX::NullaryExpr(m.nr(), [&] { return 2.0 * u(rng); });
  const VecX a = VecX::NullaryExpr(m.nr(), [&] { return 2.0 * u(rng); });
  for (int body : {m.nb() - 1, 2}) {
    const PrescribedPoint c(m, body, Vec3(0.2, -0.1, 0.3), ellipse);
    SCOPED_TRACE(body);
    const auto e = evalConstraint(c, m, s);
    // G = dC/dq (central differences of the point position), vel_err = dC/dt along (qdot, t)
    EXPECT_TRUE(nearRel(e.G, testing::fdPositionJacobian(c, m, s), 1e-6));
    EXPECT_TRUE(nearRel(e.vel_err, testing::fdPositionRate(c, m, s), 1e-6));
    // vel_err = xdot_p - G... : with G = -J, vel_err = xdot_p(t) + G qdot
    EXPECT_TRUE(nearRel(e.vel_err, ellipse(s.t).v + e.G * s.qdot, 1e-12));
    // rhs = -Gdot qdot - xddot_p(t): Gdot qdot = d/dt(G) qdot from differences of G along qdot
    EXPECT_TRUE(nearRel(e.rhs, -testing::fdGdotQdot(c, m, s) - ellipse(s.t).a, 1e-6));
    // and the acceleration row is exact: d/dt vel_err = G a - rhs for any a
    EXPECT_TRUE(nearRel(testing::fdVelocityRate(c, m, s, a), e.G * a - e.rhs, 1e-6));
  }
}

INSTANTIATE_TEST_SUITE_P(Seeds, PrescribedPointFd, ::testing::Range(0, 3),
                         [](const ::testing::TestParamInfo<int>& i) { return "seed" + std::to_string(i.param); });

// theta(t) = 0.5 sin(2 t) + 0.2 and its derivatives
struct Swing {
  double th(double t) const { return 0.5 * std::sin(2 * t) + 0.2; }
  double thd(double t) const { return std::cos(2 * t); }
  double thdd(double t) const { return -2.0 * std::sin(2 * t); }
};

TEST(PrescribedPoint, PendulumTipOnACircleTakesTheInverseDynamicsForce) {
  // singlePendulum: a 1 m, 1 kg rod hinged about z at the origin, hanging along -y. Its tip
  // (0, -1, 0) driven on the circle x_p = (sin th, -cos th, 0): reachable, so of the three rows
  // only the tangential one is independent and the KKT solve gives the minimum-norm multiplier,
  // the tangential force F t with F L = tau_ID = (m L^2 / 3) thdd + m g (L/2) sin th.
  const Model m = scenes::singlePendulum();
  const Swing sw;
  const double L = 1.0, mass = 1.0, g = 9.81;
  System sys(m);
  sys.addConstraint(std::make_shared<PrescribedPoint>(m, 0, Vec3(0, -L, 0), [&](double t) {
    const double th = sw.th(t), w = sw.thd(t), al = sw.thdd(t);
    PointSample p;
    p.x = L * Vec3(std::sin(th), -std::cos(th), 0);
    p.v = L * w * Vec3(std::cos(th), std::sin(th), 0);
    p.a = L * al * Vec3(std::cos(th), std::sin(th), 0) + L * w * w * Vec3(-std::sin(th), std::cos(th), 0);
    return p;
  }));
  System plain(m);
  DynamicsWorkspace ws(sys), ws_id(plain);
  for (double t : {0.1, 0.9, 2.3}) {
    State s = sys.defaultState();
    s.t = t;
    s.q[0] = sw.th(t);
    s.qdot[0] = sw.thd(t);
    const VecX qdd = sys.forwardDynamics(s, ws);
    EXPECT_NEAR(qdd[0], sw.thdd(t), 1e-12);
    const double tau_analytic = mass * L * L / 3 * sw.thdd(t) + mass * g * L / 2 * std::sin(sw.th(t));
    const VecX tau_id = plain.inverseDynamics(s, VecX::Constant(1, sw.thdd(t)), ws_id);
    EXPECT_NEAR(tau_id[0], tau_analytic, 1e-12);
    // the generalized force of the prescription, J^T lambda, is the ID torque
    EXPECT_NEAR(sys.prescribedForces(ws)[0], tau_id[0], 1e-12);
    // and lambda itself the tangential force tau / L
    const Vec3 tangent(std::cos(sw.th(t)), std::sin(sw.th(t)), 0);
    EXPECT_LE((ws.lambda - tau_analytic / L * tangent).norm(), 1e-12) << ws.lambda.transpose();
  }
}

TEST(PrescribedPoint, TranslatingBodyTakesMassTimesAccelerationMinusWeight) {
  // A 2 kg body on a free translation, its point (0.1, 0.2, -0.3) prescribed on the ellipse: three
  // independent rows, lambda = m (xddot_p - g) exactly, with the body's rotation fixed.
  ModelBuilder b("slider");
  const Vec3 grav(0, -9.81, 0);
  b.setGravity(grav);
  const double mass = 2.0;
  b.addBody("block", mass, Vec3(0.05, 0, 0), Mat3::Identity() * 0.01, -1, "slide", Translational{});
  const Model m = b.finalize();
  const Vec3 r(0.1, 0.2, -0.3);
  System sys(m);
  sys.addConstraint(std::make_shared<PrescribedPoint>(m, 0, r, ellipse));
  DynamicsWorkspace ws(sys);
  for (double t : {0.0, 0.6, 1.4}) {
    State s = sys.defaultState();
    s.t = t;
    s.q = ellipse(t).x - r;
    s.qdot = ellipse(t).v;
    const VecX qdd = sys.forwardDynamics(s, ws);
    EXPECT_LE((qdd - ellipse(t).a).norm(), 1e-12);
    EXPECT_LE((ws.lambda - mass * (ellipse(t).a - grav)).norm(), 1e-12) << ws.lambda.transpose();
  }
}

TEST(PrescribedPoint, BaumgarteKeepsADoublePendulumTipOnItsPath) {
  // the tip of a bent double pendulum (q = 0.3, 0.8) driven on a 5 cm circle in its plane: two
  // independent rows (the z row is zero and consistent) fix both joints; RK4 on the KKT
  // accelerations (tests/core/dynamics/constraint_scenes.hpp)
  const Model m = scenes::doublePendulum();
  std::vector<Mat4> E;
  const VecX q0 = Vec2(0.3, 0.8);
  calcBodyPoses(m, q0, E);
  const Vec3 tip_local(0, -1, 0);
  const Vec3 x0 = transformPoint(E[1], tip_local);
  const double r = 0.05, w = 3.0;
  auto path = [=](double t) {
    PointSample p;
    const double c = std::cos(w * t), s = std::sin(w * t);
    p.x = x0 + r * Vec3(c - 1, s, 0);
    p.v = r * w * Vec3(-s, c, 0);
    p.a = -r * w * w * Vec3(c, s, 0);
    return p;
  };
  auto track = [&](double alpha, double h, int steps) {
    System sys(m);
    sys.addConstraint(std::make_shared<PrescribedPoint>(m, 1, tip_local, path));
    sys.stabilization.alpha = sys.stabilization.beta = alpha;
    DynamicsWorkspace ws(sys);
    State s = sys.defaultState();
    s.q = q0;
    sys.projectVelocities(s, ws);
    double err = 0;
    for (int k = 0; k < steps; ++k) {
      testing::rk4Step(sys, s, h, ws);
      sys.calcMassAndForce(s, ws);
      sys.calcConstraints(s, ws);
      err = std::max(err, ws.pos_err.norm());
    }
    return err;
  };
  // 10 s of RK4: without stabilisation the error is the integrator's, growing with time and as
  // h^4; the System's Baumgarte terms (alpha = beta = 2 /s) pull it back (measured 3.10e-8 m
  // plain, 4.94e-10 m stabilised at h = 1e-2 s; 4.96e-7 m plain at 2e-2 s)
  const double plain = track(0.0, 1e-2, 1000), plain2 = track(0.0, 2e-2, 500), stabilised = track(2.0, 1e-2, 1000);
  std::printf("double pendulum tip on a circle, rk4 10 s: largest error %.3e m (h 1e-2), %.3e m (h 2e-2), %.3e m "
              "with Baumgarte 2/s (h 1e-2)\n", plain, plain2, stabilised);
  EXPECT_NEAR(plain2 / plain, 16.0, 1.0);
  EXPECT_NEAR(plain, 3.10e-8, 0.05e-8);
  EXPECT_NEAR(stabilised, 4.94e-10, 0.05e-10);
}

TEST(PrescribedPoint, RejectsBadInput) {
  const Model m = scenes::singlePendulum();
  EXPECT_THROW(PrescribedPoint(m, 1, Vec3::Zero(), ellipse), ModelError);
  EXPECT_THROW(PrescribedPoint(m, -1, Vec3::Zero(), ellipse), ModelError);
  EXPECT_THROW(PrescribedPoint(m, 0, Vec3(NAN, 0, 0), ellipse), ModelError);
  EXPECT_THROW(PrescribedPoint(m, 0, Vec3::Zero(), PointTrajectory{}), ModelError);
}

}  // namespace
}  // namespace redmax
