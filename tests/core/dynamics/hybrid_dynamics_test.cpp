// Hybrid dynamics [D Sec. 4.6.5, Eq. 4.109-4.110]: prescribed and locked coordinates. With every
// coordinate prescribed the multipliers are the inverse-dynamics torques; with some prescribed,
// the free coordinates accelerate as forward dynamics under the computed torques.
#include <gtest/gtest.h>

#include <random>

#include "constraint_scenes.hpp"
#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/integrators/integrator.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

/// q(t) = a sin(w t + p) + b with its derivatives
struct Sine {
  double a, w, p, b;
  double q(double t) const { return a * std::sin(w * t + p) + b; }
  double qd(double t) const { return a * w * std::cos(w * t + p); }
  double qdd(double t) const { return -a * w * w * std::sin(w * t + p); }
  ConstraintFunctionPtr function() const {
    const Sine s = *this;
    return makeConstraintFunction1([s](double t) { return s.q(t); }, [s](double t) { return s.qd(t); },
                                   [s](double t) { return s.qdd(t); });
  }
};

std::vector<Sine> randomSines(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Sine> v;
  for (int k = 0; k < n; ++k) v.push_back({0.8 * u(rng), 1.0 + 2.0 * std::abs(u(rng)), 3.0 * u(rng), 0.3 * u(rng)});
  return v;
}

/// a random tree with joint springs and dampers on some coordinates (they belong in f_r, so the
/// torques must include them)
Model springyTree(int n, std::uint32_t seed) {
  ModelBuilder edit(scenes::randomTree(n, seed));
  for (int k = 0; k < edit.nr(); k += 3) {
    edit.coordinateAt(k).stiffness = 3.0 + k;
    edit.coordinateAt(k).rest_value = 0.2;
    edit.coordinateAt(k).damping = 0.5;
  }
  return edit.finalize();
}

class Hybrid : public ::testing::TestWithParam<int> {};

TEST_P(Hybrid, PrescribingEveryCoordinateGivesInverseDynamicsTorques) {
  const Model m = springyTree(10, 1300 + GetParam());
  std::mt19937 rng(GetParam());
  const auto sines = randomSines(m.nr(), rng);
  System sys(m);
  for (int k = 0; k < m.nr(); ++k) sys.addConstraint(std::make_shared<PrescribedCoordinate>(m, k, sines[k].function()));
  DynamicsWorkspace ws(m), ws_id(m);
  System plain(m);
  double worst = 0;
  for (double t : {0.3, 1.1, 2.9}) {
    State s;
    s.t = t;
    s.q.resize(m.nr());
    s.qdot.resize(m.nr());
    VecX qdd_p(m.nr());
    for (int k = 0; k < m.nr(); ++k) {
      s.q[k] = sines[k].q(t);
      s.qdot[k] = sines[k].qd(t);
      qdd_p[k] = sines[k].qdd(t);
    }
    const VecX qdd = sys.forwardDynamics(s, ws);
    EXPECT_TRUE(nearRel(qdd, qdd_p, 1e-10));
    // lambda is the actuation with M qddot = f + tau [D Eq. 4.109]: equal to both ID routes
    const VecX tau_id = plain.inverseDynamics(s, qdd_p, ws_id);
    const VecX tau_rnea = inverseDynamicsRecursive(m, s, qdd_p);
    EXPECT_LE((ws.lambda - tau_id).norm(), 1e-9 * tau_id.norm()) << (ws.lambda - tau_id).norm() / tau_id.norm();
    EXPECT_LE((ws.lambda - tau_rnea).norm(), 1e-9 * tau_rnea.norm());
    EXPECT_TRUE(nearRel(sys.prescribedForces(ws), ws.lambda, 1e-14));
    worst = std::max({worst, (ws.lambda - tau_id).norm() / tau_id.norm(), (ws.lambda - tau_rnea).norm() / tau_rnea.norm()});
  }
  std::printf("all prescribed, seed %d: |lambda - tau_ID| / |tau_ID| <= %.1e\n", GetParam(), worst);
}

TEST_P(Hybrid, FreeCoordinatesFollowForwardDynamicsUnderTheComputedTorques) {
  const Model m = springyTree(10, 1400 + GetParam());
  std::mt19937 rng(50 + GetParam());
  const auto sines = randomSines(m.nr(), rng);
  const std::vector<int> prescribed = {0, 2, m.nr() - 1};
  System sys(m);
  for (int k : prescribed) sys.addConstraint(std::make_shared<PrescribedCoordinate>(m, k, sines[k].function()));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.t = 0.7;
  s.q = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  s.qdot = VecX::NullaryExpr(m.nr(), [&] { return 2 * u(rng); });
  DynamicsWorkspace ws(m);
  const VecX qdd = sys.forwardDynamics(s, ws);
  const VecX tau = sys.prescribedForces(ws);
  // the prescribed coordinates get their prescribed accelerations, and only they are actuated
  for (int k = 0; k < m.nr(); ++k) {
    const bool p = std::find(prescribed.begin(), prescribed.end(), k) != prescribed.end();
    if (p) {
      EXPECT_NEAR(qdd[k], sines[k].qdd(s.t), 1e-10 * (1 + std::abs(sines[k].qdd(s.t))));
      EXPECT_GT(std::abs(tau[k]), 1e-6);
    } else {
      EXPECT_EQ(tau[k], 0.0);
    }
  }
  // plain forward dynamics under tau reproduces every acceleration
  System plain(m);
  DynamicsWorkspace wp(m);
  plain.calcMassAndForce(s, wp);
  const VecX qdd_fd = wp.M.ldlt().solve(wp.f + tau);
  EXPECT_TRUE(nearRel(qdd_fd, qdd, 1e-10));
  // and inverse dynamics of those accelerations gives back tau
  EXPECT_TRUE(nearRel(plain.inverseDynamics(s, qdd, wp), tau, 1e-9));
}

INSTANTIATE_TEST_SUITE_P(Seeds, Hybrid, ::testing::Range(0, 5),
                         [](const ::testing::TestParamInfo<int>& i) { return "seed" + std::to_string(i.param); });

TEST(Locked, HoldingTorqueHasTheDocumentedSign) {
  // a 1 m, 1 kg rod hinged about z, hanging along -y; locked horizontal (q = pi/2, rod along +x):
  // gravity pulls it down with torque -m g L/2, so the actuator must supply +m g L/2
  ModelBuilder b("rod");
  b.setGravity(Vec3(0, -9.81, 0));
  b.addBody("rod", 1.0, Vec3(0, -0.5, 0), Vec3(1.0 / 12, 1e-6, 1.0 / 12).asDiagonal(), -1, "pin", Revolute{});
  const Model m = b.finalize();
  System sys(m);
  sys.addConstraint(PrescribedCoordinate::makeLocked(m, 0, M_PI / 2));
  EXPECT_EQ(sys.constraints()[0]->name(), "locked_pin_0");
  State s;
  s.q = VecX::Constant(1, M_PI / 2);
  s.qdot = VecX::Zero(1);
  DynamicsWorkspace ws(m);
  const VecX qdd = sys.forwardDynamics(s, ws);
  EXPECT_NEAR(qdd[0], 0.0, 1e-14);
  EXPECT_NEAR(ws.lambda[0], 9.81 * 0.5, 1e-12);
}

TEST(Locked, DoublePendulumWithALockedShoulderSwingsAsASinglePendulum) {
  // link 1 locked at 0.3 rad: link 2 is a rod pendulum about its pin,
  // qddot_2 = -(3 g / 2 L) sin(q1 + q2)
  const Model m = scenes::doublePendulum();
  System sys(m);
  sys.addConstraint(PrescribedCoordinate::makeLocked(m, 0, 0.3));
  auto euler = makeIntegrator("euler", IntegratorOptions{.dt = 1e-3});
  State s;
  s.q = Vec2(0.3, 0.8);
  s.qdot = Vec2(0.0, -1.0);
  DynamicsWorkspace ws(m);
  System plain(m);
  DynamicsWorkspace wp(m);
  double max_lock = 0, max_acc = 0, max_tau = 0;
  for (int k = 0; k < 2000; ++k) {
    const VecX qdd = sys.forwardDynamics(s, ws);
    max_acc = std::max(max_acc, std::abs(qdd[1] + 1.5 * 9.81 * std::sin(s.q[0] + s.q[1])));
    // the holding torque is inverse dynamics of the constrained motion
    max_tau = std::max(max_tau, std::abs(ws.lambda[0] - plain.inverseDynamics(s, qdd, wp)[0]));
    euler->advance(sys, s, s.t + 1e-3);
    max_lock = std::max(max_lock, std::abs(s.q[0] - 0.3));
  }
  // the velocity-level row keeps qdot_1 = 0 exactly, so q_1 never moves (no projection)
  EXPECT_LE(max_lock, 1e-12);
  EXPECT_LE(max_acc, 1e-10);
  EXPECT_LE(max_tau, 1e-10);
}

TEST(Prescribed, TrackingInSimulation) {
  // shoulder driven along q1(t) = 0.6 sin(2 t + 0.3) - 0.2, elbow free
  const Model m = scenes::doublePendulum();
  const Sine drive{0.6, 2.0, 0.3, -0.2};
  auto makeSys = [&] {
    System sys(m);
    sys.addConstraint(std::make_shared<PrescribedCoordinate>(m, 0, drive.function()));
    return sys;
  };
  State s0;
  s0.q = Vec2(drive.q(0), 0.4);
  s0.qdot = Vec2(drive.qd(0), 0.0);
  DynamicsWorkspace ws(m);
  // (1) library Euler, velocity level only: O(h) tracking; with projection: exact
  {
    System sys = makeSys();
    auto euler = makeIntegrator("euler", IntegratorOptions{.dt = 1e-3});
    State s = s0, sp = s0;
    double err_plain = 0, err_proj = 0;
    for (int k = 0; k < 2000; ++k) {
      euler->advance(sys, s, s.t + 1e-3);
      euler->advance(sys, sp, sp.t + 1e-3);
      sys.projectPositions(sp, ws, 1e-14);
      sys.projectVelocities(sp, ws);
      err_plain = std::max(err_plain, std::abs(s.q[0] - drive.q(s.t)));
      err_proj = std::max({err_proj, std::abs(sp.q[0] - drive.q(sp.t)), std::abs(sp.qdot[0] - drive.qd(sp.t))});
    }
    EXPECT_LE(err_plain, 5e-3);
    EXPECT_LE(err_proj, 1e-12);
    std::printf("prescribed shoulder euler 2 s: tracking error %.2e (velocity level), %.2e (with projection)\n",
                err_plain, err_proj);
  }
  // (2) RK4 on the KKT accelerations with Baumgarte stabilisation
  {
    System sys = makeSys();
    sys.stabilization.alpha = sys.stabilization.beta = 20.0;
    State s = s0;
    double err = 0;
    for (int k = 0; k < 2000; ++k) {
      testing::rk4Step(sys, s, 1e-3, ws);
      err = std::max(err, std::abs(s.q[0] - drive.q(s.t)));
    }
    EXPECT_LE(err, 1e-9);
  }
}

}  // namespace
}  // namespace redmax
