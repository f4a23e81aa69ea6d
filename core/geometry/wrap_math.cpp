#include "core/geometry/wrap_math.hpp"

#include <cmath>
#include <limits>

namespace redmax::detail {

double normalizeOrZero(const Vec3& v, Vec3& out) {
  const double mag = v.norm();
  // OpenSim's threshold is SimTK::Eps, the machine epsilon
  if (mag >= std::numeric_limits<double>::epsilon())
    out = v / mag;
  else
    out.setZero();
  return mag;
}

void closestPointOnLine(const Vec3& pt, const Vec3& line_pt, const Vec3& line, Vec3& closest,
                        double& t) {
  Vec3 v1, v2;
  const double mag = normalizeOrZero(pt - line_pt, v1);
  const double mag2 = normalizeOrZero(line, v2);
  t = v1.dot(v2) * mag;
  closest = line_pt + t * v2;
  t = t / mag2;
}

double distanceSquaredToLine(const Vec3& point, const Vec3& line_pt, const Vec3& line) {
  const Vec3 d = line_pt - point;
  const Vec3 n = line.normalized();
  return (d - d.dot(n) * n).squaredNorm();
}

bool intersectLines(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& p4, Vec3& pint1,
                    double& s, Vec3& pint2, double& t) {
  Vec3 v1, v2;
  const double mag1 = normalizeOrZero(p2 - p1, v1);
  const double mag2 = normalizeOrZero(p4 - p3, v2);
  const Vec3 c = v1.cross(v2);
  const double denom = c.squaredNorm();
  if (std::abs(denom) <= 2e-13) {  // OpenSim's EQUAL_WITHIN_ERROR (ROUNDOFF_ERROR)
    s = t = std::numeric_limits<double>::quiet_NaN();
    return false;
  }
  // Cramer's rule on the 3x3 systems of the two closest-approach conditions
  Mat3 m;
  m.row(0) = (p3 - p1).transpose();
  m.row(1) = v1.transpose();
  m.row(2) = c.transpose();
  t = m.determinant() / denom;
  pint2 = p3 + t * v2;
  m.row(1) = v2.transpose();
  s = m.determinant() / denom;
  pint1 = p1 + s * v1;
  s /= mag1;
  t /= mag2;
  return true;
}

bool intersectSegmentPlane(const Vec3& pt1, const Vec3& pt2, const Vec3& n, double d, Vec3& inter) {
  constexpr double kLineEps = 1e-5;
  const Vec3 v = pt2 - pt1;
  const double dp = v.dot(n);
  if (std::abs(dp) < kLineEps) return false;
  const double t = (-d - n.dot(pt1)) / dp;
  if (t < -kLineEps || t > 1.0 + kLineEps) return false;
  inter = pt1 + t * v;
  return true;
}

}  // namespace redmax::detail
