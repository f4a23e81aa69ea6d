// OpenSim's compliant contact as ForceTerms (core/dynamics/contact_force_terms.hpp,
// docs/contact.md): the generalized force against J^T F of the reported contact force, the elastic
// part against central differences of its potential, the smooth model against HuntCrossley in its
// sharp limit, and simulations against closed forms: the Hertz rest penetration, the Hunt-Crossley
// restitution of a bounce, a block sliding to rest, energy conserved by an elastic bounce.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>

#include "core/dynamics/contact_force_terms.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/core/dynamics/term_eval.hpp"

namespace redmax {
namespace {

using test::potentialGradient;
using test::termForce;
using test::termPotential;

constexpr double kG = 9.80665;

Mat4 halfSpaceFrame() {
  // OpenSim's ground half-space: rotated -90 deg about z, it fills y < 0 (outward normal +y)
  Mat4 X = Mat4::Identity();
  X.topLeftCorner<3, 3>() = Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
  return X;
}

ContactSurface floorSurface() { return {"floor", ContactShape::HalfSpace, -1, halfSpaceFrame(), 0.0}; }

// a ball of mass m on a planar translation (x, y) with a contact sphere of radius r at its origin
Model ballModel(double m) {
  ModelBuilder b("ball");
  b.addBody("ball", m, Vec3::Zero(), Mat3::Identity() * 0.01, -1, "xy", Planar{});
  return b.finalize();
}

// a free-floating body (6 DoF) for the force and potential checks
Model freeBody() {
  ModelBuilder b("free");
  // translation (x, y, z) first, then exponential rotation coordinates
  b.addBody("box", 1.5, Vec3(0.01, -0.02, 0.03), Vec3(0.02, 0.03, 0.025).asDiagonal(), -1, "free", Free3D{});
  return b.finalize();
}

HuntCrossleyForceTerm::Force ballFloor(int body, double r, double k, double c, double us, double ud, double uv,
                                       double vt = 0.01) {
  HuntCrossleyForceTerm::Force F;
  F.name = "ball_floor";
  F.surfaces = {floorSurface(), {"ball", ContactShape::Sphere, body, Mat4::Identity(), r}};
  F.materials = {{k, c, us, ud, uv}, {k, c, us, ud, uv}};
  F.transition_velocity = vt;
  return F;
}

// generalized force from the reported contact forces: sum of J_p^T F at the contact points
VecX forceFromReports(const Model& m, const ContactForceTerm& t, const State& s, int body) {
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  std::vector<ContactReport> reps;
  t.contacts(sk, reps);
  VecX f = VecX::Zero(m.nr());
  MatX J(3, m.nr());
  for (const ContactReport& r : reps) {
    const Mat4& E = sk.E_wi[body];
    const Vec3 x_i = E.topLeftCorner<3, 3>().transpose() * (r.point_w - E.topRightCorner<3, 1>());
    pointJacobian(m, sk, body, x_i, J);
    f += J.transpose() * r.force_w;
  }
  return f;
}

State freeState(double height) {
  State s;
  s.q = VecX::Zero(6);
  s.qdot = VecX::Zero(6);
  s.q << 0.02, height, -0.01, 0.3, -0.2, 0.4;
  s.qdot << 0.7, -0.9, 0.4, 1.1, -0.6, 0.8;
  return s;
}

TEST(HuntCrossleyForceTerm, GeneralizedForceIsJacobianTransposeOfTheContactForce) {
  const Model m = freeBody();
  // a sphere off the body origin so that the force has a moment; friction and dissipation on
  HuntCrossleyForceTerm::Force F = ballFloor(0, 0.1, 1e6, 0.3, 0.9, 0.6, 0.1);
  F.surfaces[1].X_body.topRightCorner<3, 1>() = Vec3(0.02, -0.03, 0.01);
  const HuntCrossleyForceTerm term(m, {F});
  const State s = freeState(0.12);  // sphere centre about 0.09 m up: penetration about 1e-2 m
  const VecX f = termForce(m, term, s);
  const VecX g = forceFromReports(m, term, s, 0);
  ASSERT_GT(f.norm(), 1.0);
  std::printf("HuntCrossley: |f - J^T F| / |f| = %.2g\n", (f - g).norm() / f.norm());
  EXPECT_LE((f - g).norm(), 1e-15 * f.norm())  // measured 1.1e-16
   << f.transpose() << "\n" << g.transpose();
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  const ContactSummary sum = term.summary(sk);
  EXPECT_EQ(sum.active, 1);
  EXPECT_GT(sum.max_penetration, 0.0);
}

TEST(HuntCrossleyForceTerm, ElasticForceIsMinusGradientOfItsPotential) {
  const Model m = freeBody();
  HuntCrossleyForceTerm::Force F = ballFloor(0, 0.1, 3e6, 0.0, 0.0, 0.0, 0.0);
  F.materials[1].stiffness = 8e6;  // unequal materials: the contact point moves
  F.surfaces[1].X_body.topRightCorner<3, 1>() = Vec3(0.02, -0.03, 0.01);
  // a second sphere on the body touching a ground sphere: the sphere-sphere pair
  F.surfaces.push_back({"knob", ContactShape::Sphere, -1, Mat4::Identity(), 0.05});
  F.surfaces.back().X_body.topRightCorner<3, 1>() = Vec3(0.3, 0.05, 0.45);
  F.materials.push_back({5e6, 0.0, 0.0, 0.0, 0.0});
  const HuntCrossleyForceTerm term(m, {F});
  State s = freeState(0.12);
  s.q[0] = 0.3;  // the body sphere also overlaps the knob (centres 0.13 apart, radii 0.15)
  s.q[2] = 0.45 - 0.0;
  s.q[1] = 0.12;
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  std::vector<ContactReport> reps;
  term.contacts(sk, reps);
  int active = 0;
  for (const auto& r : reps) active += r.active;
  ASSERT_EQ(active, 2) << "both pairs must overlap";
  s.qdot.setZero();  // no dissipation anyway; zero speed keeps the friction out
  const VecX f = termForce(m, term, s);
  const VecX grad = potentialGradient(m, term, s);
  std::printf("HuntCrossley: |f + dV/dq| / |f| = %.2g\n", (f + grad).norm() / f.norm());
  EXPECT_LE((f + grad).norm(), 1e-9 * f.norm())  // measured 1.4e-10
   << f.transpose() << "\n" << -grad.transpose();
}

TEST(HuntCrossleyForceTerm, StribeckFrictionLaw) {
  // Simbody's law: min(v/vt, 1) (ud + 2 (us - ud) / (1 + (v/vt)^2)) + uv v
  const double us = 0.9, ud = 0.5, uv = 0.1, vt = 0.01;
  EXPECT_DOUBLE_EQ(HuntCrossleyForceTerm::frictionCoefficient(us, ud, uv, vt, 0.0), 0.0);
  // at v = vt the peak us (plus viscous)
  EXPECT_DOUBLE_EQ(HuntCrossleyForceTerm::frictionCoefficient(us, ud, uv, vt, vt), us + uv * vt);
  // far above: ud + uv v
  EXPECT_NEAR(HuntCrossleyForceTerm::frictionCoefficient(us, ud, uv, vt, 10.0), ud + uv * 10.0, 1e-5);
  // below vt: linear in v at small v (slope (ud + 2(us - ud)) / vt)
  EXPECT_NEAR(HuntCrossleyForceTerm::frictionCoefficient(us, ud, 0.0, vt, 1e-6), 1e-6 / vt * (2 * us - ud), 1e-9);
}

TEST(HuntCrossleyForceTerm, RefusesBadParameters) {
  const Model m = ballModel(1.0);
  auto bad = [&](const std::function<void(HuntCrossleyForceTerm::Force&)>& edit) {
    HuntCrossleyForceTerm::Force F = ballFloor(0, 0.1, 1e6, 0.1, 0.5, 0.5, 0.0);
    edit(F);
    EXPECT_THROW(HuntCrossleyForceTerm(m, {F}), ModelError);
  };
  bad([](auto& F) { F.materials[0].stiffness = 0.0; });
  bad([](auto& F) { F.materials[1].dissipation = -1.0; });
  bad([](auto& F) { F.surfaces[1].radius = 0.0; });
  bad([](auto& F) { F.transition_velocity = 0.0; });
  bad([](auto& F) { F.surfaces[1].body = 5; });
  bad([](auto& F) { F.materials[1].static_friction = std::nan(""); });
}

TEST(SmoothSphereHalfSpaceForceTerm, SharpLimitIsHuntCrossleyWithEqualMaterials) {
  const Model m = freeBody();
  const double E = 2e6, c = 0.4;
  HuntCrossleyForceTerm::Force F = ballFloor(0, 0.1, E, c, 0.7, 0.5, 0.2, 0.05);
  F.surfaces[1].X_body.topRightCorner<3, 1>() = Vec3(0.02, -0.03, 0.01);
  const HuntCrossleyForceTerm hc(m, {F});
  SmoothSphereHalfSpaceForceTerm::Contact C;
  C.name = "smooth";
  C.sphere = F.surfaces[1];
  C.half_space = F.surfaces[0];
  C.stiffness = E;
  C.dissipation = c;
  C.static_friction = 0.7;
  C.dynamic_friction = 0.5;
  C.viscous_friction = 0.2;
  C.transition_velocity = 0.05;
  // no constant force, steep switches: the smooth law becomes Hunt-Crossley's
  C.constant_contact_force = 0.0;
  C.hertz_smoothing = 1e9;
  C.hunt_crossley_smoothing = 1e9;
  const SmoothSphereHalfSpaceForceTerm smooth(m, {C});
  const State s = freeState(0.12);
  const VecX a = termForce(m, hc, s), b = termForce(m, smooth, s);
  ASSERT_GT(a.norm(), 1.0);
  std::printf("smooth vs HuntCrossley, sharp limit: %.2g relative\n", (a - b).norm() / a.norm());
  EXPECT_LE((a - b).norm(), 5e-15 * a.norm())  // measured 5.1e-16
   << a.transpose() << "\n" << b.transpose();
  EXPECT_NEAR(termPotential(m, hc, s), termPotential(m, smooth, s), 1e-14 * termPotential(m, hc, s));
  // OpenSim's defaults (cf 1e-5, bd 300, bv 50): the force at 1 cm follows the smooth formula
  C.constant_contact_force = 1e-5;
  C.hertz_smoothing = 300;
  C.hunt_crossley_smoothing = 50;
  C.static_friction = C.dynamic_friction = C.viscous_friction = 0.0;
  C.dissipation = 0.0;
  C.sphere.X_body = Mat4::Identity();
  const SmoothSphereHalfSpaceForceTerm defaults(m, {C});
  State r = freeState(0.09);  // centre 0.09 m up: x = 0.01 m
  r.q.tail<3>().setZero();
  r.q[0] = r.q[2] = 0.0;
  r.qdot.setZero();
  const double k = 0.5 * std::pow(E, 2.0 / 3.0), x = 0.01;
  const double fh = 4.0 / 3.0 * k * std::sqrt(0.1 * k) * std::pow(x * x + 1e-5, 0.75) * (0.5 + 0.5 * std::tanh(300 * x));
  const VecX fr = termForce(m, defaults, r);
  EXPECT_NEAR(fr[1], fh, 1e-10 * fh);  // the vertical translation takes the normal force
  // and applies a tiny force out of contact: 4 cm up, x = -0.04 (0.5 (1 + tanh(-12)) = 3.8e-11)
  r.q[1] = 0.14;
  const VecX fa = termForce(m, defaults, r);
  EXPECT_GT(fa[1], 0.0);
  EXPECT_LT(fa[1], 1e-6);
}

// ---------------------------------------------------------------------------------------------
// simulations

struct BallRun {
  System sys;
  State s;
};

BallRun ballOnFloor(double mass, double r, double k, double c, double us, double ud, double height, double vx) {
  const Model m = ballModel(mass);
  System sys(m);
  sys.addTerm(std::make_shared<HuntCrossleyForceTerm>(m, std::vector{ballFloor(0, r, k, c, us, ud, 0.0)}));
  State s = sys.defaultState();
  s.q << 0.0, height;
  s.qdot << vx, 0.0;
  return {std::move(sys), s};
}

double restPenetration(double mass, double r, double k) {
  const double E = std::pow(0.5 * std::pow(k, 2.0 / 3.0), 1.5);  // two equal materials
  return std::pow(3.0 * mass * kG / (4.0 * E * std::sqrt(r)), 2.0 / 3.0);
}

TEST(ContactSimulation, BallComesToRestAtTheHertzPenetration) {
  const double mass = 1.0, r = 0.1, k = 1e7;
  BallRun b = ballOnFloor(mass, r, k, 1.0, 0.0, 0.0, 0.3, 0.0);
  IntegratorOptions o;
  o.rtol = 1e-9;
  o.atol = 1e-11;
  auto integ = makeIntegrator("rk45", o);
  integ->advance(b.sys, b.s, 3.0);
  const double d = r - b.s.q[1], d_eq = restPenetration(mass, r, k);
  std::printf("rest penetration %.8g m, closed form %.8g m, relative difference %.2g\n", d, d_eq, std::abs(d - d_eq) / d_eq);
  EXPECT_NEAR(d, d_eq, 1e-7 * d_eq) << d;  // measured 1.5e-8
  EXPECT_LT(std::abs(b.s.qdot[1]), 1e-5);
}

// the scalar Hunt-Crossley impact with gravity, m x'' = -(k x^1.5 (1 + 1.5 c x') - m g) for
// penetration x, integrated by RK4 with a tiny step from first touch at speed v to separation:
// the exit speed (an independent reference for the rebound)
double scalarExitSpeed(double mass, double kh, double c, double v) {
  auto acc = [&](double x, double xd) {
    const double fe = x > 0 ? kh * std::pow(x, 1.5) * (1.0 + 1.5 * c * xd) : 0.0;
    return kG - std::max(fe, 0.0) / mass;
  };
  double x = 0.0, xd = v;
  const double h = 1e-7;
  for (long i = 0; i < 100000000; ++i) {
    const double k1x = xd, k1v = acc(x, xd);
    const double k2x = xd + 0.5 * h * k1v, k2v = acc(x + 0.5 * h * k1x, xd + 0.5 * h * k1v);
    const double k3x = xd + 0.5 * h * k2v, k3v = acc(x + 0.5 * h * k2x, xd + 0.5 * h * k2v);
    const double k4x = xd + h * k3v, k4v = acc(x + h * k3x, xd + h * k3v);
    const double xn = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    const double vn = xd + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (xn <= 0.0 && i > 0) {
      // linear interpolation to x = 0 for the exit speed
      const double a = x / (x - xn);
      return -(xd + a * (vn - xd));
    }
    x = xn;
    xd = vn;
  }
  return std::nan("");
}

TEST(ContactSimulation, BounceFollowsHuntCrossleyRestitution) {
  const double mass = 1.0, r = 0.1, k = 1e7, c = 0.05, h0 = 0.3;
  BallRun b = ballOnFloor(mass, r, k, c, 0.0, 0.0, r + h0, 0.0);
  IntegratorOptions o;
  o.rtol = 1e-10;
  o.atol = 1e-12;
  o.max_step = 1e-3;
  auto integ = makeIntegrator("rk45", o);
  // the top of the first rebound: the highest point after the first contact
  double t = 0.0, top = 0.0;
  bool touched = false;
  while (t < 0.8) {
    t += 2e-5;
    integ->advance(b.sys, b.s, t);
    if (b.s.q[1] < r) touched = true;
    if (touched && b.s.q[1] > r) top = std::max(top, b.s.q[1] - r);
  }
  ASSERT_TRUE(touched);
  const double v_in = std::sqrt(2 * kG * h0);
  const double e = std::sqrt(top / h0);
  // the independent scalar reference (Hertz constant of two equal materials)
  const double kh = 4.0 / 3.0 * std::pow(0.5 * std::pow(k, 2.0 / 3.0), 1.5) * std::sqrt(r);
  const double e_ref = scalarExitSpeed(mass, kh, c, v_in) / v_in;
  std::printf("restitution %.8g, scalar reference %.8g, 1 - c v = %.8g (c v = %.4g)\n", e, e_ref, 1 - c * v_in, c * v_in);
  EXPECT_NEAR(e, e_ref, 1e-7) << e << " " << e_ref;  // measured 1e-8
  // Hunt and Crossley's relation e = 1 - c v holds to first order in c v: here c v = 0.1213,
  // measured e = 0.88846, 1 - c v = 0.87872, the difference 0.66 (c v)^2
  EXPECT_NEAR(e, 1.0 - c * v_in, 0.8 * (c * v_in) * (c * v_in)) << e;
  EXPECT_GT(e, 1.0 - c * v_in);
}

TEST(ContactSimulation, ElasticBounceConservesEnergy) {
  const double mass = 1.0, r = 0.1, k = 1e7;
  BallRun b = ballOnFloor(mass, r, k, 0.0, 0.0, 0.0, r + 0.2, 0.0);
  IntegratorOptions o;
  o.rtol = 1e-10;
  o.atol = 1e-12;
  auto integ = makeIntegrator("rk45", o);
  DynamicsWorkspace ws(b.sys);
  const double E0 = b.sys.kineticEnergy(b.s, ws) + b.sys.potentialEnergy(b.s, ws);
  double worst = 0.0, lowest = 1.0;
  for (double t = 0.01; t <= 1.0 + 1e-12; t += 0.01) {
    integ->advance(b.sys, b.s, t);
    const double E = b.sys.kineticEnergy(b.s, ws) + b.sys.potentialEnergy(b.s, ws);
    worst = std::max(worst, std::abs(E - E0));
    lowest = std::min(lowest, b.s.q[1]);
  }
  EXPECT_LT(lowest, r);  // it bounced (several times)
  std::printf("elastic bounce: worst |E - E0| = %.3g J of %.4g J\n", worst, E0);
  EXPECT_LE(worst, 5e-8 * std::abs(E0)) << worst;  // measured 1.8e-8 J (6e-9 relative)
}

// distance a block slides from v0 with friction coefficient mu(v) (Simbody's law), the normal
// force m g: s = integral_0^v0 v / (g mu(v)) dv, by Simpson's rule in two pieces
double slidingDistance(double us, double ud, double vt, double v0) {
  auto integrand = [&](double v) {
    if (v <= 0.0) return vt / (kG * (2 * us - ud));  // the limit v / mu(v) at 0
    return v / (kG * HuntCrossleyForceTerm::frictionCoefficient(us, ud, 0.0, vt, v));
  };
  auto simpson = [&](double a, double b, int n) {
    const double h = (b - a) / n;
    double s = integrand(a) + integrand(b);
    for (int i = 1; i < n; ++i) s += integrand(a + i * h) * (i % 2 ? 4 : 2);
    return s * h / 3;
  };
  return simpson(0.0, vt, 20000) + simpson(vt, v0, 200000);
}

TEST(ContactSimulation, BlockSlidesToRestAtTheFrictionDistance) {
  const double mass = 2.0, r = 0.05, k = 1e7, v0 = 2.0, vt = 0.01;
  for (const auto& [us, ud] : {std::pair{0.5, 0.5}, std::pair{0.8, 0.5}}) {
    // start at the rest penetration: the normal force is m g throughout
    BallRun b = ballOnFloor(mass, r, k, 0.5, us, ud, r - restPenetration(mass, r, k), v0);
    IntegratorOptions o;
    o.rtol = 1e-9;
    o.atol = 1e-12;
    auto integ = makeIntegrator("rk45", o);
    integ->advance(b.sys, b.s, 1.0);  // stops after about 0.41 s; the tail below vt decays in ~2 ms
    const double s_ref = slidingDistance(us, ud, vt, v0);
    std::printf("sliding us %.2g ud %.2g: %.10g m, reference %.10g m, relative %.2g\n", us, ud, b.s.q[0], s_ref,
                std::abs(b.s.q[0] - s_ref) / s_ref);
    if (us == ud) {
      // closed form (v0^2 + vt^2) / (2 ud g) = 0.40790 m
      EXPECT_NEAR(s_ref, (v0 * v0 + vt * vt) / (2 * ud * kG), 1e-9);
    }
    EXPECT_NEAR(b.s.q[0], s_ref, 3e-11 * s_ref) << us << " " << ud;  // measured 2.9e-13, 3.7e-12
    EXPECT_LT(std::abs(b.s.qdot[0]), 1e-6);
  }
}

}  // namespace
}  // namespace redmax
