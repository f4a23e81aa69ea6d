// WrapSphere as OpenSim computes it (docs/opensim_compatibility.md §6): tangent points in the plane through
// P1, P2 and the centre, a great-circle arc between them, and OpenSim's quadrant handling
// (including the negative length of far-side wraps).
#include <cmath>

#include "core/muscles/wrap/wrap_geometry.hpp"

namespace redmax::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

// the two points of tangency seen from p (outside the sphere), in the plane with normal n:
// p + |p| cos(a) (cos(a) y -/+ sin(a) z), y toward the centre, z = n x y, sin(a) = R / |p|
void tangentPoints(double R, const Vec3& p, const Vec3& n, Vec3& a, Vec3& b) {
  Vec3 y;
  normalizeOrZero(-p, y);
  const Vec3 z = n.cross(y);
  const double pn = p.norm();
  const double ang = std::asin(R / pn);
  a = p + pn * std::cos(ang) * (std::cos(ang) * y - std::sin(ang) * z);
  b = p + pn * std::cos(ang) * (std::cos(ang) * y + std::sin(ang) * z);
}

}  // namespace

void wrapSphere(const WrapSurface& s, const Vec3& p1, const Vec3& p2, WrapResult& r) {
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

  Vec3 p1p2, np2;
  normalizeOrZero(p1 - p2, p1p2);
  normalizeOrZero(p2, np2);
  Vec3 hp2 = p1p2.cross(np2);
  Vec3 n;
  if (hp2.norm() < 1e-5) {
    // the line passes (almost) through the centre: OpenSim reuses the previous wrap's tangent
    // points; we are history-free and take the plane containing the line and the coordinate axis
    // least aligned with it
    int k = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs(p1p2[i]) < std::abs(p1p2[k])) k = i;
    hp2 = p1p2.cross(Vec3::Unit(k));
  }
  normalizeOrZero(hp2, n);

  Vec3 r1a, r1b, r2a, r2b;
  tangentPoints(R, p1, n, r1a, r1b);
  tangentPoints(R, p2, n, r2a, r2b);
  Vec3 u1a, u1b, u2a, u2b;
  normalizeOrZero(r1a, u1a);
  normalizeOrZero(r1b, u1b);
  normalizeOrZero(r2a, u2a);
  normalizeOrZero(r2b, u2b);

  // unconstrained choice: the pair closest together on the sphere
  const Vec3 *o1, *o2;  // the candidates not chosen
  {
    const double j1 = u1a.dot(u2a), j2 = u1a.dot(u2b), j3 = u1b.dot(u2a), j4 = u1b.dot(u2b);
    if (j1 > j2 && j1 > j3 && j1 > j4) {
      r.r1 = r1a; r.r2 = r2a; o1 = &r1b; o2 = &r2b;
    } else if (j2 > j3 && j2 > j4) {
      r.r1 = r1a; r.r2 = r2b; o1 = &r1b; o2 = &r2a;
    } else if (j3 > j4) {
      r.r1 = r1b; r.r2 = r2a; o1 = &r1a; o2 = &r2b;
    } else {
      r.r1 = r1b; r.r2 = r2b; o1 = &r1a; o2 = &r2a;
    }
  }

  if (sign != 0) {
    const bool s1 = dsign(p1[axis]) == sign, s2 = dsign(p2[axis]) == sign;
    if (s1 || s2) {
      // OpenSim's intersection test: tt is a distance along the unit direction, compared with 1
      // as if it were a fraction (reproduced as is)
      Vec3 mm;
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

  Vec3 r1n, r2n;
  normalizeOrZero(r.r1, r1n);
  normalizeOrZero(r.r2, r2n);
  double angle = std::acos(r1n.dot(r2n));
  Vec3 ax;
  normalizeOrZero(r1n.cross(r2n), ax);
  // the arc from r1 to r2: the short way about r1n x r2n, or the long way back
  r.arc = ArcKind::Helix;
  r.arc_center = Vec3::Zero();
  r.arc_axis = ax.squaredNorm() > 0.0 ? ax : Vec3(n);
  r.arc_rise = 0.0;
  if (far_side_wrap) angle = -(2.0 * kPi - angle);
  r.arc_angle = angle;
  r.length = R * angle;
  r.code = code;
}

}  // namespace redmax::detail
