// WrapEllipsoid as OpenSim computes it (docs/opensim_compatibility.md §6). In coordinates scaled by
// f = 3 / sum(dimensions): the segment must cross the ellipsoid; a point c1 on the surface fixes
// the wrapping plane (the "fan" of closest points along the chord, the "axial" (Frans) cross
// section, a blend of the two (hybrid), or the chord midpoint); r1 and r2 are found in that plane
// by OpenSim's damped Gauss-Newton iteration; the surface path is a polyline of rays from a point
// of the plane, 1 mm per segment (at most 499).
#include <cmath>
#include <limits>

#include "core/geometry/wrap_math.hpp"

namespace redmax::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTiny = 1e-8;          // ELLIPSOID_TINY
constexpr double kMuBlendMin = 0.7073;  // 100% fan below
constexpr double kMuBlendMax = 0.9;     // 100% axial above
constexpr int kFanSamples = 300;
constexpr double kSvBoundaryBlend = 0.3;
constexpr double kRoundoff = 2e-13;     // OpenSim's ROUNDOFF_ERROR

bool nearZero(double v) { return std::abs(v) <= kRoundoff; }

// Graphics Gems IV closest point on the ellipse (x/a)^2 + (y/b)^2 = 1 to (u, v), with OpenSim's
// special cases near the axes
double closestPointToEllipse(double a, double b, double u, double v, double& x, double& y) {
  const double a2 = a * a, b2 = b * b, a2u2 = a2 * u * u, b2v2 = b2 * v * v;
  const bool near_x = nearZero(u), near_y = nearZero(v);
  if (near_x && near_y) {
    if (a < b) {
      x = u < 0.0 ? -a : a;
      y = v;
      return a;
    }
    x = u;
    y = v < 0.0 ? -b : b;
    return b;
  }
  if (near_x) {
    if (a >= b || std::abs(v) >= b - a2 / b) {
      x = u;
      y = v >= 0 ? b : -b;
      return std::abs(y - v);
    }
    y = b2 * v / (b2 - a2);
    const double dy = y - v, ydb = y / b;
    x = a * std::sqrt(std::abs(1 - ydb * ydb));
    return std::sqrt(x * x + dy * dy);
  }
  if (near_y) {
    if (b >= a || std::abs(u) >= a - b2 / a) {
      x = u >= 0 ? a : -a;
      y = v;
      return std::abs(x - u);
    }
    x = a2 * u / (a2 - b2);
    const double dx = x - u, xda = x / a;
    y = b * std::sqrt(std::abs(1 - xda * xda));
    return std::sqrt(dx * dx + y * y);
  }
  double t = (u / a) * (u / a) + (v / b) * (v / b) < 1.0 ? 0.0 : std::max(a, b) * std::sqrt(u * u + v * v);
  double P = 0.0, Q = 0.0;
  for (int i = 0; i < 64; ++i) {
    P = t + a2;
    Q = t + b2;
    const double f = P * P * Q * Q - a2u2 * Q * Q - b2v2 * P * P;
    if (std::abs(f) < 1e-9) break;
    const double fp = 2.0 * (P * Q * (P + Q) - a2u2 * Q - b2v2 * P);
    t -= f / fp;
  }
  x = a2 * u / P;
  y = b2 * v / Q;
  return std::hypot(x - u, y - v);
}

}  // namespace

double closestPointOnEllipsoid(const Vec3& abc, const Vec3& uvw, Vec3& x, int special_axis) {
  const double a = abc[0], b = abc[1], c = abc[2];
  const double u = uvw[0], v = uvw[1], w = uvw[2];
  if (special_axis < 0) {
    // near a coordinate plane: the narrowest elliptical cross-section there
    double min_sum = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
      if (!nearZero(uvw[i])) continue;
      double sum = 0.0;
      for (int j = 0; j < 3; ++j)
        if (j != i) sum += abc[j];
      if (min_sum > sum) {
        special_axis = i;
        min_sum = sum;
      }
    }
  }
  if (special_axis == 0) {
    x[0] = u;
    return closestPointToEllipse(b, c, v, w, x[1], x[2]);
  }
  if (special_axis == 1) {
    x[1] = v;
    return closestPointToEllipse(c, a, w, u, x[2], x[0]);
  }
  if (special_axis == 2) {
    x[2] = w;
    return closestPointToEllipse(a, b, u, v, x[0], x[1]);
  }
  // general case: Newton on the Lagrange parameter t
  const double a2 = a * a, b2 = b * b, c2 = c * c;
  const double a2u2 = a2 * u * u, b2v2 = b2 * v * v, c2w2 = c2 * w * w;
  double t = (u / a) * (u / a) + (v / b) * (v / b) + (w / c) * (w / c) < 1.0
                 ? 0.0
                 : std::max(a, std::max(b, c)) * std::sqrt(u * u + v * v + w * w);
  for (int i = 0; i < 64; ++i) {
    const double P = t + a2, Q = t + b2, R = t + c2;
    const double P2 = P * P, Q2 = Q * Q, R2 = R * R;
    const double f = P2 * Q2 * R2 - a2u2 * Q2 * R2 - b2v2 * P2 * R2 - c2w2 * P2 * Q2;
    if (std::abs(f) < 1e-9) {
      x = Vec3(a2 * u / P, b2 * v / Q, c2 * w / R);
      return (x - uvw).norm();
    }
    const double PQ = P * Q, PR = P * R, QR = Q * R, PQR = P * Q * R;
    const double fp = 2.0 * (PQR * (QR + PR + PQ) - a2u2 * QR * (Q + R) - b2v2 * PR * (P + R) -
                             c2w2 * PQ * (P + Q));
    t -= f / fp;
  }
  return -1.0;
}

namespace {

// residuals of the tangent point r1 (with the tangent-plane offset d1) in the plane vs.x + vs4 = 0:
// in the plane, on the ellipsoid, and the tangent plane at r1 passing through p1
struct TangentResidual {
  const Vec3 &p1, &m, &a, &vs;
  double vs4;
  Vec4 operator()(const Vec3& r1, double d1) const {
    const Vec3 nr1 = 2.0 * (r1 - m).cwiseQuotient(a.cwiseProduct(a));
    Vec4 ee;
    ee[0] = vs.dot(r1) + vs4;
    ee[1] = (r1 - m).cwiseQuotient(a).squaredNorm() - 1.0;
    ee[2] = nr1.dot(r1) + d1;
    ee[3] = nr1.dot(p1) + d1;
    return ee;
  }
};

// OpenSim's calcTangentPoint: damped Gauss-Newton (Levenberg steps, then step doubling) on the
// four residuals, from the current r1
void calcTangentPoint(double p1e, Vec3& r1, const Vec3& p1, const Vec3& m, const Vec3& a,
                      const Vec3& vs, double vs4) {
  if (std::abs(p1e) < 1e-4) {
    r1 = p1;
    return;
  }
  const TangentResidual res{p1, m, a, vs, vs4};
  const Vec3 a_sq = a.cwiseProduct(a);
  double d1 = -(2.0 * (r1 - m).cwiseQuotient(a_sq)).dot(r1);
  Vec4 ee = res(r1, d1);
  double ssqo = ee.squaredNorm(), ssq = ssqo;
  double alpha = 0.01;
  for (int nit = 0; ssq > kTiny && nit < 50; ++nit) {
    // dedth(i, j) = d ee[j] / d x[i], x = (r1, d1) as OpenSim writes it
    Eigen::Matrix4d dedth;
    for (int i = 0; i < 3; ++i) {
      dedth(i, 0) = vs[i];
      dedth(i, 1) = 2.0 * (r1[i] - m[i]) / a_sq[i];
      dedth(i, 2) = 2.0 * (2.0 * r1[i] - m[i]) / a_sq[i];
      dedth(i, 3) = 2.0 * p1[i] / a_sq[i];
    }
    dedth.row(3) << 0.0, 0.0, 1.0, 1.0;
    Vec3 p1r1, p1m;
    normalizeOrZero(p1 - r1, p1r1);
    normalizeOrZero(p1 - m, p1m);
    const double pcos = p1r1.dot(p1m);
    const double dd = pcos > 0.1 ? 1.0 - std::pow(pcos, 100) : 1.0;
    const Vec4 v = -dedth * ee;
    Eigen::Matrix4d dedth2 = dedth * dedth.transpose();
    const Vec4 diag = dedth2.diagonal();
    Vec4 vt = Vec4::Zero();
    // Levenberg: raise the damping until the sum of squares stops growing (steps accumulate)
    for (int nit2 = 0; ssq >= ssqo && nit2 < 1000; ++nit2) {
      for (int i = 0; i < 4; ++i) dedth2(i, i) = diag[i] * (1.0 + alpha);
      const Eigen::Matrix4d inv = dedth2.inverse();
      vt = dd * (inv * v) / 16.0;
      r1 += vt.head<3>();
      d1 += vt[3];
      ee = res(r1, d1);
      ssqo = ssq;
      ssq = ee.squaredNorm();
      alpha *= 4.0;
    }
    alpha /= 8.0;
    // then double the step while it keeps helping, and take back the last one
    double fakt = 0.5;
    for (int nit2 = 0; ssq <= ssqo && nit2 < 1000; ++nit2) {
      fakt *= 2.0;
      r1 += vt.head<3>() * fakt;
      d1 += vt[3] * fakt;
      ee = res(r1, d1);
      ssqo = ssq;
      ssq = ee.squaredNorm();
    }
    r1 -= vt.head<3>() * fakt;
    d1 -= vt[3] * fakt;
    ee = res(r1, d1);
    ssq = ee.squaredNorm();
    ssqo = ssq;
  }
}

// OpenSim's CalcDistanceOnEllipsoid: rays from a0 (where the plane meets the coordinate axis most
// normal to it) swept from r1 to r2, each cut with the ellipsoid; length of the polyline
void calcDistanceOnEllipsoid(const Vec3& r1, const Vec3& r2, const Vec3& m, const Vec3& a,
                             const Vec3& vs, double vs4, bool far_side_wrap, double factor,
                             std::vector<Vec3>& pts, double& length) {
  constexpr double kSegLength = 0.001;
  const double len = (r1 - r2).norm() / factor;
  pts.clear();
  if (len < kSegLength) {
    pts = {r1, r2};
    length = len * factor;
    return;
  }
  int nseg = static_cast<int>(len / kSegLength);
  if (nseg > 499) nseg = 499;
  int imax = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(vs[i]) > std::abs(vs[imax])) imax = i;
  const Vec3 u = Vec3::Unit(imax);
  const double mu = (-vs.dot(m) - vs4) / vs.dot(u);
  const Vec3 a0 = m + mu * u;
  Vec3 ar1, ar2, vsz;
  normalizeOrZero(r1 - a0, ar1);
  normalizeOrZero(r2 - a0, ar2);
  const double phi0 = std::acos(ar1.dot(ar2));
  const double dphi = far_side_wrap ? -(2 * kPi - phi0) / nseg : phi0 / nseg;
  normalizeOrZero(ar1.cross(ar2), vsz);
  const Vec3 vsy = vsz.cross(ar1);
  pts.reserve(nseg + 1);
  pts.push_back(r1);
  const Vec3 f2 = (a0 - m).cwiseQuotient(a);
  for (int i = 0; i < nseg - 1; ++i) {
    const double phi = (i + 1) * dphi;
    const Vec3 rr = std::cos(phi) * ar1 + std::sin(phi) * vsy;
    const Vec3 f1 = rr.cwiseQuotient(a);
    const double aa = f1.dot(f1), bb = 2.0 * f1.dot(f2), cc = f2.dot(f2) - 1.0;
    const double mu3 = (-bb + std::sqrt(bb * bb - 4.0 * aa * cc)) / (2.0 * aa);
    pts.push_back(a0 + mu3 * rr);
  }
  pts.push_back(r2);
  length = 0.0;
  for (int i = 0; i < nseg; ++i) length += (pts[i + 1] - pts[i]).norm();
}

}  // namespace

void wrapEllipsoid(const WrapSurface& s, const Vec3& P1, const Vec3& P2, WrapMethod method,
                   WrapResult& r) {
  const int axis = s.quadrant_axis, sign = s.quadrant_sign;
  r.code = WrapCode::NoWrap;
  // scale so that the coordinates are near 1
  const double factor = 3.0 / s.dimensions.sum();
  const Vec3 p1 = P1 * factor, p2 = P2 * factor, m = Vec3::Zero(), a = s.dimensions * factor;
  const double p1e = p1.cwiseQuotient(a).squaredNorm() - 1.0;
  const double p2e = p2.cwiseQuotient(a).squaredNorm() - 1.0;
  if (p1e < -1e-4 || p2e < -1e-4) {
    r.code = WrapCode::InsideRadius;
    return;
  }
  const Vec3 p1p2 = p1 - p2;
  Vec3 p1m, p2m;
  normalizeOrZero(p1 - m, p1m);
  normalizeOrZero(p2 - m, p2m);
  if (std::abs(p1m.dot(p2m) - 1.0) < 1e-4) return;  // both points seen in the same direction

  // the line must cross the ellipsoid between the points
  const Vec3 f1 = p1p2.cwiseQuotient(a), f2 = (p2 - m).cwiseQuotient(a);
  const double aa = f1.dot(f1), bb = 2.0 * f1.dot(f2), cc = f2.dot(f2) - 1.0;
  const double disc = bb * bb - 4.0 * aa * cc;
  if (disc < 0.0) return;
  const double l1 = (-bb + std::sqrt(disc)) / (2.0 * aa), l2 = (-bb - std::sqrt(disc)) / (2.0 * aa);
  if (!(0.0 < l1 && l1 < 1.0) || !(0.0 < l2 && l2 < 1.0)) return;

  // r1, r2: where the chord meets the surface
  Vec3 r1 = p2 + l1 * p1p2, r2 = p2 + l2 * p1p2;
  const Vec3 r1r2 = r2 - r1;
  Vec3 c1 = Vec3::Zero(), sv = Vec3::Zero();

  // wrapping plane: axial (Frans) candidates per coordinate axis
  Vec3 mu;
  normalizeOrZero(p1p2, mu);
  Vec3 t;
  Vec3 t_sv[3], t_c1[3];
  for (int i = 0; i < 3; ++i) {
    mu[i] = std::abs(mu[i]);
    t[i] = (m[i] - r1[i]) / r1r2[i];
    t_sv[i] = r1 + t[i] * r1r2;
    t_c1[i].setZero();
    closestPointOnEllipsoid(a, t_sv[i], t_c1[i], i);
  }
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (mu[i] > mu[best]) best = i;
  double fan_weight = -std::numeric_limits<double>::infinity();

  if (method == WrapMethod::Hybrid || method == WrapMethod::Axial) {
    if (method == WrapMethod::Hybrid && mu[best] > kMuBlendMin) {
      // fade the axial solution out when its sv nears the chord's ends
      double sfade = 1.0;
      if (t[best] < 0.0 || t[best] > 1.0)
        sfade = 0.0;
      else if (t[best] < kSvBoundaryBlend)
        sfade = t[best] / kSvBoundaryBlend;
      else if (t[best] > 1.0 - kSvBoundaryBlend)
        sfade = (1.0 - t[best]) / kSvBoundaryBlend;
      if (sfade < 1.0) mu[best] = kMuBlendMin + sfade * (mu[best] - kMuBlendMin);
    }
    if (method == WrapMethod::Axial || mu[best] > kMuBlendMin) {
      c1 = t_c1[best];
      sv = t_sv[best];
    }
    if (method == WrapMethod::Hybrid && mu[best] < kMuBlendMax) {
      // fan: average of the directions from chord points to their closest surface points
      Vec3 v_sum = Vec3::Zero();
      const Vec3 mid = r1 + 0.5 * r1r2;
      for (int i = 1; i < kFanSamples - 1; ++i) {
        const double tt = static_cast<double>(i) / kFanSamples;
        const Vec3 svi = r1 + tt * r1r2;
        closestPointOnEllipsoid(a, svi, t_c1[0]);
        Vec3 v;
        normalizeOrZero(t_c1[0] - svi, v);
        v_sum += v;
      }
      normalizeOrZero(v_sum, v_sum);
      t_c1[0] = mid + v_sum;
      if (mu[best] <= kMuBlendMin) {
        closestPointOnEllipsoid(a, t_c1[0], c1);
        sv = mid;
        fan_weight = 1.0;
      } else {
        const double tt = (mu[best] - kMuBlendMin) / (kMuBlendMax - kMuBlendMin);
        closestPointOnEllipsoid(a, t_c1[0], t_c1[1]);
        t_c1[2] = tt * c1 + (1.0 - tt) * t_c1[1];
        sv = tt * sv + (1.0 - tt) * mid;
        closestPointOnEllipsoid(a, t_c1[2], c1);
        fan_weight = 1.0 - tt;
      }
    }
  } else {
    sv = r1 + 0.5 * (r2 - r1);
    closestPointOnEllipsoid(a, sv, c1);
  }

  // start the tangent searches from c1 (axial: only when its sv is inside the chord)
  bool use_c1 = true;
  if (method == WrapMethod::Axial) use_c1 = t[best] > 0.0 && t[best] < 1.0;
  if (use_c1) r1 = r2 = c1;

  // quadrant: mirror c1 onto the active side, pulled toward the bisection by the fan weight
  if (sign != 0) {
    const double dist = c1[axis] - m[axis];
    if (dsign(dist) != sign) {
      const Vec3 orig_c1 = c1;
      c1[axis] = -c1[axis];
      r1 = r2 = c1;
      // OpenSim's test |fan_weight - (-inf)| <= eps is never true (inf - inf is NaN): kept as is
      if (std::abs(fan_weight + std::numeric_limits<double>::infinity()) <= kRoundoff)
        fan_weight = 1.0 - (mu[best] - kMuBlendMin) / (kMuBlendMax - kMuBlendMin);
      if (fan_weight > 1.0) fan_weight = 1.0;
      if (fan_weight > 0.0) {
        const double bisection = (orig_c1[axis] + c1[axis]) / 2.0;
        c1[axis] = c1[axis] + fan_weight * (bisection - c1[axis]);
        const Vec3 tc1 = c1;
        closestPointOnEllipsoid(a, tc1, c1);
      }
    }
  }

  // the wrapping plane through p1, p2 and c1
  Vec3 vs;
  normalizeOrZero(p1p2.cross(p1 - c1), vs);
  const double vs4 = -vs.dot(c1);
  calcTangentPoint(p1e, r1, p1, m, a, vs, vs4);
  calcTangentPoint(p2e, r2, p2, m, a, vs, vs4);

  bool far_side_wrap = false;
  double length = 0.0;
  std::vector<Vec3> pts;
  for (;;) {
    calcDistanceOnEllipsoid(r1, r2, m, a, vs, vs4, far_side_wrap, factor, pts, length);
    if (sign == 0 || pts.size() <= 2 || far_side_wrap) break;
    // a wrong-way wrap (first or last surface segment bending back toward its end point): go
    // round the far side instead
    Vec3 r1p1, r1w1, r2p2, r2w2;
    normalizeOrZero(p1 - r1, r1p1);
    normalizeOrZero(pts[1] - r1, r1w1);
    normalizeOrZero(p2 - r2, r2p2);
    normalizeOrZero(pts[pts.size() - 2] - r2, r2w2);
    if (r1p1.dot(r1w1) > 0.0 || r2p2.dot(r2w2) > 0.0)
      far_side_wrap = true;
    else
      break;
  }

  // back to unscaled coordinates
  r.r1 = r1 / factor;
  r.r2 = r2 / factor;
  r.length = length / factor;
  r.arc = ArcKind::Polyline;
  r.far_side = far_side_wrap;
  r.polyline.resize(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) r.polyline[i] = pts[i] * (1.0 / factor);
  r.code = WrapCode::MandatoryWrap;
}

}  // namespace redmax::detail
