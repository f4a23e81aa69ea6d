#pragma once
// Exact wrapping over one surface, as OpenSim 4.x computes it (the dissertation's "existing
// library" [D Sec. 5.3.3]; semantics in docs/opensim_compatibility.md §6). Everything here is in the
// surface frame s: the wrap object's own frame, whose pose in its body is WrapObject's
// (xyz_body_rotation, translation). Units are metres and radians.
//
// Surfaces (local geometry):
//   Cylinder   axis = z, centred at the origin, radius R, length L (tangent points beyond |z| > L/2
//              at both ends: no wrap).
//   Sphere     centre at the origin, radius R.
//   Ellipsoid  centre at the origin, semi-axes `dimensions` along x, y, z.
//   Torus      centre circle of radius `outer_radius` in the xy plane, tube radius `inner_radius`.
// Quadrant: axis 0/1/2 with sign +1/-1 restricts the wrap to that half space (x > 0 for "+x");
// sign 0 means "all". OpenSim's DSIGN (v >= 0 -> +1) is used for every side test.
//
// Reproduced OpenSim behaviours (re-derived from WrapCylinder/WrapSphere/WrapEllipsoid/WrapTorus):
//   - Cylinder, unconstrained: wraps only when the straight segment passes within R of the finite
//     axis segment (closest-approach parameter strictly inside (0, 1)) -> MandatoryWrap; else
//     NoWrap. Constrained: MandatoryWrap on such an intersection; Wrapped when the end points lie
//     on opposite sides of the quadrant plane and the closest point is not on the active side;
//     neither end on the active side -> the wrap goes round the active (far) side. Tangent points
//     are chosen by OpenSim's candidate table, then slid along the axis into the plane through
//     P1, P2 and the apex; long wraps (> half turn) by OpenSim's sign test. Surface length is the
//     helix sqrt((R theta)^2 + dz^2). OpenSim's slide test passes the point P2's axis projection
//     as a line direction; when that projection is the origin (P2 at z = 0 exactly) r1 does not
//     slide: reproduced. With `single_wrap` false (several wrap objects on the path)
//     OpenSim's iterative tangency correction (0.1 degree, at most 100 passes, 2 mm sampling) runs.
//   - Sphere: wraps only when both roots of the line-sphere intersection lie in (0, 1) (also with a
//     quadrant); returns Wrapped (not Mandatory) unless the constrained test finds an
//     intersection. Far-side wraps give a NEGATIVE surface length -(R (2 pi - angle)): OpenSim's
//     quirk, reproduced because the path length adds it. The arc itself goes the long way round.
//   - Ellipsoid: OpenSim's iterative tangent-point search in a plane fixed by c1 (hybrid, midpoint
//     or axial method; hybrid blends fan and axial for mu in [0.7073, 0.9]), Graphics-Gems closest
//     points, surface polyline of floor(chord / 1 mm) segments (at most 499) and its length, all in
//     coordinates scaled by 3 / sum(dimensions). Returns MandatoryWrap when it wraps.
//   - Torus: closest point of the centre circle to the line (two 1-D searches from each end, the
//     better one, quadrant-aware), then a cylinder of radius inner_radius, length 1e4, quadrant
//     "+x" pointing to the torus centre, tangent to the circle there.
// Not reproduced: OpenSim keeps the previous wrap's r1/r2 in the PathWrap and reuses them when a
// sphere's line passes within 1e-5 of the centre (we pick a fixed plane instead: history-free);
// the torus's closest point is found to 1e-12 by Newton/bisection instead of MINPACK's lmdif with
// tolerance 1e-4 (differences below lmdif's tolerance); when the torus's inner cylinder gives no
// wrap OpenSim still reports "wrapped" with no points (which inserts nothing); we report NoWrap.
#include <string>
#include <vector>

#include "core/spatial/types.hpp"

namespace redmax {

enum class WrapType { Cylinder, Sphere, Ellipsoid, Torus };

/// "cylinder", "sphere", "ellipsoid", "torus" (std::invalid_argument for anything else) and back.
WrapType parseWrapType(const std::string& name);
std::string wrapTypeName(WrapType type);

/// OpenSim PathWrap `method` (ellipsoids only)
enum class WrapMethod { Hybrid, Midpoint, Axial };

/// A wrap surface as plain data, in its own frame s.
struct WrapSurface {
  WrapType type = WrapType::Cylinder;
  double radius = 0.0;                ///< cylinder, sphere (m)
  double length = 1.0;                ///< cylinder (m)
  Vec3 dimensions = Vec3::Ones();     ///< ellipsoid semi-axes along x, y, z (m)
  double inner_radius = 0.0;          ///< torus tube radius (m)
  double outer_radius = 0.0;          ///< torus centre-circle radius (m)
  int quadrant_axis = -1;             ///< 0, 1, 2 (x, y, z); -1 = all
  int quadrant_sign = 0;              ///< +1, -1; 0 = all
  bool active = true;                 ///< inactive surfaces never wrap

  /// p (frame s, m) strictly inside the solid: cylinder radially (any z), sphere, ellipsoid, torus
  /// tube. The smooth and network wrap models refuse such an end point.
  bool contains(const Vec3& p) const;

  static WrapSurface makeCylinder(double radius, double length, int axis = -1, int sign = 0);
  static WrapSurface makeSphere(double radius, int axis = -1, int sign = 0);
  static WrapSurface makeEllipsoid(const Vec3& dimensions, int axis = -1, int sign = 0);
  static WrapSurface makeTorus(double inner_radius, double outer_radius, int axis = -1,
                               int sign = 0);
};

/// OpenSim's return codes (WrapObject::WrapAction)
enum class WrapCode { NoWrap, InsideRadius, Wrapped, MandatoryWrap };

/// How the surface arc from r1 to r2 is described.
///   Helix:    x(s) = c + Rot(axis, s phi) (r1 - c) + s h axis, s in [0, 1] (cylinder, sphere
///             (h = 0), torus (its local cylinder)); exact.
///   Polyline: the points of `polyline` (r1 first, r2 last), linear in between (ellipsoid).
enum class ArcKind { None, Helix, Polyline };

struct WrapResult {
  WrapCode code = WrapCode::NoWrap;
  Vec3 r1 = Vec3::Zero();    ///< first tangent point (on the P1 side), frame s
  Vec3 r2 = Vec3::Zero();    ///< second tangent point (on the P2 side), frame s
  /// surface length l as OpenSim adds it to the path (m); negative for a far-side sphere wrap
  double length = 0.0;
  ArcKind arc = ArcKind::None;
  Vec3 arc_center = Vec3::Zero();       ///< Helix: a point on the rotation axis
  Vec3 arc_axis = Vec3::UnitZ();        ///< Helix: unit rotation axis
  double arc_angle = 0.0;               ///< Helix: signed total rotation phi (rad)
  double arc_rise = 0.0;                ///< Helix: total advance h along the axis (m)
  std::vector<Vec3> polyline;           ///< Polyline: r1, interior points, r2
  /// Ellipsoid with a quadrant: the arc goes round the far side of its plane (the near arc would
  /// bend back toward an end point). Sphere with a quadrant: OpenSim's far-side wrap (the long way
  /// round, arc_angle = -(2 pi - short angle), the negative length quirk).
  bool far_side = false;

  /// Wrapped or MandatoryWrap: the path goes over the surface
  bool wraps() const { return code == WrapCode::Wrapped || code == WrapCode::MandatoryWrap; }
  /// geometric length of the arc (>= 0; equals |length| except for the sphere quirk)
  double arcLength() const;
  /// point of the arc at fraction s in [0, 1] of its geometric length (frame s)
  Vec3 arcPoint(double s) const;
};

struct WrapOptions {
  WrapMethod method = WrapMethod::Hybrid;  ///< ellipsoids
  /// OpenSim's WrapResult::singleWrap: true when the path has one wrap object (no cylinder
  /// tangency iterations)
  bool single_wrap = true;
};

/// Wrap the segment p_start -> p_end (frame s) over the surface. An inactive surface, or
/// degenerate input (coincident points, non-finite values), gives NoWrap.
WrapResult calcWrap(const WrapSurface& surface, const Vec3& p_start, const Vec3& p_end,
                    const WrapOptions& options = {});

/// The point at fraction alpha in [0, 1] of the total path length of p1 -> r1 -> arc -> r2 -> p2
/// (frame s; the straight segment p1 -> p2 when the result does not wrap) [D Eq. 5.38]. Alpha is
/// clamped to [0, 1]. The result must come from calcWrap(surface, p1, p2).
Vec3 calcWrappedPathPoint(const WrapSurface& surface, const WrapResult& result, const Vec3& p1,
                          const Vec3& p2, double alpha);

/// Total geometric path length |p1 r1| + arc + |r2 p2| (or |p1 p2| without a wrap), in m.
double calcWrappedPathLength(const WrapResult& result, const Vec3& p1, const Vec3& p2);

}  // namespace redmax
