#include "core/muscles/wrap/wrap_surface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/muscles/wrap/wrap_geometry.hpp"

namespace redmax {

WrapType parseWrapType(const std::string& name) {
  if (name == "cylinder") return WrapType::Cylinder;
  if (name == "sphere") return WrapType::Sphere;
  if (name == "ellipsoid") return WrapType::Ellipsoid;
  if (name == "torus") return WrapType::Torus;
  throw std::invalid_argument("unknown surface '" + name + "' (expected cylinder, sphere, ellipsoid or torus)");
}

std::string wrapTypeName(WrapType type) {
  switch (type) {
    case WrapType::Cylinder: return "cylinder";
    case WrapType::Sphere: return "sphere";
    case WrapType::Ellipsoid: return "ellipsoid";
    case WrapType::Torus: return "torus";
  }
  return "?";
}

using namespace detail;

bool WrapSurface::contains(const Vec3& p) const {
  switch (type) {
    case WrapType::Cylinder: return p.head<2>().norm() < radius;
    case WrapType::Sphere: return p.norm() < radius;
    case WrapType::Ellipsoid: return p.cwiseQuotient(dimensions).squaredNorm() < 1.0;
    case WrapType::Torus: {
      const double rho = p.head<2>().norm() - outer_radius;
      return rho * rho + p[2] * p[2] < inner_radius * inner_radius;
    }
  }
  return false;
}

WrapSurface WrapSurface::makeCylinder(double radius, double length, int axis, int sign) {
  WrapSurface s;
  s.type = WrapType::Cylinder;
  s.radius = radius;
  s.length = length;
  s.quadrant_axis = sign == 0 ? -1 : axis;
  s.quadrant_sign = sign;
  return s;
}

WrapSurface WrapSurface::makeSphere(double radius, int axis, int sign) {
  WrapSurface s;
  s.type = WrapType::Sphere;
  s.radius = radius;
  s.quadrant_axis = sign == 0 ? -1 : axis;
  s.quadrant_sign = sign;
  return s;
}

WrapSurface WrapSurface::makeEllipsoid(const Vec3& dimensions, int axis, int sign) {
  WrapSurface s;
  s.type = WrapType::Ellipsoid;
  s.dimensions = dimensions;
  s.quadrant_axis = sign == 0 ? -1 : axis;
  s.quadrant_sign = sign;
  return s;
}

WrapSurface WrapSurface::makeTorus(double inner_radius, double outer_radius, int axis, int sign) {
  WrapSurface s;
  s.type = WrapType::Torus;
  s.inner_radius = inner_radius;
  s.outer_radius = outer_radius;
  s.quadrant_axis = sign == 0 ? -1 : axis;
  s.quadrant_sign = sign;
  return s;
}

double WrapResult::arcLength() const {
  switch (arc) {
    case ArcKind::None: return 0.0;
    case ArcKind::Helix: {
      // radius of r1 about the axis times the turned angle, and the rise: a helix
      const Vec3 d = r1 - arc_center;
      const double rho = (d - d.dot(arc_axis) * arc_axis).norm();
      return std::hypot(rho * arc_angle, arc_rise);
    }
    case ArcKind::Polyline: {
      double l = 0.0;
      for (size_t k = 1; k < polyline.size(); ++k) l += (polyline[k] - polyline[k - 1]).norm();
      return l;
    }
  }
  return 0.0;
}

Vec3 WrapResult::arcPoint(double s) const {
  s = std::clamp(s, 0.0, 1.0);
  switch (arc) {
    case ArcKind::None: return r1 + s * (r2 - r1);
    case ArcKind::Helix: {
      // a helix has constant speed, so the parameter is the arc-length fraction
      const Eigen::AngleAxisd rot(s * arc_angle, arc_axis);
      return arc_center + rot * (r1 - arc_center) + (s * arc_rise) * arc_axis;
    }
    case ArcKind::Polyline: {
      if (polyline.size() < 2) return r1;
      const double total = arcLength();
      double target = s * total;
      for (size_t k = 1; k < polyline.size(); ++k) {
        const double seg = (polyline[k] - polyline[k - 1]).norm();
        if (target <= seg || k + 1 == polyline.size()) {
          const double f = seg > 0.0 ? std::clamp(target / seg, 0.0, 1.0) : 0.0;
          return polyline[k - 1] + f * (polyline[k] - polyline[k - 1]);
        }
        target -= seg;
      }
      return polyline.back();
    }
  }
  return r1;
}

WrapResult calcWrap(const WrapSurface& surface, const Vec3& p_start, const Vec3& p_end,
                    const WrapOptions& options) {
  WrapResult r;
  if (!surface.active || !p_start.allFinite() || !p_end.allFinite() || p_start == p_end) return r;
  switch (surface.type) {
    case WrapType::Cylinder:
      wrapCylinder(surface.radius, surface.length, surface.quadrant_axis, surface.quadrant_sign,
                   p_start, p_end, options.single_wrap, r);
      break;
    case WrapType::Sphere: wrapSphere(surface, p_start, p_end, r); break;
    case WrapType::Ellipsoid: wrapEllipsoid(surface, p_start, p_end, options.method, r); break;
    case WrapType::Torus: wrapTorus(surface, p_start, p_end, options.single_wrap, r); break;
  }
  if (!r.wraps()) {
    r.arc = ArcKind::None;
    r.length = 0.0;
    r.polyline.clear();
  }
  return r;
}

double calcWrappedPathLength(const WrapResult& result, const Vec3& p1, const Vec3& p2) {
  if (!result.wraps()) return (p2 - p1).norm();
  return (result.r1 - p1).norm() + result.arcLength() + (p2 - result.r2).norm();
}

Vec3 calcWrappedPathPoint(const WrapSurface& /*surface*/, const WrapResult& result, const Vec3& p1,
                          const Vec3& p2, double alpha) {
  alpha = std::clamp(alpha, 0.0, 1.0);
  if (!result.wraps()) return p1 + alpha * (p2 - p1);
  // walk the three pieces by arc length [D Eq. 5.38]
  const double l1 = (result.r1 - p1).norm();
  const double la = result.arcLength();
  const double l2 = (p2 - result.r2).norm();
  const double total = l1 + la + l2;
  if (!(total > 0.0)) return p1;
  double s = alpha * total;
  if (s <= l1) return l1 > 0.0 ? Vec3(p1 + (s / l1) * (result.r1 - p1)) : result.r1;
  s -= l1;
  if (s <= la) return result.arcPoint(la > 0.0 ? s / la : 0.0);
  s -= la;
  return l2 > 0.0 ? Vec3(result.r2 + std::min(1.0, s / l2) * (p2 - result.r2)) : result.r2;
}

}  // namespace redmax
