// WrapTorus as OpenSim computes it (docs/opensim_compatibility.md §6): the point of the centre circle
// nearest the muscle line (searched from each end, the better of the two, quadrant-aware) carries
// a long cylinder of the tube radius, tangent to the circle, with quadrant "+x" toward the torus
// centre; the cylinder code does the rest. The search and the frame are constructions.hpp's,
// shared with the smooth model.
#include <algorithm>
#include <cmath>

#include "core/geometry/wrap_math.hpp"

namespace redmax::detail {

double torusSolveFromStart(const Vec3& p, const Vec3& n, double r) {
  const V3<double> pv = constant<double>(p), nv = constant<double>(n);
  auto res = [&](double u) {
    double f, fu;
    torusResidual(pv, nv, r, u, f, fu);
    return f;
  };
  double u = 0.0, f = res(u), bound = 0.2;
  for (int it = 0; it < 500 && std::isfinite(f); ++it) {
    const double h = 1e-7 * (1.0 + std::abs(u));
    const double df = (res(u + h) - res(u - h)) / (2 * h);
    double step = (df != 0.0 && std::isfinite(df)) ? -f / df : (f > 0 ? -bound : bound);
    if (std::abs(step) > bound) step = step > 0 ? bound : -bound;
    // halve until |residual| decreases (as a trust region would)
    bool accepted = false;
    for (int k = 0; k < 60; ++k) {
      const double fn = res(u + step);
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

bool torusAnchorSearch(const WrapSurface& s, const Vec3& p1, const Vec3& p2, double& u1, double& u2, bool& first) {
  const double radius = s.outer_radius;
  const Vec3 n12 = (p2 - p1).normalized();
  u1 = torusSolveFromStart(p1, n12, radius);
  u2 = torusSolveFromStart(p2, -n12, radius);
  const Vec3 a1 = p1 + u1 * n12, a2 = p2 - u2 * n12;
  auto dist = [&](const Vec3& x) {
    return std::sqrt(x.squaredNorm() + radius * radius - 2.0 * radius * std::hypot(x[0], x[1]));
  };
  first = dist(a1) < dist(a2);
  if (s.quadrant_sign != 0) {
    const bool ok1 = dsign(a1[s.quadrant_axis]) == s.quadrant_sign, ok2 = dsign(a2[s.quadrant_axis]) == s.quadrant_sign;
    if (!ok1 && !ok2) return false;
    if (ok1 != ok2) first = ok1;
  }
  return true;
}

void wrapTorus(const WrapSurface& s, const Vec3& p1, const Vec3& p2, bool single_wrap,
               WrapResult& r) {
  r.code = WrapCode::NoWrap;
  double u1, u2;
  bool first;
  if (!torusAnchorSearch(s, p1, p2, u1, u2, first)) return;
  const Vec3 n12 = (p2 - p1).normalized();
  const Vec3 x = first ? Vec3(p1 + u1 * n12) : Vec3(p2 - u2 * n12);
  TorusFrame<double> f;
  if (!makeTorusFrame(s.outer_radius, constant<double>(x), constant<double>(p1), constant<double>(p2), f)) return;
  if (!values(f.c).allFinite()) return;
  // the cylinder in the frame k at the anchor; its result back in the torus frame
  const WrapSurface cyl = torusCylinder(s);
  WrapResult rc;
  wrapCylinder(cyl.radius, cyl.length, cyl.quadrant_axis, cyl.quadrant_sign, values(f.q1), values(f.q2), single_wrap,
               rc);
  if (!rc.wraps()) return;  // OpenSim reports "wrapped" with no points here, which adds nothing
  r = rc;
  r.r1 = values(f.toTorus(constant<double>(rc.r1)));
  r.r2 = values(f.toTorus(constant<double>(rc.r2)));
  r.arc_center = values(f.toTorus(constant<double>(rc.arc_center)));
  r.arc_axis = values(f.directionToTorus(constant<double>(rc.arc_axis)));
  r.code = WrapCode::Wrapped;  // OpenSim's torus always returns "wrapped"
}

}  // namespace redmax::detail
