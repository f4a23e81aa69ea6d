// WrapCylinder as OpenSim computes it (docs/opensim_compatibility.md §6): candidate tangent points in the
// planes through P1 and P2 normal to the axis, OpenSim's choice among them, a slide along the axis
// into the plane through P1, P2 and the apex, then a helix between r1 and r2.
#include <cmath>

#include "core/muscles/wrap/wrap_geometry.hpp"

namespace redmax::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxTangentIterations = 100;
constexpr double kTangencyThreshold = 0.1 * kPi / 180.0;  // 0.1 degree

// the axis line of OpenSim's cylinder code: through (0, 0, -1) along +z
const Vec3 kP0(0.0, 0.0, -1.0);
const Vec3 kDn(0.0, 0.0, 1.0);

// two tangent candidates from point p: in the plane through p normal to the axis
void tangentCandidates(double R, const Vec3& p, Vec3& pa, Vec3& a, Vec3& b, double& p_dist) {
  double t;
  closestPointOnLine(p, kP0, kDn, pa, t);
  Vec3 vv;
  p_dist = normalizeOrZero(p - pa, vv);
  const double sin_theta = R / p_dist;
  double dist = R * sin_theta;
  const Vec3 pp = pa + dist * vv;
  dist = std::sqrt(R * R - dist * dist);
  const Vec3 uu = kDn.cross(vv);
  a = pp + dist * uu;
  b = pp - dist * uu;
}

// OpenSim's _adjust_tangent_point: slide r1 so that p1 -> r1 meets the helix within 0.1 degree
bool adjustTangentPoint(const Vec3& pt1, Vec3& r1, const Vec3& w1) {
  Vec3 pr, rw;
  normalizeOrZero(r1 - pt1, pr);
  normalizeOrZero(w1 - r1, rw);
  const double alpha = std::acos(pr.dot(kDn));
  const double omega = std::acos(rw.dot(kDn));
  if (!(std::abs(alpha - omega) > kTangencyThreshold)) return false;
  Vec3 p1a, w1a, int1, int2 = r1;
  double t, s;
  closestPointOnLine(pt1, r1, kDn, p1a, t);
  closestPointOnLine(w1, r1, kDn, w1a, t);
  intersectLines(pt1, w1, p1a, w1a, int1, s, int2, t);
  r1 += 1.5 * (int2 - r1);
  return true;
}

// helix r1 -> r2 about the axis; with several wrap objects, OpenSim's tangency iterations
void makeSpiral(double R, const Vec3& p1, const Vec3& p2, bool long_wrap, bool single_wrap,
                WrapResult& r) {
  const double sense = long_wrap ? -1.0 : 1.0;
  for (int iterations = 0;; ++iterations) {
    Vec3 r1a, r2a;
    double t;
    closestPointOnLine(r.r1, kP0, kDn, r1a, t);
    closestPointOnLine(r.r2, kP0, kDn, r2a, t);
    const double axial = (r2a - r1a).dot(kDn);
    const Vec3 uu = r.r1 - r1a, vv = r.r2 - r2a;
    double theta = std::atan2(uu.cross(vv).dot(kDn), uu.dot(vv));
    if (long_wrap) theta = 2.0 * kPi - theta;
    r.length = std::sqrt(R * theta * R * theta + axial * axial);
    r.arc = ArcKind::Helix;
    r.arc_center = Vec3::Zero();
    r.arc_axis = kDn;
    r.arc_angle = sense * theta;
    r.arc_rise = axial;
    if (single_wrap || iterations >= kMaxTangentIterations) return;
    // OpenSim samples the helix every 2 mm and corrects the tangent points at the second sample
    const int n = static_cast<int>(r.length / 0.002);
    if (n < 2) return;
    const double ts = 1.0 / n;
    auto spiral = [&](double s) -> Vec3 {
      return Eigen::AngleAxisd(sense * s * theta, kDn) * r.r1 + kDn * (s * axial);
    };
    const Vec3 w1 = spiral(ts);
    const bool adj1 = adjustTangentPoint(p1, r.r1, w1);
    const Vec3 w2 = spiral(1.0 - ts);  // uses the (possibly moved) r1, as OpenSim does
    const bool adj2 = adjustTangentPoint(p2, r.r2, w2);
    if (!adj1 && !adj2) return;
  }
}

}  // namespace

void wrapCylinder(double R, double L, int axis, int sign, const Vec3& p1, const Vec3& p2,
                  bool single_wrap, WrapResult& r) {
  const double r_sq = R * R;
  const bool constrained = sign != 0;
  bool far_side_wrap = false, long_wrap = false;
  WrapCode code = WrapCode::Wrapped;
  r.code = WrapCode::NoWrap;

  // an end point inside the (infinite) cylinder
  if (distanceSquaredToLine(p1, kP0, kDn) < r_sq || distanceSquaredToLine(p2, kP0, kDn) < r_sq) {
    r.code = WrapCode::InsideRadius;
    return;
  }

  // closest approach of the muscle segment and the finite axis segment
  const Vec3 cyl_start(0.0, 0.0, -0.5 * L), cyl_end(0.0, 0.0, 0.5 * L);
  Vec3 near12 = Vec3::Constant(std::numeric_limits<double>::quiet_NaN()), near00 = near12;
  double t12, t00;
  intersectLines(p1, p2, cyl_start, cyl_end, near12, t12, near00, t00);
  const bool intersects = (near12 - near00).squaredNorm() < r_sq && t12 > 0.0 && t12 < 1.0;

  if (!constrained) {
    if (!intersects) return;
    code = WrapCode::MandatoryWrap;
  }

  Vec3 p11, p22, r1a, r1b, r2a, r2b;
  double p11_dist, p22_dist;
  tangentCandidates(R, p1, p11, r1a, r1b, p11_dist);
  tangentCandidates(R, p2, p22, r2a, r2b, p22_dist);

  if (constrained) {
    const bool s1 = dsign(p1[axis]) == sign, s2 = dsign(p2[axis]) == sign;
    if (s1 || s2) {
      if (intersects)
        code = WrapCode::MandatoryWrap;
      else if (dsign(p1[axis]) != dsign(p2[axis]) && dsign(near12[axis]) != sign)
        code = WrapCode::Wrapped;
      else
        return;
    }
    const Vec3 r1am = r1a - p11, r1bm = r1b - p11, r2am = r2a - p22, r2bm = r2b - p22;
    const double alpha = std::acos(r1am.dot(r2bm) / (r1am.norm() * r2bm.norm()));
    const double beta = std::acos(r1bm.dot(r2am) / (r1bm.norm() * r2am.norm()));
    const bool a1 = dsign(r1a[axis]) == sign, b1 = dsign(r1b[axis]) == sign;
    const bool a2 = dsign(r2a[axis]) == sign, b2 = dsign(r2b[axis]) == sign;
    // OpenSim's case table over which candidates lie on the active side
    auto pick_ba = [&](bool far_if_alpha_gt_beta) {
      r.r1 = r1b;
      r.r2 = r2a;
      far_side_wrap = (alpha > beta) == far_if_alpha_gt_beta;
    };
    auto pick_ab = [&](bool far_if_alpha_gt_beta) {
      r.r1 = r1a;
      r.r2 = r2b;
      far_side_wrap = (alpha > beta) == far_if_alpha_gt_beta;
    };
    if (a1 && b1) {
      if (a2) pick_ba(false);
      else pick_ab(true);
    } else if (a1 && !b1) {
      pick_ab(true);
    } else if (!a1 && b1) {
      pick_ba(false);
    } else {
      if (a2) pick_ba(false);
      else if (b2) pick_ab(true);
      else if (alpha > beta) {
        r.r1 = r1a;
        r.r2 = r2b;
        far_side_wrap = true;
      } else {
        r.r1 = r1b;
        r.r2 = r2a;
        far_side_wrap = true;
      }
    }
    // a long wrap (more than half way round)
    const Vec3 sum_musc = (r.r1 - p1) + (r.r2 - p2);
    const Vec3 sum_r = (r.r1 - p11) + (r.r2 - p22);
    if (sum_r.dot(sum_musc) < 0.0) long_wrap = true;
  } else {
    // unconstrained: the pair of candidates whose radial directions agree best
    Vec3 u1a, u1b, u2a, u2b;
    normalizeOrZero(r1a - p11, u1a);
    normalizeOrZero(r1b - p11, u1b);
    normalizeOrZero(r2a - p22, u2a);
    normalizeOrZero(r2b - p22, u2b);
    const double d1 = u1a.dot(u2a), d2 = u1a.dot(u2b), d3 = u1b.dot(u2a), d4 = u1b.dot(u2b);
    if (d1 > d2 && d1 > d3 && d1 > d4) {
      r.r1 = r1a;
      r.r2 = r2a;
    } else if (d2 > d3 && d2 > d4) {
      r.r1 = r1a;
      r.r2 = r2b;
    } else if (d3 > d4) {
      r.r1 = r1b;
      r.r2 = r2a;
    } else {
      r.r1 = r1b;
      r.r2 = r2b;
    }
  }

  // apex: the surface point of the axis-normal plane through the point of the muscle line at
  // fraction d1 / (d1 + d2), on the near side (far side for far-side wraps)
  double t = p11_dist / (p11_dist + p22_dist);
  const Vec3 mpt = p1 + t * (p2 - p1);
  Vec3 axispt;
  closestPointOnLine(mpt, kP0, kDn, axispt, t);
  Vec3 l1, l2, n, vert1, vert2;
  normalizeOrZero(p1 - axispt, l1);
  normalizeOrZero(p2 - axispt, l2);
  normalizeOrZero(l1.cross(l2), n);
  normalizeOrZero(kDn.cross(n), vert1);
  normalizeOrZero(n.cross(kDn), vert2);
  const Vec3 apex1 = axispt + R * vert1, apex2 = axispt + R * vert2;
  const double dist1 = (mpt - apex1).squaredNorm(), dist2 = (mpt - apex2).squaredNorm();
  const Vec3 apex = far_side_wrap ? (dist1 < dist2 ? apex2 : apex1) : (dist1 < dist2 ? apex1 : apex2);

  // slide r1 and r2 along the axis into the plane through P1, P2 and the apex, each only when that
  // moves it toward the other end
  Vec3 uu, vv;
  normalizeOrZero(p1 - apex, uu);
  normalizeOrZero(p2 - apex, vv);
  Vec3 pn = uu.cross(vv);
  pn /= pn.norm();  // NaN when degenerate, as SimTK's UnitVec3: then nothing slides
  const double d = -p1.dot(pn);
  Vec3 r1p, r2p;
  const bool r1_inter = intersectSegmentPlane(r.r1 - 10.0 * kDn, r.r1 + 10.0 * kDn, pn, d, r1p);
  const bool r2_inter = intersectSegmentPlane(r.r2 - 10.0 * kDn, r.r2 + 10.0 * kDn, pn, d, r2p);
  if (r1_inter) {
    // OpenSim passes the point p22 as the line's direction: the axis, up to sign
    Vec3 q;
    closestPointOnLine(r1p, p11, p22, q, t);
    if ((q - p22).squaredNorm() < (p11 - p22).squaredNorm()) r.r1 = r1p;
  }
  if (r2_inter) {
    Vec3 q;
    closestPointOnLine(r2p, p11, p22, q, t);
    if ((q - p11).squaredNorm() < (p22 - p11).squaredNorm()) r.r2 = r2p;
  }

  // both tangent points beyond the cylinder's ends: no wrap
  const double half = 0.5 * L;
  if ((r.r1[2] < -half || r.r1[2] > half) && (r.r2[2] < -half || r.r2[2] > half)) return;

  makeSpiral(R, p1, p2, long_wrap, single_wrap, r);
  r.code = code;
}

}  // namespace redmax::detail
