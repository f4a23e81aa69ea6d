#pragma once
// The analytic smooth wrap model (beyond the dissertation; issue 7): the exact wrapped path away
// from the contact change, blended with the straight path across a transition of given width so
// that mass-point positions are C2 in the end points, with exact first and second derivatives and
// no training.
//
// Penetration. d = size - dist(straight line p1 p2, surface core): R - distance to the axis for
// the cylinder, R - distance to the centre for the sphere, the tube radius - distance to the axis
// of the torus's local cylinder (below). The exact library wraps exactly when
// d > 0 (with both end points outside, the closest approach then lies strictly inside the
// segment, so no other test can switch inside the blend).
// Blend. u = clamp(d / width, 0, 1), w = 6u^5 - 15u^4 + 10u^3 (quintic smoothstep: w, w', w'' are
// continuous at u = 0 and 1), x = w x_wrapped + (1 - w) x_straight. For d <= 0 the result is the
// straight path (what the exact library gives); for d >= width it is the exact wrapped path; in
// between it moves smoothly from one to the other (the error is at most |x_wrapped - x_straight|
// inside the band, which is O(width)).
// Wrapped path: the exact library's own construction for cylinders, spheres and tori (the function
// templates of core/geometry/constructions.hpp, which the library runs on double) evaluated on
// Jet numbers (core/geometry/dual.hpp: value, velocity derivative, all 6 or 7 input partials and
// their velocity derivatives in one pass), so J = dx/d(p1, p2) and Jdot = dJ/dt along (p1dot,
// p2dot) are exact to round-off; ellipsoids below. The alpha-independent construction is built
// once per segment and shared by its mass points (calcSmoothWrapPoints). The earlier route
// (nested duals, one pass per input direction, per point) stays as smooth_reference.
//
// End points near the surface. As an end point nears the surface the tangent point runs into it
// like sqrt(clearance): the wrapped path's derivatives grow without bound and are infinite on the
// surface, and OpenSim (the exact library) straightens the path once the end is inside
// (InsideRadius). The weight is therefore multiplied by a second quintic smoothstep of the smaller
// end clearance over the same width (clearance measured as the InsideRadius test measures it: from
// the infinite cylinder, from the sphere, from the ellipsoid in units of its smallest semi-axis) over
// a narrow band, 0.02 of the width (models place path points close to their surfaces: a wide fade
// would move many real poses off OpenSim's path), so the path turns straight, C2, before an end
// reaches the surface. Outside both bands the path is the exact one. (The torus uses its own rule:
// no wrap with an end inside its local cylinder, below.)
// Supported: Cylinder, Sphere and Ellipsoid (also with a quadrant) and Torus, single wrap
// (OpenSim's algorithms as the exact library reproduces them).
// Quadrant cylinders. The library wraps on contact (d > 0) when an end lies on the active side;
// it also forces a wrap round the active side when neither end is active, or when the ends lie on
// opposite sides of the quadrant plane and the line's point nearest the axis ("foot") lies on
// the inactive side, whatever the sign of d. Forced wraps are the exact path (w = 1), so the model
// is continuous where the library is, e.g. across d = 0 with the foot on the inactive side. The
// contact-driven wrap is blended with a band that narrows as the foot nears the quadrant plane,
// u = d / width * max(1, k R / foot) (k = 0.25, foot > 0 on the active side), so the weight
// reaches 1 before the forced side begins. Not smoothed (the library itself jumps there): an end
// point crossing the quadrant plane with neither end then active, the foot crossing the plane
// with d < 0, and the library's candidate-table flips near the plane.
// Quadrant spheres. The library wraps only where the segment crosses the sphere (d > 0), quadrant
// or not; it then picks its tangent points by discrete tests (core/geometry/sphere.cpp): with
// both ends on the active side the unconstrained pair; with an end on the inactive side the
// candidates facing away from the ends' midpoint, flipped to the others where the path would bend
// away from the active side, and the long way round where the arc would face away from the ends
// (the far side). The model runs the library on values, takes the candidates and the side it
// chose, and builds the same construction over Jet numbers, blended by d as without a quadrant.
// Where the line passes on the inactive side the library's path jumps at contact from the straight
// line onto a wrap round the active side (up to a diameter): the blend spreads that jump over the
// band (C2, |J| of the jump over the width there). Not smoothed, because the library itself jumps
// there and the model equals it outside the band: its side switch inside the wrapped region (the
// bend of its chosen path crossing the quadrant plane), an end crossing the quadrant plane, and
// OpenSim's intersection test with an end on the active side, which compares the distance from p1
// to the line's point nearest the centre (in metres) with 1 as if it were a fraction: beyond 1 m
// the library gives no wrap unless the ends lie on opposite sides with that point on the inactive
// side. The model's length is the geometric one (calcWrappedPathLength), not OpenSim's negative
// far-side surface length.
// Tori. The library anchors a quadrant "+x" cylinder of the tube radius (length 1e4) at the point
// of the centre circle nearest the line, found by a 1-D search from each end (the better one);
// the model runs the same search on values, then refines the chosen solution over the dual
// numbers by two Newton steps (implicit function theorem: exact first and second derivatives of
// the solution); the search ends at a root of OpenSim's residual or, where the residual has no
// root near (7% of the default box), at a stationary point of it, and that condition is the one
// differentiated. The rest is the smooth quadrant cylinder in the anchor's frame. Equal to the
// library outside the band to 1e-12 at roots and to 1.2e-7 of the tube size at stationary points
// (the library's search locates those only to ~1e-9 in u; the residual is flat there). Not
// smoothed: the switch between the two ends' solutions, and an end entering the local cylinder
// (the library then gives no wrap).
// Ellipsoids (hybrid method, the library's default). In the library's scaled
// coordinates: the chord's crossing points, the plane point c1 (axial cross-section closest point,
// fan of 298 closest points, their linear blends and fades by the chord direction), the plane
// through p1, p2 and c1, the tangent points in it, the surface curve between them. Each closest
// point is the library's Newton iteration on values, polished, then refined over the dual numbers
// by two Newton steps (implicit function theorem). The tangent points, which the library finds by
// damped Gauss-Newton to a residual of 1e-4, are here the closed-form intersection of the plane,
// the end point's polar plane and the ellipsoid (the root nearer c1). The library's polyline of
// floor(chord / 1 mm) segments (at most 499) is replaced by its limit, the plane curve itself
// (rays from the library's point a0), with its arc length by 8 x 8-point Gauss-Legendre and the
// point at a given arc length by Newton steps (polished on values, two over T). Positions equal
// the library's outside the band to the library's own accuracy: on the default box, |smooth -
// exact| / smallest semi-axis has median 5.7e-6, 99th percentile 9.6e-5, max 3.3e-3; path lengths
// median 1.6e-7, 99th percentile 6.8e-6. J and Jdot are exact derivatives of this model. Not
// smoothed (the library's own kinks and jumps, J jumps there): the hybrid method's linear blend
// in the chord direction (mu in [0.7073, 0.9]) and its fade near the chord's ends, a fan sample
// switching between roots of the closest-point equation (interior points), and the library's
// "same direction seen from the centre" cut-off.
// Quadrant ellipsoids. The library wraps on the same contact as without a quadrant, but c1 is
// mirrored onto the active side when it lies on the other, then pulled toward the quadrant plane
// by the fan's weight and put back on the surface; its tangent searches start from the mirrored
// c1 (whose basin need not hold the nearer root, so the model runs the library on values and takes,
// in closed form, the roots it converged to); and where the near arc's first or last 1 mm segment
// bends back toward its end point the library goes round the far side (the same plane swept
// 2 pi - phi0 the other way), which the model takes from that run (WrapResult::far_side). Equal
// to the library outside the band (default box, random quadrants: median 6.2e-6, 99th percentile
// 1.2e-4, max 5.4e-4 of the smallest semi-axis) except where the library's own construction
// breaks (its rays' origin outside the ellipsoid: its polyline jumps; or a tangent search that
// does not converge: NaN), 6 of 409 wrapped samples, where neither is a path. Not smoothed, as
// in the library: the mirror switching sides, the roots' basins, the far-side switch.
// Cost: measured in docs/performance.md §7 (validation/bench/wrap_model_bench.cpp).
// Penetration of an ellipsoid: 1 - the line's distance from the centre in coordinates divided by
// the semi-axes, times the smallest semi-axis (> 0 exactly when the library wraps).
// Not supported (smoothWrapUnsupportedReason() says why): inactive surfaces and non-positive sizes.
// Also not smoothed: a mass point crossing a tangent point (the path's curvature changes there;
// OpenSim's cylinder construction is not exactly tangent, so J has a small jump there too), and
// the cylinder's finite length (both tangent points beyond the ends: the exact library stops
// wrapping).
#include <string>
#include <vector>

#include "core/geometry/wrap_surface.hpp"

namespace redmax {

struct SmoothWrapOptions {
  /// transition width of the penetration d (m); <= 0: 0.05 times the surface size (cylinder and
  /// sphere radius, torus tube radius, smallest ellipsoid semi-axis)
  double width = 0.0;
};

/// Mass point of the smooth model with its derivatives, all in the surface frame s.
struct SmoothWrapPoint {
  Vec3 x = Vec3::Zero();                           ///< position (m)
  Eigen::Matrix<double, 3, 6> J = Eigen::Matrix<double, 3, 6>::Zero();     ///< dx / d(p1, p2)
  Eigen::Matrix<double, 3, 6> Jdot = Eigen::Matrix<double, 3, 6>::Zero();  ///< dJ/dt along (p1dot, p2dot)
  double penetration = 0.0;  ///< d (m); > 0: the exact library wraps
  double weight = 0.0;       ///< blend weight w of the wrapped path
};

/// Clearance of point p (surface frame, m) outside the surface as the end-point fade measures it:
/// from the infinite cylinder, from the sphere, from the ellipsoid in units of its smallest semi-axis;
/// a huge value for the torus.
double calcWrapEndClearance(const WrapSurface& surface, const Vec3& p);

/// The end-point fade's band (m): the wrapped path fades to the straight one as the smaller end
/// clearance falls from this to 0 (0.02 of the penetration band's width).
double smoothWrapEndFadeWidth(const WrapSurface& surface, const SmoothWrapOptions& options = {});

/// "" when the smooth model handles the surface, otherwise why not.
std::string smoothWrapUnsupportedReason(const WrapSurface& surface);

/// Penetration d of the straight segment into the surface (m), see the file header.
double calcWrapPenetration(const WrapSurface& surface, const Vec3& p1, const Vec3& p2);

/// Position of the mass point at arc fraction alpha (frame s). std::invalid_argument for an
/// unsupported surface or an end point inside it.
Vec3 calcSmoothWrapPoint(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, double alpha,
                         const SmoothWrapOptions& options = {});

/// Position, Jacobian and its time derivative along the end-point velocities (frame s).
SmoothWrapPoint calcSmoothWrapPointDerivatives(const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                               double alpha, const Vec3& p1dot, const Vec3& p2dot,
                                               const SmoothWrapOptions& options = {});

/// A smooth-model point with its arc fraction as a seventh input (frame s), for mass points whose
/// fraction within a wrapped segment of a longer path moves (core/muscles/wrap_muscle.hpp).
struct SmoothWrapSegmentPoint {
  Vec3 x = Vec3::Zero();                                                   ///< position (m)
  Eigen::Matrix<double, 3, 7> J = Eigen::Matrix<double, 3, 7>::Zero();     ///< dx / d(p1, p2, alpha)
  Eigen::Matrix<double, 3, 7> Jdot = Eigen::Matrix<double, 3, 7>::Zero();  ///< dJ/dt along (p1dot, p2dot, alphadot)
};

/// calcSmoothWrapPointDerivatives with alpha (in [0, 1]) differentiated too, moving at alphadot.
SmoothWrapSegmentPoint calcSmoothWrapSegmentPoint(const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                                  double alpha, const Vec3& p1dot, const Vec3& p2dot,
                                                  double alphadot, const SmoothWrapOptions& options = {});

/// The smooth model's length of the segment p1 -> p2 (frame s): L = L_straight + w (L_wrapped -
/// L_straight) with the blend weight w of the points, so the exact library's |p1 r1| + arc + |r2 p2|
/// outside the band and C2 across it (m); J = dL/d(p1, p2), Jdot = dJ/dt along (p1dot, p2dot).
struct SmoothWrapLength {
  double length = 0.0;
  Eigen::Matrix<double, 1, 6> J = Eigen::Matrix<double, 1, 6>::Zero();
  Eigen::Matrix<double, 1, 6> Jdot = Eigen::Matrix<double, 1, 6>::Zero();
};
SmoothWrapLength calcSmoothWrapLength(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                                      const Vec3& p2dot, const SmoothWrapOptions& options = {});

/// A muscle's mass points over one surface (frame s), with J = dx/d(p1, p2) and Jdot along
/// (p1dot, p2dot) for each; which model produced them (the network's: calcNetworkWrapModel,
/// core/muscles/wrap/network_model.hpp).
struct WrapMassPoints {
  std::vector<Vec3> x;
  std::vector<Eigen::Matrix<double, 3, 6>> J, Jdot;
  bool used_network = false;  ///< false: the inputs left the network's training box (or no network)
};

/// A muscle's mass points on one wrapped segment p1 -> p2 (frame s) at fractions `alphas` (each
/// clamped to [0, 1]) moving at `alphadots` (empty: all zero): x, J = dx/d(p1, p2) and Jdot along
/// (p1dot, p2dot, alphadots), and (when given) x_alpha = dx/dalpha and its time derivative
/// x_alphadot. The alpha-independent construction (penetration, blend weight, tangent points, arc;
/// ellipsoid plane and arc-length table; torus anchor) is built once for all points, over Jet
/// numbers (core/geometry/dual.hpp) that carry every input direction in one pass. Equal to the
/// per-point nested-dual route (smooth_reference) to round-off (tests/core/muscles/
/// wrap_smooth_shared_test.cpp). Throws as calcSmoothWrapPoint.
void calcSmoothWrapPoints(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                          const Vec3& p2dot, const std::vector<double>& alphas, const std::vector<double>& alphadots,
                          const SmoothWrapOptions& options, WrapMassPoints& out, std::vector<Vec3>* x_alpha = nullptr,
                          std::vector<Vec3>* x_alphadot = nullptr);

/// The smooth model's derivatives as computed before issue 18: nested dual numbers, one pass per
/// input direction, the whole construction per point. Kept as the reference the tests compare
/// the shared route with (same signatures and meaning as the functions above).
namespace smooth_reference {
SmoothWrapPoint calcSmoothWrapPointDerivatives(const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                               double alpha, const Vec3& p1dot, const Vec3& p2dot,
                                               const SmoothWrapOptions& options = {});
SmoothWrapSegmentPoint calcSmoothWrapSegmentPoint(const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                                  double alpha, const Vec3& p1dot, const Vec3& p2dot,
                                                  double alphadot, const SmoothWrapOptions& options = {});
SmoothWrapLength calcSmoothWrapLength(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                                      const Vec3& p2dot, const SmoothWrapOptions& options = {});
}  // namespace smooth_reference

}  // namespace redmax
