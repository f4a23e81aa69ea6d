// WrapTorus as OpenSim computes it (docs/opensim_compatibility.md §6): the point of the centre circle
// nearest the muscle line (searched from each end, the better of the two, quadrant-aware) carries
// a long cylinder of the tube radius, tangent to the circle, with quadrant "+x" toward the torus
// centre; the cylinder code does the rest.
#include <cmath>

#include "core/muscles/wrap/wrap_geometry.hpp"

namespace redmax::detail {
namespace {

constexpr double kCylinderLength = 10000.0;

// OpenSim's residual for the line point x(u) = p1 + u n: d/du of |x|^2 - 4 r |x_xy|, i.e. the
// squared distance to a circle of radius 2r (OpenSim's factor, reproduced): zero at the point
// it takes as nearest
double circleResidual(const Vec3& p1, const Vec3& n, double r, double u) {
  const double c2 = 2.0 * p1.dot(n);
  const double c3 = p1[0] * n[0] + p1[1] * n[1];
  const double c4 = n[0] * n[0] + n[1] * n[1];
  const double c5 = p1[0] * p1[0] + p1[1] * p1[1];
  return c2 + 2.0 * u - 2.0 * r * (2.0 * c4 * u + 2.0 * c3) / std::sqrt(u * u * c4 + 2.0 * c3 * u + c5);
}

// a root of the residual reached from u = 0 by damped Newton steps (OpenSim: MINPACK lmdif from
// u = 0, step bound 0.2, tolerance 1e-4; here converged to ~1e-12)
double solveFromStart(const Vec3& p1, const Vec3& n, double r) {
  double u = 0.0, f = circleResidual(p1, n, r, u), bound = 0.2;
  for (int it = 0; it < 500 && std::isfinite(f); ++it) {
    const double h = 1e-7 * (1.0 + std::abs(u));
    const double df = (circleResidual(p1, n, r, u + h) - circleResidual(p1, n, r, u - h)) / (2 * h);
    double step = (df != 0.0 && std::isfinite(df)) ? -f / df : (f > 0 ? -bound : bound);
    if (std::abs(step) > bound) step = step > 0 ? bound : -bound;
    // halve until |residual| decreases (as a trust region would)
    bool accepted = false;
    for (int k = 0; k < 60; ++k) {
      const double fn = circleResidual(p1, n, r, u + step);
      if (std::isfinite(fn) && std::abs(fn) < std::abs(f)) {
        u += step;
        f = fn;
        accepted = true;
        break;
      }
      step *= 0.5;
    }
    if (!accepted) break;
    bound = std::max(bound, 2.0 * std::abs(step));
    if (std::abs(step) < 1e-13 * (1.0 + std::abs(u)) || std::abs(f) < 1e-14) break;
  }
  return u;
}

// OpenSim's findClosestPoint; false when a quadrant excludes both candidates
bool findClosestCirclePoint(double radius, const Vec3& p1, const Vec3& p2, int axis, int sign,
                            Vec3& c) {
  const double mag = (p2 - p1).norm();
  const Vec3 n12 = (p2 - p1) / mag;
  const Vec3 a1 = p1 + solveFromStart(p1, n12, radius) * n12;
  const Vec3 a2 = p2 + solveFromStart(p2, -n12, radius) * (-n12);
  auto dist = [&](const Vec3& x) {
    return std::sqrt(x.squaredNorm() + radius * radius - 2.0 * radius * std::hypot(x[0], x[1]));
  };
  const double d1 = dist(a1), d2 = dist(a2);
  bool first;
  if (sign != 0) {
    const bool ok1 = dsign(a1[axis]) == sign, ok2 = dsign(a2[axis]) == sign;
    if (ok1 && ok2)
      first = d1 < d2;
    else if (ok1)
      first = true;
    else if (ok2)
      first = false;
    else
      return false;
  } else {
    first = d1 < d2;
  }
  // the circle point above the chosen line point
  const Vec3& x = first ? a1 : a2;
  const double m = std::hypot(x[0], x[1]);
  c = Vec3(x[0] * radius / m, x[1] * radius / m, 0.0);
  return true;
}

}  // namespace

void wrapTorus(const WrapSurface& s, const Vec3& p1, const Vec3& p2, bool single_wrap,
               WrapResult& r) {
  r.code = WrapCode::NoWrap;
  Vec3 c;
  if (!findClosestCirclePoint(s.outer_radius, p1, p2, s.quadrant_axis, s.quadrant_sign, c)) return;
  if (!c.allFinite()) return;
  // cylinder frame k at c: x toward the torus centre, y = -z of the torus, z = x cross y (the
  // circle's tangent); p_k = R_kt (p_t - c)
  Vec3 xk;
  normalizeOrZero(-c, xk);
  const Vec3 yk(0.0, 0.0, -1.0);
  const Vec3 zk = xk.cross(yk);
  Mat3 R_kt;
  R_kt.row(0) = xk.transpose();
  R_kt.row(1) = yk.transpose();
  R_kt.row(2) = zk.transpose();
  const Vec3 q1 = R_kt * (p1 - c), q2 = R_kt * (p2 - c);
  WrapResult rc;
  wrapCylinder(s.inner_radius, kCylinderLength, 0, +1, q1, q2, single_wrap, rc);
  if (!rc.wraps()) return;  // OpenSim reports "wrapped" with no points here, which adds nothing
  r = rc;
  r.r1 = R_kt.transpose() * rc.r1 + c;
  r.r2 = R_kt.transpose() * rc.r2 + c;
  r.arc_center = R_kt.transpose() * rc.arc_center + c;
  r.arc_axis = R_kt.transpose() * rc.arc_axis;
  r.code = WrapCode::Wrapped;  // OpenSim's torus always returns "wrapped"
}

}  // namespace redmax::detail
