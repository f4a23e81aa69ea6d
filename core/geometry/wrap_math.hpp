#pragma once
// Internal helpers of the exact wrap library (core/geometry/): OpenSim's WrapMath primitives
// re-derived, and one routine per surface type. All in the surface frame. Not a public API: use
// calcWrap() from wrap_surface.hpp.
#include "core/geometry/constructions.hpp"
#include "core/geometry/wrap_surface.hpp"

namespace redmax::detail {

/// out = v / |v| (zero when |v| < machine epsilon); returns |v|
double normalizeOrZero(const Vec3& v, Vec3& out);

/// closest point on the line through line_pt with direction `line` (any length) to pt; t is the
/// parameter in units of |line| (OpenSim's GetClosestPointOnLineToPoint)
void closestPointOnLine(const Vec3& pt, const Vec3& line_pt, const Vec3& line, Vec3& closest,
                        double& t);

/// squared distance from point to the line through line_pt along `line`
double distanceSquaredToLine(const Vec3& point, const Vec3& line_pt, const Vec3& line);

/// closest points of the lines p1p2 and p3p4: pint1 = p1 + s (p2 - p1), pint2 = p3 + t (p4 - p3).
/// False (s = t = NaN, outputs untouched) when the lines are parallel within 2e-13.
bool intersectLines(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& p4, Vec3& pint1,
                    double& s, Vec3& pint2, double& t);

/// intersection of segment pt1pt2 with the plane n.x + d = 0 (tolerance 1e-5 on the parameter)
bool intersectSegmentPlane(const Vec3& pt1, const Vec3& pt2, const Vec3& n, double d, Vec3& inter);

/// cylinder along z centred at the origin; axis/sign the quadrant (sign 0: all)
void wrapCylinder(double radius, double length, int axis, int sign, const Vec3& p1, const Vec3& p2,
                  bool single_wrap, WrapResult& r);
void wrapSphere(const WrapSurface& s, const Vec3& p1, const Vec3& p2, WrapResult& r);
void wrapEllipsoid(const WrapSurface& s, const Vec3& p1, const Vec3& p2, WrapMethod method,
                   WrapResult& r);
void wrapTorus(const WrapSurface& s, const Vec3& p1, const Vec3& p2, bool single_wrap,
               WrapResult& r);

/// OpenSim's WrapEllipsoid closest point on the ellipsoid (x/a)^2 + (y/b)^2 + (z/c)^2 = 1 to
/// (u, v, w) (Graphics Gems IV, with OpenSim's coordinate-plane special cases; special_axis >= 0
/// forces the cross-section normal to that axis). Leaves `x` untouched and returns -1 when the
/// general iteration does not converge in 64 steps.
double closestPointOnEllipsoid(const Vec3& abc, const Vec3& uvw, Vec3& x, int special_axis = -1);

}  // namespace redmax::detail
