// WrapCylinder as OpenSim computes it (docs/opensim_compatibility.md §6): candidate tangent points in the
// planes through P1 and P2 normal to the axis, OpenSim's choice among them, a slide along the axis
// into the plane through P1, P2 and the apex (constructions.hpp, shared with the smooth model),
// then a helix between r1 and r2.
#include <cmath>

#include "core/geometry/wrap_math.hpp"

namespace redmax::detail {
namespace {

constexpr int kMaxTangentIterations = 100;
constexpr double kTangencyThreshold = 0.1 * 3.14159265358979323846 / 180.0;  // 0.1 degree

// the axis line of OpenSim's cylinder code: through (0, 0, -1) along +z
const Vec3 kP0(0.0, 0.0, -1.0);
const Vec3 kDn(0.0, 0.0, 1.0);

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
  for (int iterations = 0;; ++iterations) {
    const double axial = r.r2[2] - r.r1[2];
    const double phi = cylinderHelixAngle(constant<double>(r.r1), constant<double>(r.r2), long_wrap);
    r.length = std::sqrt(R * phi * R * phi + axial * axial);
    r.arc = ArcKind::Helix;
    r.arc_center = Vec3::Zero();
    r.arc_axis = kDn;
    r.arc_angle = phi;
    r.arc_rise = axial;
    if (single_wrap || iterations >= kMaxTangentIterations) return;
    // OpenSim samples the helix every 2 mm and corrects the tangent points at the second sample
    const int n = static_cast<int>(r.length / 0.002);
    if (n < 2) return;
    const double ts = 1.0 / n;
    auto spiral = [&](double s) -> Vec3 { return Eigen::AngleAxisd(s * phi, kDn) * r.r1 + kDn * (s * axial); };
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

  if (sign == 0) {
    if (!intersects) return;
    code = WrapCode::MandatoryWrap;
  } else if (dsign(p1[axis]) == sign || dsign(p2[axis]) == sign) {
    // an end on the active side: a wrap on intersection, or when the ends lie on opposite sides
    // and the closest point is not on the active side; neither end active: round the active side
    if (intersects)
      code = WrapCode::MandatoryWrap;
    else if (dsign(p1[axis]) != dsign(p2[axis]) && dsign(near12[axis]) != sign)
      code = WrapCode::Wrapped;
    else
      return;
  }

  V3<double> r1, r2;
  bool long_wrap = false;
  const bool within = cylinderTangentPoints(R, L, axis, sign, constant<double>(p1), constant<double>(p2), r1, r2, long_wrap);
  r.r1 = values(r1);  // kept also without a wrap, as OpenSim's code leaves them
  r.r2 = values(r2);
  if (!within) return;  // both tangent points beyond the cylinder's ends: no wrap
  makeSpiral(R, p1, p2, long_wrap, single_wrap, r);
  r.code = code;
}

}  // namespace redmax::detail
