#pragma once
// The exact library's tangent-point constructions over any scalar T (double, or the dual numbers
// of dual.hpp): the cylinder's candidates, OpenSim's choice among them and the slide into the
// plane through the apex; the sphere's wrapping plane, tangent points and arc; the torus's search
// for the centre-circle point nearest the line and its local cylinder frame. The exact library
// (cylinder.cpp, sphere.cpp, torus.cpp) runs them on double; the smooth wrap model
// (core/muscles/wrap/smooth.cpp) on Jet numbers for exact J and Jdot. Discrete choices (which
// candidate, which side, whether a point slides) are decided on values, so T only carries
// derivatives through the continuous parts. All in the surface frame; see wrap_surface.hpp for the
// OpenSim behaviours reproduced.
#include <cmath>
#include <limits>

#include "core/geometry/dual.hpp"
#include "core/geometry/wrap_surface.hpp"

namespace redmax::detail {

/// OpenSim's DSIGN: +1 for v >= 0, -1 otherwise
inline int dsign(double v) { return v >= 0.0 ? 1 : -1; }

/// v / |v|, or zero when |v| is below the machine epsilon (OpenSim's threshold)
template <class T>
V3<T> normalizeOrZero(const V3<T>& v) {
  const T n = norm(v);
  if (!(value(n) >= std::numeric_limits<double>::epsilon())) return {T(0.0), T(0.0), T(0.0)};
  return (1.0 / n) * v;
}

/// Of the candidate pairs (1a 2a, 1a 2b, 1b 2a, 1b 2b), the index 0..3 of the one whose unit
/// directions agree best (OpenSim's unconstrained choice; ties go to the later pair).
inline int closestCandidatePair(const Vec3& u1a, const Vec3& u1b, const Vec3& u2a, const Vec3& u2b) {
  const double d1 = u1a.dot(u2a), d2 = u1a.dot(u2b), d3 = u1b.dot(u2a), d4 = u1b.dot(u2b);
  if (d1 > d2 && d1 > d3 && d1 > d4) return 0;
  if (d2 > d3 && d2 > d4) return 1;
  if (d3 > d4) return 2;
  return 3;
}

// ---------------------------------------------------------------------------------------------
// cylinder: axis z through the origin, radius R

/// The two tangent candidates a, b from p in the plane through p normal to the axis; pa = p's
/// foot on the axis, rho = p's distance from it.
template <class T>
void cylinderTangentCandidates(double R, const V3<T>& p, V3<T>& pa, V3<T>& a, V3<T>& b, T& rho) {
  pa = {T(0.0), T(0.0), p[2]};
  const V3<T> radial{p[0], p[1], T(0.0)};
  rho = norm(radial);
  const V3<T> vv = (1.0 / rho) * radial;
  const T dist = R * (R / rho);
  const V3<T> pp = pa + dist * vv;
  const T dist2 = dsqrt(R * R - dist * dist);
  const V3<T> uu = cross(zAxis<T>(), vv);
  a = pp + dist2 * uu;
  b = pp - dist2 * uu;
}

/// OpenSim's tangent points r1 (p1 side), r2 (p2 side) on a cylinder of radius R and length L
/// with quadrant axis/sign (sign 0: none): the candidate pair (unconstrained: the best-agreeing
/// radial directions; constrained: OpenSim's table over which candidates lie on the active side,
/// with its long-wrap test), each then slid along the axis into the plane through p1, p2 and
/// OpenSim's apex (the plane through p1, p2 and the axis point) when that moves it toward the
/// other end. long_wrap: the arc goes more than
/// half way round. False when both tangent points lie beyond the ends (|z| > L/2): no wrap.
template <class T>
bool cylinderTangentPoints(double R, double L, int axis, int sign, const V3<T>& p1, const V3<T>& p2, V3<T>& r1,
                           V3<T>& r2, bool& long_wrap) {
  V3<T> p11, p22, r1a, r1b, r2a, r2b;
  T rho1, rho2;
  cylinderTangentCandidates(R, p1, p11, r1a, r1b, rho1);
  cylinderTangentCandidates(R, p2, p22, r2a, r2b, rho2);
  long_wrap = false;
  if (sign == 0) {
    const Vec3 u1a = (values(r1a) - values(p11)).normalized(), u1b = (values(r1b) - values(p11)).normalized();
    const Vec3 u2a = (values(r2a) - values(p22)).normalized(), u2b = (values(r2b) - values(p22)).normalized();
    const int k = closestCandidatePair(u1a, u1b, u2a, u2b);
    r1 = k < 2 ? r1a : r1b;
    r2 = k % 2 == 0 ? r2a : r2b;
  } else {
    const Vec3 r1am = values(r1a) - values(p11), r1bm = values(r1b) - values(p11);
    const Vec3 r2am = values(r2a) - values(p22), r2bm = values(r2b) - values(p22);
    const double al = std::acos(r1am.dot(r2bm) / (r1am.norm() * r2bm.norm()));
    const double be = std::acos(r1bm.dot(r2am) / (r1bm.norm() * r2am.norm()));
    const bool a1 = dsign(value(r1a[axis])) == sign, b1 = dsign(value(r1b[axis])) == sign;
    const bool a2 = dsign(value(r2a[axis])) == sign, b2 = dsign(value(r2b[axis])) == sign;
    // (OpenSim's far-side flag only chose its apex, whose plane is the one through the axis point)
    auto pick_ba = [&] { r1 = r1b, r2 = r2a; };
    auto pick_ab = [&] { r1 = r1a, r2 = r2b; };
    // OpenSim's case table over which candidates lie on the active side
    if (a1 && b1) {
      if (a2) pick_ba();
      else pick_ab();
    } else if (a1 && !b1) {
      pick_ab();
    } else if (!a1 && b1) {
      pick_ba();
    } else if (a2) {
      pick_ba();
    } else if (b2) {
      pick_ab();
    } else {
      if (al > be) r1 = r1a, r2 = r2b;
      else r1 = r1b, r2 = r2a;
    }
    // a long wrap (more than half way round)
    const Vec3 sum_musc = (values(r1) - values(p1)) + (values(r2) - values(p2));
    const Vec3 sum_r = (values(r1) - values(p11)) + (values(r2) - values(p22));
    long_wrap = sum_r.dot(sum_musc) < 0.0;
  }
  // OpenSim's apex is the surface point of the axis-normal plane through the muscle line's point at
  // fraction rho1 / (rho1 + rho2), on the near (far-side wraps: far) side; only its plane is used
  const T t = rho1 / (rho1 + rho2);
  const V3<T> mpt = p1 + t * (p2 - p1);
  const V3<T> axispt{T(0.0), T(0.0), mpt[2]};
  const V3<T> l1 = normalizeOrZero(p1 - axispt), l2 = normalizeOrZero(p2 - axispt);
  const V3<T> n = normalizeOrZero(cross(l1, l2));
  // slide r1, r2 along the axis into the plane through p1, p2 and the apex: the segment r -/+ 10 z
  // meets the plane (OpenSim's segment-plane test, tolerance 1e-5; a degenerate plane slides
  // nothing). That plane is the one through p1, p2 and the axis point, normal n: the apex lies in
  // it by construction (apex - axispt is normal to n). OpenSim forms it from p1 - apex and p2 - apex,
  // which are nearly parallel whenever the muscle line passes close to the apex (a shallow
  // penetration): measured 2.5e-7 m off the line on the running leg's gastrocnemius, where that
  // normal's round-off reached 1e-9 and its second derivatives 1e-4 relative, enough to stall rk45
  // at 1e-11. The slide does not depend on the normal's sign.
  const V3<T>& pn = n;
  const T dplane = -dot(p1, pn);
  auto slide = [&](const V3<T>& r, V3<T>& out) {
    const T dp = 20.0 * pn[2];
    if (!(std::abs(value(dp)) >= 1e-5)) return false;
    const T s = (-dplane - (dot(pn, r) - 10.0 * pn[2])) / dp;
    if (value(s) < -1e-5 || value(s) > 1.0 + 1e-5) return false;
    out = {r[0], r[1], r[2] - 10.0 + 20.0 * s};
    return true;
  };
  // only toward the other end: OpenSim projects onto the line through p11 with direction p22 (it
  // passes the point p22 as the direction; the axis, up to sign)
  auto closestOnP11Line = [&](const Vec3& pt) {
    const Vec3 a = values(p11), dir = values(p22).normalized();
    return Vec3(a + (pt - a).dot(dir) * dir);
  };
  V3<T> r1p, r2p;
  const bool r1_inter = slide(r1, r1p), r2_inter = slide(r2, r2p);
  const Vec3 p11v = values(p11), p22v = values(p22);
  if (r1_inter && (closestOnP11Line(values(r1p)) - p22v).squaredNorm() < (p11v - p22v).squaredNorm()) r1 = r1p;
  if (r2_inter && (closestOnP11Line(values(r2p)) - p11v).squaredNorm() < (p22v - p11v).squaredNorm()) r2 = r2p;
  const double half = 0.5 * L;
  const double z1 = value(r1[2]), z2 = value(r2[2]);
  return !((z1 < -half || z1 > half) && (z2 < -half || z2 > half));
}

/// Signed rotation about +z that takes r1 to r2 along the cylinder's helix: the short way, or for
/// a long wrap the long way round, turning the other way.
template <class T>
T cylinderHelixAngle(const V3<T>& r1, const V3<T>& r2, bool long_wrap) {
  constexpr double kPi = 3.14159265358979323846;
  const T theta = datan2(r1[0] * r2[1] - r1[1] * r2[0], r1[0] * r2[0] + r1[1] * r2[1]);
  return long_wrap ? -(2.0 * kPi - theta) : theta;
}

// ---------------------------------------------------------------------------------------------
// sphere: centre at the origin, radius R

/// Unit normal of the wrapping plane through p1, p2 and the centre. For a line through the centre
/// (within 1e-5) OpenSim reuses the previous wrap's plane; history-free, we take the plane holding
/// the line and the coordinate axis least aligned with it.
template <class T>
V3<T> sphereWrapPlaneNormal(const V3<T>& p1, const V3<T>& p2) {
  const V3<T> p1p2 = normalizeOrZero(p1 - p2);
  V3<T> hp2 = cross(p1p2, normalizeOrZero(p2));
  if (values(hp2).norm() < 1e-5) {
    const Vec3 d = values(p1p2);
    int k = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs(d[i]) < std::abs(d[k])) k = i;
    hp2 = cross(p1p2, constant<T>(Vec3::Unit(k)));
  }
  return normalizeOrZero(hp2);
}

/// The two points of tangency seen from p (outside the sphere) in the plane with unit normal n:
/// p + |p| cos(a) (cos(a) y -/+ sin(a) z), y toward the centre, z = n x y, sin(a) = R / |p|.
template <class T>
void sphereTangentPoints(double R, const V3<T>& p, const V3<T>& n, V3<T>& a, V3<T>& b) {
  const V3<T> y = normalizeOrZero((-1.0) * p);
  const V3<T> z = cross(n, y);
  const T pn = norm(p);
  const T ang = dasin(R / pn);
  const T c = dcos(ang), s = dsin(ang);
  a = p + (pn * c) * (c * y - s * z);
  b = p + (pn * c) * (c * y + s * z);
}

/// The short great-circle arc from r1 to r2: its angle and unit axis (n, the wrapping plane's
/// normal, when r1 and r2 are parallel).
template <class T>
void sphereArc(const V3<T>& r1, const V3<T>& r2, const V3<T>& n, T& angle, V3<T>& axis) {
  const V3<T> r1n = normalizeOrZero(r1), r2n = normalizeOrZero(r2);
  angle = dacos(dot(r1n, r2n));
  const V3<T> ax = normalizeOrZero(cross(r1n, r2n));
  axis = values(ax).squaredNorm() > 0.0 ? ax : n;
}

// ---------------------------------------------------------------------------------------------
// torus: centre circle of radius `outer_radius` in the xy plane, tube radius `inner_radius`

/// The torus's local cylinder: radius inner_radius, length 1e4, quadrant +x (toward the centre).
inline WrapSurface torusCylinder(const WrapSurface& s) {
  return WrapSurface::makeCylinder(s.inner_radius, 10000.0, 0, +1);
}

/// OpenSim's residual along the line p + u n: d/du of |x|^2 - 4 r |x_xy|, i.e. the squared
/// distance to a circle of radius 2r (OpenSim's factor, reproduced), zero at the point it takes as
/// nearest; with its first and (if asked) second u-derivatives.
template <class T>
void torusResidual(const V3<T>& p, const V3<T>& n, double r, const T& u, T& f, T& fu, T* fuu = nullptr) {
  const T c2 = 2.0 * dot(p, n);
  const T c3 = p[0] * n[0] + p[1] * n[1];
  const T c4 = n[0] * n[0] + n[1] * n[1];
  const T c5 = p[0] * p[0] + p[1] * p[1];
  const T q = u * u * c4 + 2.0 * c3 * u + c5;
  const T sq = dsqrt(q);
  const T qu = 2.0 * c4 * u + 2.0 * c3;
  f = c2 + 2.0 * u - 2.0 * r * qu / sq;
  fu = 2.0 - 2.0 * r * (2.0 * c4 / sq - qu * qu / (2.0 * q * sq));
  if (fuu) {
    const T s3 = q * sq;
    *fuu = -2.0 * r * (-3.0 * c4 * qu / s3 + 0.75 * qu * qu * qu / (s3 * q));
  }
}

/// OpenSim's search along p + u n from u = 0 (MINPACK lmdif there, step bound 0.2, tolerance
/// 1e-4; here damped Newton steps converged to ~1e-12): a root of torusResidual, or where it has
/// none near, the point where |residual| stops falling.
double torusSolveFromStart(const Vec3& p, const Vec3& n, double r);

/// OpenSim's findClosestPoint: the parameters u1 along p1 + u n12 and u2 along p2 - u n12 (n12 the
/// unit direction p1 -> p2) of the line points each end's search finds, and which one is kept
/// (`first`: u1; the nearer to the circle, quadrant-aware). False when a quadrant excludes both.
bool torusAnchorSearch(const WrapSurface& s, const Vec3& p1, const Vec3& p2, double& u1, double& u2, bool& first);

/// The local cylinder's frame k at the circle point c (x toward the torus centre, y = -z of the
/// torus, z = x cross y, the circle's tangent) and the end points in it.
template <class T>
struct TorusFrame {
  V3<T> c, xk, yk, zk, q1, q2;
  V3<T> toTorus(const V3<T>& q) const { return c + q[0] * xk + q[1] * yk + q[2] * zk; }
  V3<T> directionToTorus(const V3<T>& v) const { return v[0] * xk + v[1] * yk + v[2] * zk; }
};

/// The frame at the circle point above the line point x (circle radius `radius`); false for a
/// degenerate anchor (x on the torus axis).
template <class T>
bool makeTorusFrame(double radius, const V3<T>& x, const V3<T>& p1, const V3<T>& p2, TorusFrame<T>& f) {
  const T m = dsqrt(x[0] * x[0] + x[1] * x[1]);
  if (!(value(m) > 0.0) || !std::isfinite(value(m))) return false;
  f.c = {x[0] * (radius / m), x[1] * (radius / m), T(0.0)};
  f.xk = normalizeOrZero((-1.0) * f.c);
  f.yk = {T(0.0), T(0.0), T(-1.0)};
  f.zk = cross(f.xk, f.yk);
  auto toK = [&](const V3<T>& q) {
    const V3<T> r = q - f.c;
    return V3<T>{dot(f.xk, r), dot(f.yk, r), dot(f.zk, r)};
  };
  f.q1 = toK(p1);
  f.q2 = toK(p2);
  return true;
}

}  // namespace redmax::detail
