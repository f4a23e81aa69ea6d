// A free-spinning, precessing rigid body on a spherical joint in exponential coordinates: the
// integrators must switch chart [D Sec. 4.5.8] as |q| passes 1.5 pi, about once per revolution,
// while the motion stays that of the torque-free body (energy and world angular momentum kept).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/skeleton/kinematics.hpp"
#include "tests/core/integrators/integrator_test_util.hpp"

namespace redmax {
namespace {
using namespace testing_util;

/// one body, COM at the joint, asymmetric inertia (principal moments 1, 2, 3 in rotated axes), no
/// gravity, on a SphericalExp joint
Model spinningBody() {
  ModelBuilder b("spinning_body");
  b.setGravity(Vec3::Zero());
  const Mat3 R = expSO3(Vec3(0.3, -0.5, 0.2));
  const Mat3 I = R * Vec3(1.0, 2.0, 3.0).asDiagonal() * R.transpose();
  b.addBody("body", 2.0, Vec3::Zero(), I, -1, "ball", SphericalExp{});
  return b.finalize();
}

/// world-frame angular momentum about the joint (= COM): R_wi I omega_i
Vec3 angularMomentum(const Model& m, const State& s) {
  SkeletonWorkspace ws(m);
  calcKinematics(m, s, ws);
  const Vec3 omega_i = ws.phi[0].head<3>();
  return ws.E_wi[0].topLeftCorner<3, 3>() * (m.bodies()[0].inertia_com * omega_i);
}

struct SpinResult {
  double max_energy_err = 0.0, max_momentum_err = 0.0, max_q_norm = 0.0, revolutions = 0.0;
  IntegratorStats stats;
};

/// spin about 100 revolutions (mostly about the major axis, precessing), sampled every 10 ms
SpinResult spin(const std::string& name, const IntegratorOptions& opt, double T) {
  System sys(spinningBody());
  const Model& m = sys.model();
  State s = sys.defaultState();
  // initial body angular velocity: 10 rev/s about the major axis plus a tilt that makes it precess
  const Mat3 R = expSO3(Vec3(0.3, -0.5, 0.2));
  const Vec3 omega_i = R * Vec3(4.0, -3.0, 20.0 * M_PI);
  // qdot = S^-1 omega at q = 0 where S = I
  s.qdot = omega_i;
  const double E0 = totalEnergy(sys, s);
  const Vec3 L0 = angularMomentum(m, s);
  SpinResult r;
  auto integ = makeIntegrator(name, opt);
  double angle = 0.0;
  const int n_out = static_cast<int>(std::lround(T / 0.01));
  for (int k = 1; k <= n_out; ++k) {
    integ->advance(sys, s, 0.01 * k);
    r.max_energy_err = std::max(r.max_energy_err, std::abs(totalEnergy(sys, s) - E0) / E0);
    r.max_momentum_err = std::max(r.max_momentum_err, (angularMomentum(m, s) - L0).norm() / L0.norm());
    r.max_q_norm = std::max(r.max_q_norm, s.q.norm());
    SkeletonWorkspace ws(m);
    calcKinematics(m, s, ws);
    angle += 0.01 * ws.phi[0].head<3>().norm();
  }
  r.revolutions = angle / (2.0 * M_PI);
  r.stats = integ->stats();
  return r;
}

// rk45 at rtol 1e-10 over ~100 revolutions: the chart switches fire (about once per revolution)
// and energy and world angular momentum stay within 1e-7 (relative).
TEST(SpinningBody, Rk45ReparameterizesAndKeepsInvariants) {
  IntegratorOptions opt;
  opt.rtol = 1e-10;
  opt.atol = 1e-12;
  const SpinResult r = spin("rk45", opt, 10.0);
  std::printf("rk45: %.1f revolutions, %ld chart switches, %ld steps, %ld rhs; max rel. energy error %.3e, "
              "momentum error %.3e, max |q| %.4f\n",
              r.revolutions, r.stats.reparameterizations, r.stats.steps, r.stats.rhs_evals, r.max_energy_err,
              r.max_momentum_err, r.max_q_norm);
  EXPECT_GE(r.revolutions, 100.0);
  EXPECT_GT(r.stats.reparameterizations, 50);
  EXPECT_LE(r.max_energy_err, 1e-7);
  EXPECT_LE(r.max_momentum_err, 1e-7);
  // returned states are always in the chart |q| <= 1.5 pi
  EXPECT_LE(r.max_q_norm, 1.5 * M_PI + 1e-12);
}

// The other integrators switch chart too and keep the invariants to their accuracy over 2 s (20
// revolutions): cvode at rtol 1e-10 (1e-6), sdirk2 at h = 1 ms (1e-2), symplectic Euler and bdf1
// at h = 0.1 ms (3e-2; first order, 6e-3 rad of spin per step; identical here: no springs).
TEST(SpinningBody, AllIntegratorsReparameterize) {
  struct Case {
    const char* name;
    double dt, tol;
  };
  for (const Case c : {Case{"cvode", 0.0, 1e-6}, Case{"sdirk2", 1e-3, 1e-2}, Case{"euler", 1e-4, 3e-2},
                       Case{"bdf1", 1e-4, 3e-2}}) {
    IntegratorOptions opt;
    opt.rtol = 1e-10;
    opt.atol = 1e-12;
    if (c.dt > 0.0) opt.dt = c.dt;
    const SpinResult r = spin(c.name, opt, 2.0);
    std::printf("%s: %.1f revolutions, %ld chart switches, %ld steps; max rel. energy error %.3e, "
                "momentum error %.3e\n",
                c.name, r.revolutions, r.stats.reparameterizations, r.stats.steps, r.max_energy_err,
                r.max_momentum_err);
    EXPECT_GT(r.stats.reparameterizations, 10) << c.name;
    EXPECT_LE(r.max_energy_err, c.tol) << c.name;
    EXPECT_LE(r.max_momentum_err, c.tol) << c.name;
    EXPECT_LE(r.max_q_norm, 1.5 * M_PI + 1e-12) << c.name;
  }
}

}  // namespace
}  // namespace redmax
