// WrapSphere as OpenSim computes it (docs/opensim_compatibility.md §6): tangent points in the plane through
// P1, P2 and the centre, a great-circle arc between them (constructions.hpp, shared with the
// smooth model), and OpenSim's quadrant handling (including the negative length of far-side
// wraps).
#include <cmath>

#include "core/geometry/wrap_math.hpp"

namespace redmax::detail {

void wrapSphere(const WrapSurface& s, const Vec3& p1, const Vec3& p2, WrapResult& r) {
  constexpr double kPi = 3.14159265358979323846;
  const double R = s.radius;
  const int axis = s.quadrant_axis, sign = s.quadrant_sign;
  WrapCode code = WrapCode::Wrapped;
  bool far_side_wrap = false;
  r.code = WrapCode::NoWrap;

  if (p1.norm() < R || p2.norm() < R) {
    r.code = WrapCode::InsideRadius;
    return;
  }

  // the segment must cross the sphere: both roots of |p2 + l (p1 - p2)|^2 = R^2 in (0, 1)
  const Vec3 ri = p1 - p2, mp = -p2;
  const double a = ri.dot(ri), b = -2.0 * mp.dot(ri), c = mp.dot(mp) - R * R;
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return;
  const double l1 = (-b + std::sqrt(disc)) / (2.0 * a), l2 = (-b - std::sqrt(disc)) / (2.0 * a);
  if (!(0.0 < l1 && l1 < 1.0) || !(0.0 < l2 && l2 < 1.0)) return;

  const V3<double> q1 = constant<double>(p1), q2 = constant<double>(p2);
  const V3<double> n = sphereWrapPlaneNormal(q1, q2);
  V3<double> c1a, c1b, c2a, c2b;
  sphereTangentPoints(R, q1, n, c1a, c1b);
  sphereTangentPoints(R, q2, n, c2a, c2b);
  const Vec3 r1a = values(c1a), r1b = values(c1b), r2a = values(c2a), r2b = values(c2b);
  Vec3 u1a, u1b, u2a, u2b;
  normalizeOrZero(r1a, u1a);
  normalizeOrZero(r1b, u1b);
  normalizeOrZero(r2a, u2a);
  normalizeOrZero(r2b, u2b);

  // unconstrained choice: the pair closest together on the sphere; o1, o2 the candidates not chosen
  const int k = closestCandidatePair(u1a, u1b, u2a, u2b);
  const Vec3* o1 = k < 2 ? &r1b : &r1a;
  const Vec3* o2 = k % 2 == 0 ? &r2b : &r2a;
  r.r1 = k < 2 ? r1a : r1b;
  r.r2 = k % 2 == 0 ? r2a : r2b;

  if (sign != 0) {
    const bool s1 = dsign(p1[axis]) == sign, s2 = dsign(p2[axis]) == sign;
    if (s1 || s2) {
      // OpenSim's intersection test: tt is a distance along the unit direction, compared with 1
      // as if it were a fraction (reproduced as is)
      Vec3 p1p2, mm;
      normalizeOrZero(p1 - p2, p1p2);
      double tt;
      closestPointOnLine(Vec3::Zero(), p1, p1p2, mm, tt);
      tt = -tt;
      if (mm.squaredNorm() < R * R && tt > 0.0 && tt < 1.0)
        code = WrapCode::MandatoryWrap;
      else if (dsign(p1[axis]) != dsign(p2[axis]) && dsign(mm[axis]) != sign)
        code = WrapCode::Wrapped;
      else
        return;
    }
    if (!s1 || !s2) {
      const Vec3 wrapaxis = sign * Vec3::Unit(axis);
      Vec3 sum_musc;
      normalizeOrZero(-p1 - p2, sum_musc);
      if (u1a.dot(sum_musc) > u1b.dot(sum_musc)) {
        r.r1 = r1a; o1 = &r1b;
      } else {
        r.r1 = r1b; o1 = &r1a;
      }
      if (u2a.dot(sum_musc) > u2b.dot(sum_musc)) {
        r.r2 = r2a; o2 = &r2b;
      } else {
        r.r2 = r2b; o2 = &r2a;
      }
      // flip to the active side when the muscle would bend away from it
      normalizeOrZero((r.r1 - p1) + (r.r2 - p2), sum_musc);
      if (sum_musc.dot(wrapaxis) < 0.0) {
        r.r1 = *o1;
        r.r2 = *o2;
      }
      const Vec3 sm = (r.r1 - p1) + (r.r2 - p2), sr = r.r1 + r.r2;
      if (sr.dot(sm) < 0.0) far_side_wrap = true;
    }
  }

  // the arc from r1 to r2: the short way about r1n x r2n, or the long way back
  double angle;
  V3<double> ax;
  sphereArc(constant<double>(r.r1), constant<double>(r.r2), n, angle, ax);
  r.arc = ArcKind::Helix;
  r.arc_center = Vec3::Zero();
  r.arc_axis = values(ax);
  r.arc_rise = 0.0;
  if (far_side_wrap) angle = -(2.0 * kPi - angle);
  r.far_side = far_side_wrap;
  r.arc_angle = angle;
  r.length = R * angle;
  r.code = code;
}

}  // namespace redmax::detail
