#pragma once
// Small mechanisms and checking tools shared by the constraint, coordinate-map and hybrid-dynamics
// tests: a planar four-bar linkage, floating bodies on 6-coordinate chains, a test-local RK4 on
// System::forwardDynamics, and finite-difference probes of a Constraint.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/dynamics/system.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::testing {

/// thin rod along x from the body origin: mass m, length L
inline Mat3 rodInertia(double m, double L) {
  return Vec3(1e-3 * m * L * L, m * L * L / 12.0, m * L * L / 12.0).asDiagonal();
}

/// Planar four-bar: ground pivots O1 = (0,0,0) and O2 = (ground, 0, 0); crank, coupler, rocker
/// hinged about z in series from O1 (3 coordinates); the rocker's tip must meet O2.
struct FourBar {
  double crank = 1.0, coupler = 2.0, rocker = 1.5, ground = 2.2;  // crank-rocker (Grashof)
  Model model;
  int crank_body = 0, coupler_body = 1, rocker_body = 2;
  Vec3 tip_rocker() const { return Vec3(rocker, 0, 0); }
  Vec3 pivot_world() const { return Vec3(ground, 0, 0); }

  FourBar() {
    ModelBuilder b("four_bar");
    b.setGravity(Vec3(0, -9.81, 0));
    crank_body = b.addBody("crank", 1.0, Vec3(crank / 2, 0, 0), rodInertia(1.0, crank), -1, "j1", Revolute{});
    coupler_body = b.addBody("coupler", 2.0, Vec3(coupler / 2, 0, 0), rodInertia(2.0, coupler), crank_body,
                             "j2", Revolute{}, makeTranslation(Vec3(crank, 0, 0)));
    rocker_body = b.addBody("rocker", 1.5, Vec3(rocker / 2, 0, 0), rodInertia(1.5, rocker), coupler_body,
                            "j3", Revolute{}, makeTranslation(Vec3(coupler, 0, 0)));
    model = b.finalize();
  }

  /// closed configuration for crank angle q1 (elbow up), by circle intersection
  VecX closedQ(double q1) const {
    const Vec2 P(crank * std::cos(q1), crank * std::sin(q1));
    const Vec2 O2(ground, 0.0);
    const double d = (O2 - P).norm();
    const double a = (coupler * coupler - rocker * rocker + d * d) / (2 * d);
    const double h = std::sqrt(coupler * coupler - a * a);
    const Vec2 e = (O2 - P) / d;
    const Vec2 Q = P + a * e + h * Vec2(-e.y(), e.x());
    const double th2 = std::atan2(Q.y() - P.y(), Q.x() - P.x());
    const double th3 = std::atan2(O2.y() - Q.y(), O2.x() - Q.x());
    VecX q(3);
    q << q1, th2 - q1, th3 - th2;
    return q;
  }
  /// velocities of the closed loop for crank rate w1 (null space of the loop Jacobian)
  VecX closedQdot(const VecX& q, double w1) const {
    // relative joint rates (w1, w2, w3) with the tip velocity zero: the tip moves with
    // sum_k w_k z x (tip - pivot_k)
    const Vec2 P(crank * std::cos(q[0]), crank * std::sin(q[0]));
    const double t2 = q[0] + q[1];
    const Vec2 Q = P + coupler * Vec2(std::cos(t2), std::sin(t2));
    const Vec2 T(ground, 0.0);
    auto perp = [](const Vec2& r) { return Vec2(-r.y(), r.x()); };
    Eigen::Matrix2d A;
    A.col(0) = perp(T - P);
    A.col(1) = perp(T - Q);
    const Vec2 w23 = A.colPivHouseholderQr().solve(-w1 * perp(T));
    VecX qd(3);
    qd << w1, w23;
    return qd;
  }
};

/// Adds a body with 6 coordinates (x, y, z translations, then rotations about x, y, z,
/// body-fixed) through five massless intermediate bodies; returns the real body's index.
inline int addFloatingBody(ModelBuilder& b, const std::string& name, double m, const Vec3& com, const Mat3& I) {
  const Mat3 Z = Mat3::Zero();
  int p = -1;
  const Vec3 axes[3] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  for (int k = 0; k < 3; ++k) {
    Prismatic j;
    j.axis = axes[k];
    p = b.addBody(name + "_t" + std::to_string(k), 0.0, Vec3::Zero(), Z, p, name + "_jt" + std::to_string(k), j);
  }
  for (int k = 0; k < 2; ++k) {
    Revolute j;
    j.axis = axes[k];
    p = b.addBody(name + "_r" + std::to_string(k), 0.0, Vec3::Zero(), Z, p, name + "_jr" + std::to_string(k), j);
  }
  Revolute j;
  j.axis = axes[2];
  return b.addBody(name, m, com, I, p, name + "_jr2", j);
}

/// coordinates (x, y, z, rx, ry, rz) of a floating body with pose E (R = Rx Ry Rz), |ry| < pi/2
inline VecX floatingCoordinates(const Mat4& E) {
  const Mat3 R = E.topLeftCorner<3, 3>();
  VecX q(6);
  q.head(3) = E.topRightCorner<3, 1>();
  q[4] = std::asin(std::clamp(R(0, 2), -1.0, 1.0));
  q[3] = std::atan2(-R(1, 2), R(2, 2));
  q[5] = std::atan2(-R(0, 1), R(0, 0));
  return q;
}

/// classical RK4 on (q, qdot) with qddot = sys.forwardDynamics (constraints through the KKT
/// accelerations, stabilised by sys.stabilization)
inline void rk4Step(const System& sys, State& s, double h, DynamicsWorkspace& ws) {
  auto acc = [&](const VecX& q, const VecX& qd, double t) {
    State x;
    x.t = t;
    x.q = q;
    x.qdot = qd;
    return sys.forwardDynamics(x, ws);
  };
  const VecX q0 = s.q, v0 = s.qdot;
  const VecX a1 = acc(q0, v0, s.t);
  const VecX v1 = v0;
  const VecX a2 = acc(q0 + 0.5 * h * v1, v0 + 0.5 * h * a1, s.t + 0.5 * h);
  const VecX v2 = v0 + 0.5 * h * a1;
  const VecX a3 = acc(q0 + 0.5 * h * v2, v0 + 0.5 * h * a2, s.t + 0.5 * h);
  const VecX v3 = v0 + 0.5 * h * a2;
  const VecX a4 = acc(q0 + h * v3, v0 + h * a3, s.t + h);
  const VecX v4 = v0 + h * a3;
  s.q = q0 + h / 6.0 * (v1 + 2 * v2 + 2 * v3 + v4);
  s.qdot = v0 + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4);
  s.t += h;
}

/// semi-implicit Euler step with velocity-level constraints [D Eq. 4.102, 4.110], the same
/// scheme as the library's "euler", written against the System API only (used for systems with
/// hyper-reduced coordinates while the integrators learn about System::reparameterize)
inline void eulerStep(const System& sys, State& s, double h, DynamicsWorkspace& ws) {
  sys.calcMassAndForce(s, ws);
  const VecX a = ws.M * s.qdot + h * ws.f;
  if (sys.numConstraintRows() == 0) {
    s.qdot = ws.M.ldlt().solve(a);
  } else {
    sys.calcConstraints(s, ws);
    const VecX b = ws.G * s.qdot + h * ws.rhs - ws.vel_err;
    s.qdot = System::solveKKT(ws.M, ws.G, a, b, &ws.lambda);
  }
  s.q += h * s.qdot;
  s.t += h;
}

/// Constraint quantities at one state, evaluated on a fresh workspace.
struct ConstraintEval {
  MatX G;
  VecX rhs, pos_err, vel_err;
};
inline ConstraintEval evalConstraint(const Constraint& c, const Model& m, const State& s) {
  SkeletonWorkspace ws(m);
  calcKinematics(m, s, ws);
  ConstraintEval e;
  e.G.setZero(c.rows(), m.nr());
  e.rhs.setZero(c.rows());
  e.pos_err.setZero(c.rows());
  e.vel_err.setZero(c.rows());
  c.calcAcceleration(m, s, ws, e.G, e.rhs);
  c.calcErrors(m, s, ws, e.pos_err, e.vel_err);
  return e;
}

/// central-difference dC/dq (rows x nr), C = pos_err
inline MatX fdPositionJacobian(const Constraint& c, const Model& m, const State& s, double h = 1e-6) {
  MatX J(c.rows(), m.nr());
  for (int j = 0; j < m.nr(); ++j) {
    State sp = s, sm = s;
    sp.q[j] += h;
    sm.q[j] -= h;
    J.col(j) = (evalConstraint(c, m, sp).pos_err - evalConstraint(c, m, sm).pos_err) / (2 * h);
  }
  return J;
}

/// d/dtau of the position error along (q + tau qdot, t + tau)
inline VecX fdPositionRate(const Constraint& c, const Model& m, const State& s, double h = 1e-6) {
  State sp = s, sm = s;
  sp.q += h * s.qdot;
  sp.t += h;
  sm.q -= h * s.qdot;
  sm.t -= h;
  return (evalConstraint(c, m, sp).pos_err - evalConstraint(c, m, sm).pos_err) / (2 * h);
}

/// d/dtau of the velocity error along (q + tau qdot, qdot + tau a, t + tau): must be G a - rhs
inline VecX fdVelocityRate(const Constraint& c, const Model& m, const State& s, const VecX& a, double h = 1e-6) {
  State sp = s, sm = s;
  sp.q += h * s.qdot;
  sp.qdot += h * a;
  sp.t += h;
  sm.q -= h * s.qdot;
  sm.qdot -= h * a;
  sm.t -= h;
  return (evalConstraint(c, m, sp).vel_err - evalConstraint(c, m, sm).vel_err) / (2 * h);
}

/// Gdot qdot by differencing G along qdot (time-independent constraints)
inline VecX fdGdotQdot(const Constraint& c, const Model& m, const State& s, double h = 1e-6) {
  State sp = s, sm = s;
  sp.q += h * s.qdot;
  sm.q -= h * s.qdot;
  return (evalConstraint(c, m, sp).G - evalConstraint(c, m, sm).G) / (2 * h) * s.qdot;
}

}  // namespace redmax::testing
