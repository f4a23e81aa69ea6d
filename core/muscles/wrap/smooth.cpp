#include "core/muscles/wrap/smooth.hpp"
#include "core/muscles/wrap/smooth_jet.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "core/geometry/constructions.hpp"
#include "core/geometry/dual.hpp"

namespace redmax {
namespace {

using namespace detail;  // dual numbers and the shared constructions

constexpr double kPi = 3.14159265358979323846;
// quadrant cylinders: the band narrows where the line's point nearest the axis is closer than
// this many radii to the quadrant plane (see smoothPoint)
constexpr double kQuadrantBlend = 0.25;

// alpha may be a constant or carry derivatives of its own (the same scalar type as the points)
template <class T> using Alpha = std::type_identity_t<T>;

// the path p1 -> r1 -> arc -> r2 -> p2, the arc turning r1 about the unit axis k through the
// origin by angle phi (with rise h along k): the library's calcWrappedPathPoint, with its
// alpha-independent lengths kept so that a muscle's mass points share them
template <class T>
struct ArcPath {
  V3<T> p1{}, p2{}, r1{}, r2{}, k{};
  T phi{}, h{}, l1{}, la{}, l2{}, total{};  // total: the geometric length |p1 r1| + arc + |r2 p2|
  // shared by the points (issue 18: a point then costs a sine, a cosine and ten products): the
  // pieces' directions, r1 = kr + u about k with k x r1 = kxr, and each piece's fraction f as
  // alpha * scale - offset (f = (alpha total - start) / piece length)
  V3<T> d1{}, d2{}, kr{}, u{}, kxr{};
  T f1{}, fa{}, fa0{}, f2{}, f20{};
};

template <class T>
ArcPath<T> makeArcPath(const V3<T>& p1, const V3<T>& p2, const V3<T>& r1, const V3<T>& r2, const V3<T>& k,
                       const T& phi, const T& h) {
  ArcPath<T> a{p1, p2, r1, r2, k, phi, h};
  a.l1 = norm(r1 - p1);
  const V3<T> r1_perp = r1 - dot(r1, k) * k;
  const T rho_phi = norm(r1_perp) * phi;
  a.la = dsqrt(rho_phi * rho_phi + h * h);
  a.l2 = norm(p2 - r2);
  a.total = a.l1 + a.la + a.l2;
  a.d1 = r1 - p1;
  a.d2 = p2 - r2;
  a.kr = dot(k, r1) * k;
  a.u = r1 - a.kr;
  a.kxr = cross(k, r1);
  // (a zero-length piece is never evaluated: the branches below test the values first)
  if (value(a.l1) > 0.0) a.f1 = a.total / a.l1;
  if (value(a.la) > 0.0) a.fa = a.total / a.la, a.fa0 = a.l1 / a.la;
  if (value(a.l2) > 0.0) a.f2 = a.total / a.l2, a.f20 = (a.l1 + a.la) / a.l2;
  return a;
}

// point at fraction alpha of the path (the branches on values as s = alpha total, less each
// piece's length, walks along it)
template <class T>
V3<T> arcPathPoint(const ArcPath<T>& a, const Alpha<T>& alpha) {
  double s = value(alpha) * value(a.total);
  if (s <= value(a.l1)) return a.p1 + (alpha * a.f1) * a.d1;
  s = s - value(a.l1);
  if (s <= value(a.la)) {
    const T f = alpha * a.fa - a.fa0;
    const T th = f * a.phi;
    return a.kr + dcos(th) * a.u + dsin(th) * a.kxr + (f * a.h) * a.k;
  }
  s = s - value(a.la);
  return s / value(a.l2) < 1.0 ? a.r2 + (alpha * a.f2 - a.f20) * a.d2 : a.p2;
}

// ---------------------------------------------------------------------------------------------
// penetration of the straight segment into the surface (see the header)

template <class T>
T penetration(const WrapSurface& surf, const V3<T>& p1, const V3<T>& p2) {
  const V3<T> u = p2 - p1;
  if (surf.type == WrapType::Cylinder) {
    // distance between the segment's line and the axis, where they come closest (2D projection)
    const T ux = u[0], uy = u[1];
    const T uu = ux * ux + uy * uy;
    if (!(value(uu) > 1e-300)) return T(-1.0);  // parallel to the axis: the library never wraps
    const T t = -(p1[0] * ux + p1[1] * uy) / uu;
    const T cx = p1[0] + t * ux, cy = p1[1] + t * uy;
    const T d = surf.radius - dsqrt(cx * cx + cy * cy);
    if (value(t) > 0.0 && value(t) < 1.0) return d;
    return value(d) > 0.0 ? -d : d;
  }
  if (surf.type == WrapType::Ellipsoid) {
    // in coordinates divided by the semi-axes the ellipsoid is the unit sphere: 1 - distance of
    // the line from the centre there, in units of the smallest semi-axis
    const Vec3& s = surf.dimensions;
    const V3<T> q1{p1[0] / s[0], p1[1] / s[1], p1[2] / s[2]};
    const V3<T> uq{u[0] / s[0], u[1] / s[1], u[2] / s[2]};
    const T t = -dot(q1, uq) / dot(uq, uq);
    const T d = s.minCoeff() * (1.0 - norm(q1 + t * uq));
    if (value(t) > 0.0 && value(t) < 1.0) return d;
    return value(d) > 0.0 ? -d : d;
  }
  // sphere: distance from the centre to the line
  const T t = -dot(p1, u) / dot(u, u);
  const V3<T> c = p1 + t * u;
  const T d = surf.radius - norm(c);
  if (value(t) > 0.0 && value(t) < 1.0) return d;
  return value(d) > 0.0 ? -d : d;
}

// ---------------------------------------------------------------------------------------------
// the exact library's cylinder, single wrap, over any scalar: its tangent points
// (core/geometry/constructions.hpp, the code the library runs on double) and the helix. Returns
// false when the library would not wrap for a reason other than penetration (both tangent points
// beyond the cylinder's ends).
template <class T>
bool cylinderSetup(const WrapSurface& surf, const V3<T>& p1, const V3<T>& p2, ArcPath<T>& path) {
  V3<T> r1, r2;
  bool long_wrap = false;
  if (!cylinderTangentPoints(surf.radius, surf.length, surf.quadrant_axis, surf.quadrant_sign, p1, p2, r1, r2,
                             long_wrap))
    return false;
  // helix about the axis
  const T theta = cylinderHelixAngle(r1, r2, long_wrap);
  path = makeArcPath(p1, p2, r1, r2, zAxis<T>(), theta, r2[2] - r1[2]);
  return true;
}

// the exact library's sphere over any scalar (constructions.hpp, as core/geometry/sphere.cpp).
// Without a quadrant the pair of tangent candidates closest together; with one, the library's
// own choice (core/geometry/sphere.cpp: with an end on the inactive side the candidates facing
// away from the ends' midpoint, flipped to the others when the path would bend away from the
// active side, and the long way round where the arc faces away from the ends), taken from a run of
// the library on values: the candidates it picked and its far-side decision, over T the same
// construction. Returns false where the library's quadrant test gives no wrap although the
// segment crosses the sphere (an end on the active side, the line's point nearest the centre
// more than 1 m (OpenSim's distance-as-fraction test) from p1, and not the ends on opposite sides
// with that point on the inactive side): the library's own jump, not smoothed.
template <class T>
bool sphereSetup(const WrapSurface& surf, const V3<T>& p1, const V3<T>& p2, ArcPath<T>& path) {
  const double R = surf.radius;
  const V3<T> n = sphereWrapPlaneNormal(p1, p2);
  V3<T> r1a, r1b, r2a, r2b;
  sphereTangentPoints(R, p1, n, r1a, r1b);
  sphereTangentPoints(R, p2, n, r2a, r2b);
  bool first_a, second_a, far_side = false;
  if (surf.quadrant_sign == 0) {
    const int k = closestCandidatePair(values(r1a).normalized(), values(r1b).normalized(), values(r2a).normalized(),
                                       values(r2b).normalized());
    first_a = k < 2;
    second_a = k % 2 == 0;
  } else {
    const WrapResult lib = calcWrap(surf, values(p1), values(p2));
    if (!lib.wraps()) return false;
    // the library's candidates are these, computed by the same code on doubles: the nearer one
    // (the two from an end point outside the sphere are 2 R sqrt(1 - R^2 / |p|^2) apart)
    first_a = (lib.r1 - values(r1a)).squaredNorm() <= (lib.r1 - values(r1b)).squaredNorm();
    second_a = (lib.r2 - values(r2a)).squaredNorm() <= (lib.r2 - values(r2b)).squaredNorm();
    far_side = lib.far_side;
  }
  const V3<T>& r1 = first_a ? r1a : r1b;
  const V3<T>& r2 = second_a ? r2a : r2b;
  T angle;
  V3<T> ax;
  sphereArc(r1, r2, n, angle, ax);
  // the library's far-side wrap: the same great circle the long way round (the path's length is
  // the geometric one, as calcWrappedPathLength's, not OpenSim's negative surface length)
  if (far_side) angle = -(2.0 * kPi - angle);
  path = makeArcPath(p1, p2, r1, r2, ax, angle, T(0.0));
  return true;
}

// ---------------------------------------------------------------------------------------------
// the exact library's ellipsoid (core/geometry/ellipsoid.cpp), hybrid method, no quadrant, over any scalar.
// The library's iterative pieces become exact-derivative ones: closest points on the ellipsoid
// are found by the library's Newton iteration on values and refined over T by two Newton steps
// (implicit function theorem); the tangent points, which the library approximates by damped
// Gauss-Newton to a residual of 1e-4, are the closed-form intersection of the wrapping plane, the
// polar plane of the end point and the ellipsoid; the polyline of floor(chord / 1 mm) segments is
// replaced by its limit, the plane curve itself, with the arc length by Gauss-Legendre quadrature
// and the point at a given arc length by Newton steps (again two over T).

constexpr double kMuBlendMin = 0.7073;  // the library's constants (core/geometry/ellipsoid.cpp)
constexpr double kMuBlendMax = 0.9;
constexpr int kFanSamples = 300;
constexpr double kSvBoundaryBlend = 0.3;
constexpr int kArcPanels = 8;            // Gauss-Legendre panels over the arc (8 nodes each)

template <class T> V3<T> cdiv(const V3<T>& v, const Vec3& a) { return {v[0] / a[0], v[1] / a[1], v[2] / a[2]}; }
template <class T> T absT(const T& x) { return value(x) < 0.0 ? -x : x; }

// the library's Newton iteration for the Lagrange parameter t of the closest point on the
// ellipsoid (dims a, 3-D) or on the ellipse in the coordinates `axes` (2-D), on values; false
// when it does not converge in 64 steps (the library then leaves its output untouched)
bool closestParameter(const Vec3& a, const Vec3& q, const std::array<int, 3>& axes, int n, double& t) {
  double inside = 0.0, amax = 0.0, qq = 0.0;
  for (int k = 0; k < n; ++k) {
    const int i = axes[k];
    inside += (q[i] / a[i]) * (q[i] / a[i]);
    amax = std::max(amax, a[i]);
    qq += q[i] * q[i];
  }
  t = inside < 1.0 ? 0.0 : amax * std::sqrt(qq);
  for (int it = 0; it < 64; ++it) {
    // f = prod P_i^2 - sum_i a_i^2 q_i^2 prod_{j != i} P_j^2, P_i = t + a_i^2
    double P[3], prod = 1.0;
    for (int k = 0; k < n; ++k) {
      P[k] = t + a[axes[k]] * a[axes[k]];
      prod *= P[k] * P[k];
    }
    double f = prod, fp = 0.0;
    for (int k = 0; k < n; ++k) {
      double others = 1.0, others_d = 0.0;
      for (int j = 0; j < n; ++j) {
        if (j == k) continue;
        others_d = others_d * P[j] * P[j] + others * 2.0 * P[j];
        others *= P[j] * P[j];
      }
      const double c = a[axes[k]] * a[axes[k]] * q[axes[k]] * q[axes[k]];
      f -= c * others;
      fp -= c * others_d;
    }
    double prod_d = 0.0;
    {
      double acc = 1.0;
      for (int k = 0; k < n; ++k) {
        prod_d = prod_d * P[k] * P[k] + acc * 2.0 * P[k];
        acc *= P[k] * P[k];
      }
    }
    fp += prod_d;
    if (std::abs(f) < 1e-9) return true;
    t -= f / fp;
  }
  return false;
}

// closest point to q on the ellipsoid (n = 3) or, in the coordinates axes[0..1], on its
// cross-section ellipse (n = 2; the third coordinate is kept), refined over T from the library's
// parameter: g(t) = sum (a_i q_i / (t + a_i^2))^2 - 1 = 0
// Newton step g / g' of g(t) = sum (a_i q_i / (t + a_i^2))^2 - 1 over any scalar
template <class S, class Q>
S closestNewtonStep(const Vec3& a, const Q& q, const std::array<int, 3>& axes, int n, const S& t) {
  S g(-1.0), gp(0.0);
  for (int k = 0; k < n; ++k) {
    const int i = axes[k];
    const S e = (a[i] * q[i]) / (t + a[i] * a[i]);
    g = g + e * e;
    gp = gp - 2.0 * e * e / (t + a[i] * a[i]);
  }
  return g / gp;
}

// the library's parameter, polished on values (the library stops at |f| < 1e-9; the steps over
// T need a converged start to give exact second derivatives); false where the library's 3-D
// iteration fails (it then leaves its output untouched; its 2-D one uses the last iterate)
bool closestParameterPolished(const Vec3& a, const Vec3& q, const std::array<int, 3>& axes, int n, double& t0) {
  if (!closestParameter(a, q, axes, n, t0) && n == 3) return false;
  const V3<double> qv = constant<double>(q);
  for (int it = 0; it < 20; ++it) {
    const double step = closestNewtonStep(a, qv, axes, n, t0);
    t0 -= step;
    if (!(std::abs(step) > 1e-15 * (1.0 + std::abs(t0)))) break;
  }
  return true;
}

// the closest point from a converged parameter: two Newton steps over T
template <class T>
V3<T> closestFromParameter(const Vec3& a, const V3<T>& q, const std::array<int, 3>& axes, int n, double t0) {
  T t(t0);
  for (int step = 0; step < 2; ++step) t = t - closestNewtonStep(a, q, axes, n, t);
  V3<T> x = q;
  for (int k = 0; k < n; ++k) {
    const int i = axes[k];
    x[i] = (a[i] * a[i]) * q[i] / (t + a[i] * a[i]);
  }
  return x;
}

template <class T>
bool closestOnEllipsoid(const Vec3& a, const V3<T>& q, const std::array<int, 3>& axes, int n, V3<T>& x) {
  double t0;
  if (!closestParameterPolished(a, values(q), axes, n, t0)) return false;
  x = closestFromParameter(a, q, axes, n, t0);
  return true;
}

// the fan's closest-point parameters on values
struct FanParameters {
  std::array<double, kFanSamples> t{};
  std::array<char, kFanSamples> ok{};
};

// the tangent point from p on the ellipse cut by the plane vs.x + vs4 = 0: the plane, the polar
// plane of p (sum x_i p_i / a_i^2 = 1, where the tangent plane at x passes through p) and the
// ellipsoid; of the two, the one nearer c1 (where the library's search starts)
template <class T>
V3<T> tangentPoint(const Vec3& a, const V3<T>& p, const V3<T>& vs, const T& vs4, const Vec3& c1) {
  const Vec3 a2 = a.cwiseProduct(a);
  const V3<T> w = cdiv(p, a2);
  const T g = dot(vs, w), ww = dot(w, w), vv = dot(vs, vs);
  const T det = vv * ww - g * g;
  const T al = (-vs4 * ww - g) / det, be = (vv + g * vs4) / det;
  const V3<T> r0 = al * vs + be * w;
  const V3<T> e = cross(vs, w);
  const V3<T> r0a = cdiv(r0, a), ea = cdiv(e, a);
  const T A = dot(ea, ea), B = 2.0 * dot(r0a, ea), C = dot(r0a, r0a) - 1.0;
  const T sq = dsqrt(B * B - 4.0 * A * C);
  const V3<T> xa = r0 + ((-B + sq) / (2.0 * A)) * e, xb = r0 + ((-B - sq) / (2.0 * A)) * e;
  return (values(xa) - c1).squaredNorm() <= (values(xb) - c1).squaredNorm() ? xa : xb;
}

// the library's surface curve: rays from a0 in the plane, swept by angle phi from r1 toward r2,
// each cut with the ellipsoid; point and speed |dP/dphi|
template <class T>
struct EllipsoidArc {
  Vec3 a;
  V3<T> a0, ar1, vsy, f2;
  T phi0;
  void eval(const T& phi, V3<T>* point, T* speed) const {
    const T c = dcos(phi), s = dsin(phi);
    const V3<T> rr = c * ar1 + s * vsy;
    const V3<T> f1 = cdiv(rr, a);
    const T A = dot(f1, f1), B = 2.0 * dot(f1, f2), C = dot(f2, f2) - 1.0;
    const T mu = (-B + dsqrt(B * B - 4.0 * A * C)) / (2.0 * A);
    if (point) *point = a0 + mu * rr;
    if (speed) {
      const V3<T> drr = c * vsy - s * ar1;
      const V3<T> df1 = cdiv(drr, a);
      const T dA = 2.0 * dot(f1, df1), dB = 2.0 * dot(df1, f2);
      const T dmu = -(dA * mu * mu + dB * mu) / (2.0 * A * mu + B);
      *speed = norm(dmu * rr + mu * drr);
    }
  }
  // arc length from phi_a to phi_b: 8-point Gauss-Legendre
  T panelLength(const T& phi_a, const T& phi_b) const {
    static const double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                                0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
    static const double wq[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                                 0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
    const T half = 0.5 * (phi_b - phi_a), mid = 0.5 * (phi_a + phi_b);
    T sum(0.0);
    for (int j = 0; j < 8; ++j) {
      T sp;
      eval(mid + x[j] * half, nullptr, &sp);
      sum = sum + wq[j] * sp;
    }
    return half * sum;
  }
};

// everything of the ellipsoid path that does not depend on alpha, in the library's scaled
// coordinates
template <class T>
struct EllipsoidWrap {
  double factor = 1.0;
  V3<T> p1{}, p2{}, r1{}, r2{};
  EllipsoidArc<T> arc{};
  std::array<T, kArcPanels + 1> cum{};  // arc length at the panel boundaries phi0 k / kArcPanels
  T la{}, d1{}, d2{}, total{};
};

template <class T>
bool ellipsoidSetup(const WrapSurface& surf, const V3<T>& P1, const V3<T>& P2, EllipsoidWrap<T>& ew) {
  // the library's scaled coordinates
  const double factor = 3.0 / surf.dimensions.sum();
  const Vec3 a = surf.dimensions * factor;
  ew.factor = factor;
  const V3<T> p1 = factor * P1, p2 = factor * P2;
  ew.p1 = p1;
  ew.p2 = p2;
  const V3<T> p1p2 = p1 - p2;
  // where the chord meets the ellipsoid
  const V3<T> f1 = cdiv(p1p2, a), f2 = cdiv(p2, a);
  const T aa = dot(f1, f1), bb = 2.0 * dot(f1, f2), cc = dot(f2, f2) - 1.0;
  const T disc = bb * bb - 4.0 * aa * cc;
  if (!(value(disc) > 0.0)) return false;
  const T l1 = (-bb + dsqrt(disc)) / (2.0 * aa), l2 = (-bb - dsqrt(disc)) / (2.0 * aa);
  const V3<T> r1c = p2 + l1 * p1p2, r2c = p2 + l2 * p1p2;
  const V3<T> r1r2 = r2c - r1c;
  // the plane point c1: hybrid of the axial (Frans) cross-section and the fan
  V3<T> mu = normalize(p1p2);
  for (int i = 0; i < 3; ++i) mu[i] = absT(mu[i]);
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (value(mu[i]) > value(mu[best])) best = i;
  T mub = mu[best];
  const T tb = (0.0 - r1c[best]) / r1r2[best];
  V3<T> c1{T(0.0), T(0.0), T(0.0)};
  if (value(mub) > kMuBlendMin) {
    // fade the axial solution out as its chord point nears the chord's ends
    T sfade(1.0);
    if (value(tb) < 0.0 || value(tb) > 1.0) sfade = T(0.0);
    else if (value(tb) < kSvBoundaryBlend) sfade = tb / kSvBoundaryBlend;
    else if (value(tb) > 1.0 - kSvBoundaryBlend) sfade = (1.0 - tb) / kSvBoundaryBlend;
    if (value(sfade) < 1.0) mub = kMuBlendMin + sfade * (mub - kMuBlendMin);
  }
  if (value(mub) > kMuBlendMin) {
    const std::array<int, 3> axes{(best + 1) % 3, (best + 2) % 3, best};
    closestOnEllipsoid(a, r1c + tb * r1r2, axes, 2, c1);
  }
  const std::array<int, 3> all{0, 1, 2};
  // the fan's weight in c1 (the library's fan_weight; none without the fan)
  bool fan_used = false;
  T fan_weight(0.0);
  if (value(mub) < kMuBlendMax) {
    // solved on values once per setup (no memo across calls: core/ keeps no per-thread state)
    FanParameters fan;
    for (int i = 1; i < kFanSamples - 1; ++i)
      fan.ok[i] = closestParameterPolished(a, values(r1c + (static_cast<double>(i) / kFanSamples) * r1r2), all, 3, fan.t[i]);
    V3<T> v_sum{T(0.0), T(0.0), T(0.0)}, cp = c1;
    for (int i = 1; i < kFanSamples - 1; ++i) {
      const V3<T> svi = r1c + (static_cast<double>(i) / kFanSamples) * r1r2;
      if (fan.ok[i]) cp = closestFromParameter(a, svi, all, 3, fan.t[i]);  // else unchanged, as in the library
      v_sum = v_sum + normalize(cp - svi);
    }
    const V3<T> tc = (r1c + 0.5 * r1r2) + normalize(v_sum);
    fan_used = true;
    if (value(mub) <= kMuBlendMin) {
      closestOnEllipsoid(a, tc, all, 3, c1);
      fan_weight = T(1.0);
    } else {
      const T tt = (mub - kMuBlendMin) / (kMuBlendMax - kMuBlendMin);
      V3<T> t1 = tc;
      closestOnEllipsoid(a, tc, all, 3, t1);
      const V3<T> t2 = tt * c1 + (1.0 - tt) * t1;
      closestOnEllipsoid(a, t2, all, 3, c1);
      fan_weight = 1.0 - tt;
    }
  }
  // quadrant: c1 mirrored onto the active side, then pulled toward the quadrant plane (the
  // bisection of c1 and its mirror) by the fan weight and put back on the surface, as the library
  // does (which never pulls without the fan: core/geometry/ellipsoid.cpp)
  const int qaxis = surf.quadrant_axis, qsign = surf.quadrant_sign;
  Vec3 start;  // where the library's tangent searches start: c1 before the pull
  if (qsign != 0 && dsign(value(c1[qaxis])) != qsign) {
    c1[qaxis] = -c1[qaxis];
    start = values(c1);
    if (fan_used && value(fan_weight) > 0.0) {
      c1[qaxis] = (1.0 - fan_weight) * c1[qaxis];
      const V3<T> pulled = c1;
      closestOnEllipsoid(a, pulled, all, 3, c1);
    }
  } else {
    start = values(c1);
  }
  // the wrapping plane through p1, p2 and c1, and the tangent points in it
  const V3<T> vs = normalize(cross(p1p2, p1 - c1));
  const T vs4 = -dot(vs, c1);
  // of the two tangent points from each end, the library takes the one its search from `start`
  // converges to; with a quadrant that need not be the nearer (c1 was mirrored), so the library
  // is run on values and its roots, and its choice of the far side, are followed
  Vec3 start1 = start, start2 = start;
  bool far_side = false;
  if (qsign != 0) {
    const WrapResult lib = calcWrap(surf, values(P1), values(P2));
    if (lib.wraps() && lib.r1.allFinite() && lib.r2.allFinite()) {
      start1 = factor * lib.r1;
      start2 = factor * lib.r2;
      far_side = lib.far_side;
    }
  }
  const V3<T> r1 = tangentPoint(a, p1, vs, vs4, start1), r2 = tangentPoint(a, p2, vs, vs4, start2);
  // the surface curve from r1 to r2 (rays from a0 where the plane meets the axis most normal to it)
  int imax = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(value(vs[i])) > std::abs(value(vs[imax]))) imax = i;
  EllipsoidArc<T> arc;
  arc.a = a;
  arc.a0 = {T(0.0), T(0.0), T(0.0)};
  arc.a0[imax] = -vs4 / vs[imax];
  arc.ar1 = normalize(r1 - arc.a0);
  const V3<T> ar2 = normalize(r2 - arc.a0);
  arc.phi0 = dacos(dot(arc.ar1, ar2));
  arc.vsy = cross(normalize(cross(arc.ar1, ar2)), arc.ar1);
  arc.f2 = cdiv(arc.a0, a);
  if (far_side) {
    // the library's far-side wrap: the same plane, swept the long way round (phi from 0 to
    // -(2 pi - phi0), i.e. 2 pi - phi0 along -vsy)
    arc.vsy = -1.0 * arc.vsy;
    arc.phi0 = 2.0 * kPi - arc.phi0;
  }
  // arc length at the panel boundaries (composite 8-point Gauss-Legendre)
  ew.cum[0] = T(0.0);
  for (int k = 0; k < kArcPanels; ++k)
    ew.cum[k + 1] = ew.cum[k] + arc.panelLength(arc.phi0 * (double(k) / kArcPanels), arc.phi0 * (double(k + 1) / kArcPanels));
  ew.arc = arc;
  ew.r1 = r1;
  ew.r2 = r2;
  ew.la = ew.cum[kArcPanels];
  ew.d1 = norm(r1 - p1);
  ew.d2 = norm(p2 - r2);
  ew.total = ew.d1 + ew.la + ew.d2;
  return true;
}

// the point at fraction alpha of p1 -> r1 -> arc -> r2 -> p2 (scaled back)
template <class T>
V3<T> ellipsoidPoint(const EllipsoidWrap<T>& ew, const Alpha<T>& alpha) {
  const EllipsoidArc<T>& arc = ew.arc;
  const T s = alpha * ew.total;
  V3<T> xs;
  if (value(s) <= value(ew.d1)) {
    xs = ew.p1 + (s / ew.d1) * (ew.r1 - ew.p1);
  } else if (value(s - ew.d1) <= value(ew.la)) {
    // the angle whose arc length is s - d1: the panel on values, Newton within it on values, then
    // two Newton steps over T
    const T target = s - ew.d1;
    const double tv = value(target);
    int k = 0;
    while (k + 1 < kArcPanels && value(ew.cum[k + 1]) < tv) ++k;
    const EllipsoidArc<double> av{arc.a, constant<double>(values(arc.a0)), constant<double>(values(arc.ar1)),
                                  constant<double>(values(arc.vsy)), constant<double>(values(arc.f2)), value(arc.phi0)};
    const double h = value(arc.phi0) / kArcPanels, lo = h * k, cum_k = value(ew.cum[k]);
    const double seg = value(ew.cum[k + 1]) - cum_k;
    double phi = lo + (seg > 0.0 ? h * (tv - cum_k) / seg : 0.0);
    for (int it = 0; it < 30; ++it) {
      double sp;
      av.eval(phi, nullptr, &sp);
      const double step = (cum_k + av.panelLength(lo, phi) - tv) / sp;
      phi -= step;
      if (!(std::abs(step) > 1e-15 * (1.0 + std::abs(phi)))) break;
    }
    T phit(phi);
    const T lot = arc.phi0 * (double(k) / kArcPanels);
    for (int step = 0; step < 2; ++step) {
      T sp;
      arc.eval(phit, nullptr, &sp);
      phit = phit - (ew.cum[k] + arc.panelLength(lot, phit) - target) / sp;
    }
    arc.eval(phit, &xs, nullptr);
  } else {
    const T f = (s - ew.d1 - ew.la) / ew.d2;
    xs = value(f) < 1.0 ? ew.r2 + f * (ew.p2 - ew.r2) : ew.p2;
  }
  return (1.0 / ew.factor) * xs;
}

// ---------------------------------------------------------------------------------------------
// the exact library's torus (core/geometry/torus.cpp, constructions.hpp): the centre-circle point nearest the line anchors a
// quadrant "+x" cylinder of the tube radius; over any scalar

// the anchor of the torus's local cylinder and the end points in its frame, the library's search
// on values refined over T; false when the library does not wrap (a quadrant excludes both
// candidates, or a degenerate anchor)
template <class T>
bool torusFrame(const WrapSurface& s, const V3<T>& p1, const V3<T>& p2, TorusFrame<T>& f) {
  const double radius = s.outer_radius;
  const Vec3 a = values(p1), b = values(p2);
  const Vec3 n12 = (b - a).normalized();
  double u1, u2;
  bool first;
  if (!torusAnchorSearch(s, a, b, u1, u2, first)) return false;
  // the chosen solution refined over T: from the converged value, each Newton step doubles the
  // order of the correct Taylor terms, so two give exact first and second derivatives (implicit
  // function theorem). The library's search minimises |residual|: it ends at a root, or (7% of
  // the default box) at a stationary point of the residual with no root near, and that
  // condition (residual' = 0) is the one differentiated then.
  const V3<T> n = normalize(p2 - p1);
  const V3<T> p = first ? p1 : p2;
  const V3<T> dir = first ? n : (-1.0) * n;
  T u(first ? u1 : u2);
  {
    const V3<double> pv = constant<double>(first ? a : b), nv = constant<double>(first ? n12 : Vec3(-n12));
    double r0, ru0;
    torusResidual(pv, nv, radius, first ? u1 : u2, r0, ru0);
    const bool root = std::abs(r0) < 1e-8;
    // polish on values first (the library stops at 1e-13 steps or when |residual| stops falling;
    // the steps over T need a converged start for exact second derivatives)
    double uv = first ? u1 : u2;
    for (int k = 0; k < 20; ++k) {
      double r, ru, ruu;
      torusResidual(pv, nv, radius, uv, r, ru, &ruu);
      const double step = root ? r / ru : ru / ruu;
      if (!std::isfinite(step)) break;
      uv -= step;
      if (!(std::abs(step) > 1e-15 * (1.0 + std::abs(uv)))) break;
    }
    u = T(uv);
    for (int k = 0; k < 2; ++k) {
      T r, ru, ruu;
      torusResidual(p, dir, radius, u, r, ru, &ruu);
      u = root ? u - r / ru : u - ru / ruu;
    }
  }
  return makeTorusFrame(radius, p + u * dir, p1, p2, f);
}

// everything of the blended path that does not depend on alpha (a muscle's mass points share
// it): the straight ends, the blend weight, the wrapped geometry; for a torus, in its local
// cylinder's frame
template <class T>
struct SmoothSetup {
  enum class Mode { Straight, Wrapped, Blend } mode = Mode::Straight;
  V3<T> p1{}, p2{};       // the straight path's ends (the local cylinder's frame for a torus)
  T l_straight{}, w{}, d{};
  bool ellipsoid = false;  // geometry: the ellipsoid's, else the arc path
  ArcPath<T> arc{};
  EllipsoidWrap<T> ew{};
  bool torus = false;      // points go back through `frame`
  TorusFrame<T> frame{};
  T wrappedLength() const { return ellipsoid ? ew.total / ew.factor : arc.total; }
  V3<T> wrappedPoint(const Alpha<T>& alpha) const { return ellipsoid ? ellipsoidPoint(ew, alpha) : arcPathPoint(arc, alpha); }
};

// the blend's setup over any scalar (the blended point: smoothPoint below)
// the end-point fade's band, as a fraction of the penetration band's width (default 0.1% of the
// surface's size): narrow, because models place path points close to their wrap surfaces (with the
// whole width, 5% of the radius, 11% of Rajagopal2016's wrapping muscle-poses at random poses
// moved by over 1 mm; with 0.02 of it, 2 of 1200 of subject_walk_armless's, 0 of Rajagopal's)
constexpr double kEndFadeFraction = 0.02;

// distance of an end point outside the surface (cylinder: from the infinite cylinder, as OpenSim's
// InsideRadius test; ellipsoid: in units of the smallest semi-axis, as penetration()); a large
// value for the torus, whose local cylinder is handled in its own frame
template <class T>
T endClearance(const WrapSurface& surf, const V3<T>& p) {
  switch (surf.type) {
    case WrapType::Cylinder: return dsqrt(p[0] * p[0] + p[1] * p[1]) - surf.radius;
    case WrapType::Sphere: return norm(p) - surf.radius;
    case WrapType::Ellipsoid: {
      const Vec3& a = surf.dimensions;
      const V3<T> q{p[0] / a[0], p[1] / a[1], p[2] / a[2]};
      return a.minCoeff() * (norm(q) - 1.0);
    }
    case WrapType::Torus: break;
  }
  return T(1e300);
}

// the end-point fade (smooth.hpp): 1 when both ends are at least `width` outside the surface, 0
// (the straight path, as OpenSim once an end is inside) when one touches it, quintic smoothstep
// between
template <class T>
T endFade(const WrapSurface& surf, const V3<T>& p1, const V3<T>& p2, double width) {
  const T c1 = endClearance(surf, p1), c2 = endClearance(surf, p2);
  const T v = (value(c1) < value(c2) ? c1 : c2) / (kEndFadeFraction * width);
  if (!(value(v) > 1e-6)) return T(0.0);
  if (value(v) >= 1.0) return T(1.0);
  return v * v * v * (10.0 + v * (-15.0 + 6.0 * v));
}

template <class T>
void smoothSetup(const WrapSurface& surf, const V3<T>& p1, const V3<T>& p2, double width, SmoothSetup<T>& st) {
  st.torus = false;
  st.p1 = p1;
  st.p2 = p2;
  st.l_straight = norm(p2 - p1);
  st.mode = SmoothSetup<T>::Mode::Straight;
  if (surf.type == WrapType::Torus) {
    // the smooth quadrant cylinder in the anchor's frame (lengths and blends are frame-free);
    // where the library does not wrap at all (no anchor, an end inside the local cylinder) the
    // straight path
    TorusFrame<T> f;
    const bool ok = torusFrame(surf, p1, p2, f);
    const WrapSurface cyl = torusCylinder(surf);
    const double ri = cyl.radius;
    const Vec3 q1 = values(f.q1), q2 = values(f.q2);
    if (!ok || std::hypot(q1[0], q1[1]) < ri || std::hypot(q2[0], q2[1]) < ri) {
      st.d = T(-1.0);
      st.w = T(0.0);
      return;
    }
    smoothSetup(cyl, f.q1, f.q2, width, st);
    st.torus = true;
    st.frame = f;
    return;
  }
  const T d = penetration(surf, p1, p2);
  st.d = d;
  st.w = T(0.0);
  // an end point at the surface: the tangent construction's derivatives are infinite there (the
  // tangent point runs into the end like sqrt(clearance)); fade to the straight path before it
  const T fade = endFade(surf, p1, p2, width);
  if (!(value(fade) > 0.0)) return;
  const bool faded = value(fade) < 1.0;
  T u_scale = T(1.0);
  if (surf.type == WrapType::Cylinder && surf.quadrant_sign != 0) {
    // the library's quadrant logic: with an end on the active side it wraps when the segment
    // meets the cylinder, and also, with the ends on opposite sides of the quadrant plane, when
    // the line's point nearest the axis lies on the inactive side (a wrap round the active side,
    // continuous across d = 0 there); with neither end active it always wraps. Those wraps are
    // the exact path (w = 1); only the contact-driven one is blended.
    const int axis = surf.quadrant_axis, sign = surf.quadrant_sign;
    const Vec3 a = values(p1), b = values(p2);
    const bool s1 = dsign(a[axis]) == sign, s2 = dsign(b[axis]) == sign;
    const V3<T> u = p2 - p1;
    const T uu = u[0] * u[0] + u[1] * u[1];
    const T tn = value(uu) > 0.0 ? -(p1[0] * u[0] + p1[1] * u[1]) / uu : T(0.0);
    const T near_axis = p1[axis] + tn * u[axis];  // the library's near12[axis]
    const bool opposite = dsign(a[axis]) != dsign(b[axis]);
    const bool forced = (!s1 && !s2) || (opposite && dsign(value(near_axis)) != sign);
    // distance of the nearest point from the quadrant plane, > 0 on the active side
    const T foot = sign * near_axis;
    const double kR = kQuadrantBlend * surf.radius;
    if (forced || (value(d) > 0.0 && !(value(foot) > 0.0))) {
      st.w = fade;
      st.ellipsoid = false;
      if (cylinderSetup(surf, p1, p2, st.arc))
        st.mode = faded ? SmoothSetup<T>::Mode::Blend : SmoothSetup<T>::Mode::Wrapped;
      return;
    }
    // as the nearest point nears the quadrant plane the band narrows to nothing (u = d kR /
    // (width foot)), so the weight reaches 1 before the forced wrap takes over on the other side:
    // continuous and smooth there, except at d = 0 on the plane itself, where the library
    // switches between no wrap and a forced wrap
    if (value(foot) > 0.0 && value(foot) < kR) u_scale = kR / foot;
  }
  // below u = 1e-6 the blend weight is < 1e-17 and the wrapped branch is not evaluated: its
  // derivatives grow like d^(-1/2) at the contact (the arc angle ~ sqrt(d)), and inf * 0 would
  // poison the dual parts
  const T u = u_scale * (d / width);
  if (!(value(u) > 1e-6)) return;
  st.ellipsoid = surf.type == WrapType::Ellipsoid;
  const bool ok = surf.type == WrapType::Cylinder    ? cylinderSetup(surf, p1, p2, st.arc)
                  : surf.type == WrapType::Ellipsoid ? ellipsoidSetup(surf, p1, p2, st.ew)
                                                     : sphereSetup(surf, p1, p2, st.arc);
  if (!ok) return;  // the library's finite-length cut-off (not smoothed)
  if (value(u) >= 1.0) {
    st.w = fade;
    st.mode = faded ? SmoothSetup<T>::Mode::Blend : SmoothSetup<T>::Mode::Wrapped;
    return;
  }
  // quintic smoothstep: C2 at both ends of the band (see the header)
  st.w = fade * (u * u * u * (10.0 + u * (-15.0 + 6.0 * u)));
  st.mode = SmoothSetup<T>::Mode::Blend;
}

// the blended point at fraction alpha from a setup; length_out (if given) receives the blended
// segment length L = L_straight + w (L_wrapped - L_straight), the exact wrapped length outside the band
template <class T>
V3<T> smoothEval(const SmoothSetup<T>& st, const Alpha<T>& alpha, T* length_out = nullptr) {
  using Mode = typename SmoothSetup<T>::Mode;
  V3<T> x;
  if (st.mode == Mode::Wrapped) {  // (the straight point is not needed)
    x = st.wrappedPoint(alpha);
    if (length_out) *length_out = st.wrappedLength();
  } else {
    x = st.p1 + alpha * (st.p2 - st.p1);
    if (length_out) *length_out = st.l_straight;
    if (st.mode == Mode::Blend) {
      x = x + st.w * (st.wrappedPoint(alpha) - x);
      if (length_out) *length_out = st.l_straight + st.w * (st.wrappedLength() - st.l_straight);
    }
  }
  return st.torus ? st.frame.toTorus(x) : x;
}

// the blended point over any scalar, one evaluation per point (the setup not shared: the
// reference route, nested duals per input direction)
template <class T>
V3<T> smoothPoint(const WrapSurface& surf, const V3<T>& p1, const V3<T>& p2, const Alpha<T>& alpha, double width, T* d_out,
                  T* w_out, T* length_out = nullptr) {
  SmoothSetup<T> st;
  smoothSetup(surf, p1, p2, width, st);
  if (d_out) *d_out = st.d;
  if (w_out) *w_out = st.w;
  return smoothEval(st, alpha, length_out);
}

void checkInputs(const WrapSurface& surf, const Vec3& p1, const Vec3& p2) {
  const std::string why = smoothWrapUnsupportedReason(surf);
  if (!why.empty()) throw std::invalid_argument("smooth wrap: " + why);
  if (!p1.allFinite() || !p2.allFinite() || p1 == p2) throw std::invalid_argument("smooth wrap: degenerate end points");
  if (surf.contains(p1) || surf.contains(p2)) throw std::invalid_argument("smooth wrap: an end point lies inside the surface");
}

// the surface's size: the default band is 5% of it
double sizeOf(const WrapSurface& surf) {
  switch (surf.type) {
    case WrapType::Cylinder:
    case WrapType::Sphere: return surf.radius;
    case WrapType::Ellipsoid: return surf.dimensions.minCoeff();
    case WrapType::Torus: return surf.inner_radius;
  }
  return surf.radius;
}

double widthOf(const WrapSurface& surf, const SmoothWrapOptions& o) { return o.width > 0.0 ? o.width : 0.05 * sizeOf(surf); }

}  // namespace

std::string smoothWrapUnsupportedReason(const WrapSurface& s) {
  if (!s.active) return "the surface is inactive";
  if (s.type == WrapType::Ellipsoid) {
    if (!(s.dimensions.minCoeff() > 0.0)) return "the ellipsoid's semi-axes must be positive";
    return "";
  }
  if (s.type == WrapType::Torus) {
    if (!(s.inner_radius > 0.0) || !(s.outer_radius > 0.0)) return "the torus radii must be positive";
    return "";
  }
  if (!(s.radius > 0.0)) return "the radius must be positive";
  return "";
}

double calcWrapPenetration(const WrapSurface& surface, const Vec3& p1, const Vec3& p2) {
  if (surface.type == WrapType::Torus) {
    TorusFrame<double> f;
    if (!torusFrame(surface, constant<double>(p1), constant<double>(p2), f)) return -1.0;
    return penetration(torusCylinder(surface), f.q1, f.q2);
  }
  return penetration(surface, constant<double>(p1), constant<double>(p2));
}

double calcWrapEndClearance(const WrapSurface& surface, const Vec3& p) {
  return endClearance(surface, constant<double>(p));
}

double smoothWrapEndFadeWidth(const WrapSurface& surface, const SmoothWrapOptions& options) {
  return kEndFadeFraction * widthOf(surface, options);
}

Vec3 calcSmoothWrapPoint(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, double alpha,
                         const SmoothWrapOptions& options) {
  checkInputs(surface, p1, p2);
  alpha = std::clamp(alpha, 0.0, 1.0);
  return values(smoothPoint<double>(surface, constant<double>(p1), constant<double>(p2), alpha,
                                    widthOf(surface, options), nullptr, nullptr));
}

namespace {

// the inputs (p1, p2) as jets: value, velocity, a unit partial per coordinate
template <int N>
void seedEnds(const Vec3& p1, const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot, V3<Jet<N>>& q1, V3<Jet<N>>& q2) {
  for (int k = 0; k < 3; ++k) {
    q1[k] = Jet<N>(p1[k]);
    q1[k].t = p1dot[k];
    q1[k].g[k] = 1.0;
    q2[k] = Jet<N>(p2[k]);
    q2[k].t = p2dot[k];
    q2[k].g[k + 3] = 1.0;
  }
}

// the shared route: one setup over jets for the muscle's points on this surface, then each point
// (N = 7: alpha is the seventh input, moving at its rate)
template <int N>
void smoothPointsJet(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot,
                     const std::vector<double>& alphas, const std::vector<double>& alphadots, double width,
                     WrapMassPoints& out, std::vector<Vec3>* x_alpha, std::vector<Vec3>* x_alphadot) {
  using J = Jet<N>;
  V3<J> q1, q2;
  seedEnds(p1, p2, p1dot, p2dot, q1, q2);
  SmoothSetup<J> st;
  smoothSetup(surface, q1, q2, width, st);
  const size_t n = alphas.size();
  out.x.resize(n);
  out.J.resize(n);
  out.Jdot.resize(n);
  if (x_alpha) x_alpha->resize(n);
  if (x_alphadot) x_alphadot->resize(n);
  for (size_t a = 0; a < n; ++a) {
    J al(std::clamp(alphas[a], 0.0, 1.0));
    if constexpr (N == 7) {
      al.t = alphadots.empty() ? 0.0 : alphadots[a];
      al.g[6] = 1.0;
    }
    const V3<J> x = smoothEval(st, al);
    for (int k = 0; k < 3; ++k) {
      out.x[a][k] = x[k].v;
      for (int i = 0; i < 6; ++i) {
        out.J[a](k, i) = x[k].g[i];
        out.Jdot[a](k, i) = x[k].gt[i];
      }
      if constexpr (N == 7) {
        if (x_alpha) (*x_alpha)[a][k] = x[k].g[6];
        if (x_alphadot) (*x_alphadot)[a][k] = x[k].gt[6];
      }
    }
  }
}

}  // namespace

void calcSmoothWrapPoints(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                          const Vec3& p2dot, const std::vector<double>& alphas, const std::vector<double>& alphadots,
                          const SmoothWrapOptions& options, WrapMassPoints& out, std::vector<Vec3>* x_alpha,
                          std::vector<Vec3>* x_alphadot) {
  checkInputs(surface, p1, p2);
  if (!alphadots.empty() && alphadots.size() != alphas.size())
    throw std::invalid_argument("smooth wrap: alphadots must be empty or one per alpha");
  out.used_network = false;
  const double width = widthOf(surface, options);
  bool moving_alpha = false;
  for (double ad : alphadots) moving_alpha = moving_alpha || ad != 0.0;
  if (moving_alpha || x_alpha || x_alphadot)
    smoothPointsJet<7>(surface, p1, p2, p1dot, p2dot, alphas, alphadots, width, out, x_alpha, x_alphadot);
  else
    smoothPointsJet<6>(surface, p1, p2, p1dot, p2dot, alphas, {}, width, out, nullptr, nullptr);
}

SmoothWrapPoint calcSmoothWrapPointDerivatives(const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                               double alpha, const Vec3& p1dot, const Vec3& p2dot,
                                               const SmoothWrapOptions& options) {
  checkInputs(surface, p1, p2);
  using J = Jet<6>;
  V3<J> q1, q2;
  seedEnds(p1, p2, p1dot, p2dot, q1, q2);
  SmoothSetup<J> st;
  smoothSetup(surface, q1, q2, widthOf(surface, options), st);
  const V3<J> x = smoothEval(st, J(std::clamp(alpha, 0.0, 1.0)));
  SmoothWrapPoint out;
  for (int k = 0; k < 3; ++k) {
    out.x[k] = x[k].v;
    for (int i = 0; i < 6; ++i) out.J(k, i) = x[k].g[i], out.Jdot(k, i) = x[k].gt[i];
  }
  out.penetration = st.d.v;
  out.weight = st.w.v;
  return out;
}

SmoothWrapSegmentPoint calcSmoothWrapSegmentPoint(const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                                  double alpha, const Vec3& p1dot, const Vec3& p2dot,
                                                  double alphadot, const SmoothWrapOptions& options) {
  WrapMassPoints mp;
  std::vector<Vec3> xa, xad;
  calcSmoothWrapPoints(surface, p1, p2, p1dot, p2dot, {alpha}, {alphadot}, options, mp, &xa, &xad);
  SmoothWrapSegmentPoint out;
  out.x = mp.x[0];
  out.J << mp.J[0], xa[0];
  out.Jdot << mp.Jdot[0], xad[0];
  return out;
}

SmoothWrapLength calcSmoothWrapLength(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                                      const Vec3& p2dot, const SmoothWrapOptions& options) {
  checkInputs(surface, p1, p2);
  using J = Jet<6>;
  V3<J> q1, q2;
  seedEnds(p1, p2, p1dot, p2dot, q1, q2);
  SmoothSetup<J> st;
  smoothSetup(surface, q1, q2, widthOf(surface, options), st);
  J L;
  smoothEval(st, J(0.0), &L);
  SmoothWrapLength out;
  out.length = L.v;
  for (int i = 0; i < 6; ++i) out.J(0, i) = L.g[i], out.Jdot(0, i) = L.gt[i];
  return out;
}

// one surface over Jets with the caller's seeds (smooth_jet.hpp; issue 22's composition)
template <int N>
struct SmoothWrapJetSegment<N>::Impl {
  SmoothSetup<Jet<N>> st;
};

template <int N>
SmoothWrapJetSegment<N>::SmoothWrapJetSegment(const WrapSurface& surface, const V& p1, const V& p2, double width)
    : impl_(std::make_unique<Impl>()) {
  SmoothSetup<J>& st = impl_->st;
  smoothSetup(surface, p1, p2, smoothWrapWidth(surface, width), st);
  weight = st.w;
  length = st.l_straight;
  lead = J(0.0);
  r1 = p1;
  r2 = p2;
  if (st.mode == SmoothSetup<J>::Mode::Straight) return;
  length = st.l_straight + st.w * (st.wrappedLength() - st.l_straight);
  if (st.ellipsoid) {
    lead = (st.ew.d1 + st.ew.la) / st.ew.factor;
    r1 = (1.0 / st.ew.factor) * st.ew.r1;
    r2 = (1.0 / st.ew.factor) * st.ew.r2;
  } else {
    lead = st.arc.l1 + st.arc.la;
    r1 = st.torus ? st.frame.toTorus(st.arc.r1) : st.arc.r1;
    r2 = st.torus ? st.frame.toTorus(st.arc.r2) : st.arc.r2;
  }
}

template <int N> SmoothWrapJetSegment<N>::~SmoothWrapJetSegment() = default;
template <int N> SmoothWrapJetSegment<N>::SmoothWrapJetSegment(SmoothWrapJetSegment&&) noexcept = default;
template <int N>
SmoothWrapJetSegment<N>& SmoothWrapJetSegment<N>::operator=(SmoothWrapJetSegment&&) noexcept = default;

template <int N>
typename SmoothWrapJetSegment<N>::V SmoothWrapJetSegment<N>::point(const J& alpha) const {
  return smoothEval(impl_->st, alpha);
}

double smoothWrapWidth(const WrapSurface& surface, double width) {
  SmoothWrapOptions o;
  o.width = width;
  return widthOf(surface, o);
}

// the sizes the composition uses: 6 unknowns per extra surface (the fixed point's Newton
// Jacobian), 7 + 12 K inputs (ends, K surface poses, the fraction) for K = 1, 2, 3
template class SmoothWrapJetSegment<6>;
template class SmoothWrapJetSegment<12>;
template class SmoothWrapJetSegment<19>;
template class SmoothWrapJetSegment<31>;
template class SmoothWrapJetSegment<43>;

// the route before issue 18 (nested duals, one pass per input direction, per point): the tests'
// reference for the shared route above
namespace smooth_reference {

namespace {

using D2 = Dual<Dual<double>>;

// pass i of the nested-dual route: the velocity direction (p1dot, p2dot) in the inner duals, the
// input direction e_i (i < 6: p1 then p2; i = 6: none, alpha is seeded by the caller) in the outer
void seedReferencePass(const Vec3& p1, const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot, int i, V3<D2>& q1,
                       V3<D2>& q2) {
  for (int k = 0; k < 3; ++k) {
    q1[k] = D2{Dual<double>{p1[k], p1dot[k]}, Dual<double>{i == k ? 1.0 : 0.0, 0.0}};
    q2[k] = D2{Dual<double>{p2[k], p2dot[k]}, Dual<double>{i == k + 3 ? 1.0 : 0.0, 0.0}};
  }
}

}  // namespace

SmoothWrapPoint calcSmoothWrapPointDerivatives(const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                               double alpha, const Vec3& p1dot, const Vec3& p2dot,
                                               const SmoothWrapOptions& options) {
  checkInputs(surface, p1, p2);
  alpha = std::clamp(alpha, 0.0, 1.0);
  const double width = widthOf(surface, options);
  SmoothWrapPoint out;
  // one pass per input direction e_i; every pass also carries the velocity direction, so b.b is
  // the mixed derivative d^2 x / (d e_i d v) = column i of Jdot
  for (int i = 0; i < 6; ++i) {
    V3<D2> q1, q2;
    seedReferencePass(p1, p2, p1dot, p2dot, i, q1, q2);
    D2 d, w;
    const V3<D2> x = smoothPoint(surface, q1, q2, alpha, width, &d, &w);
    for (int k = 0; k < 3; ++k) {
      out.J(k, i) = x[k].b.a;
      out.Jdot(k, i) = x[k].b.b;
    }
    if (i == 0) {
      for (int k = 0; k < 3; ++k) out.x[k] = x[k].a.a;
      out.penetration = d.a.a;
      out.weight = w.a.a;
    }
  }
  return out;
}

SmoothWrapSegmentPoint calcSmoothWrapSegmentPoint(const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                                  double alpha, const Vec3& p1dot, const Vec3& p2dot,
                                                  double alphadot, const SmoothWrapOptions& options) {
  checkInputs(surface, p1, p2);
  alpha = std::clamp(alpha, 0.0, 1.0);
  const double width = widthOf(surface, options);
  SmoothWrapSegmentPoint out;
  // as calcSmoothWrapPointDerivatives, with a seventh pass for alpha
  for (int i = 0; i < 7; ++i) {
    V3<D2> q1, q2;
    seedReferencePass(p1, p2, p1dot, p2dot, i, q1, q2);
    const D2 a{Dual<double>{alpha, alphadot}, Dual<double>{i == 6 ? 1.0 : 0.0, 0.0}};
    const V3<D2> x = smoothPoint<D2>(surface, q1, q2, a, width, nullptr, nullptr);
    for (int k = 0; k < 3; ++k) {
      out.J(k, i) = x[k].b.a;
      out.Jdot(k, i) = x[k].b.b;
    }
    if (i == 0)
      for (int k = 0; k < 3; ++k) out.x[k] = x[k].a.a;
  }
  return out;
}

SmoothWrapLength calcSmoothWrapLength(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                                      const Vec3& p2dot, const SmoothWrapOptions& options) {
  checkInputs(surface, p1, p2);
  const double width = widthOf(surface, options);
  SmoothWrapLength out;
  for (int i = 0; i < 6; ++i) {
    V3<D2> q1, q2;
    seedReferencePass(p1, p2, p1dot, p2dot, i, q1, q2);
    D2 L;
    smoothPoint<D2>(surface, q1, q2, D2(0.0), width, nullptr, nullptr, &L);
    out.J(0, i) = L.b.a;
    out.Jdot(0, i) = L.b.b;
    if (i == 0) out.length = L.a.a;
  }
  return out;
}

}  // namespace smooth_reference

}  // namespace redmax
