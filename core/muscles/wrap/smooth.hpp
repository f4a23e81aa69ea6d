#pragma once
// The analytic smooth wrap model (beyond the dissertation; issue 7): the exact wrapped path away
// from the contact change, blended with the straight path across a transition of given width so
// that mass-point positions are C2 in the end points, with exact first and second derivatives and
// no training.
//
// Penetration. d = size - dist(straight line p1 p2, surface core): R - distance to the axis for
// the cylinder, R - distance to the centre for the sphere. The exact library wraps exactly when
// d > 0 (with both end points outside, the closest approach then lies strictly inside the
// segment, so no other test can switch inside the blend).
// Blend. u = clamp(d / width, 0, 1), w = 6u^5 - 15u^4 + 10u^3 (quintic smoothstep: w, w', w'' are
// continuous at u = 0 and 1), x = w x_wrapped + (1 - w) x_straight. For d <= 0 the result is the
// straight path (what the exact library gives); for d >= width it is the exact wrapped path; in
// between it moves smoothly from one to the other (the error is at most |x_wrapped - x_straight|
// inside the band, which is O(width)).
// Wrapped path: the same construction as the exact library (core/muscles/wrap/wrap_surface.hpp),
// re-derived as a function template and evaluated on nested dual numbers, so J = dx/d(p1, p2) and
// Jdot = dJ/dt along (p1dot, p2dot) are exact to round-off (forward-over-forward differentiation,
// 6 passes: one per input direction, each also carrying the velocity direction).
//
// Supported: Cylinder (also with a quadrant) and Sphere without a quadrant, single wrap (OpenSim's
// algorithms as the exact library reproduces them). A quadrant cylinder is blended as above when an
// end point lies on the active side and the library wraps only on contact; when it forces a wrap
// round the active side (neither end active, or ends on opposite sides with the line passing on
// the inactive side) the model is the exact wrapped path: those switches (an end point crossing
// the quadrant plane) are not smoothed. Not supported (smoothWrapUnsupportedReason() says why):
// spheres with a quadrant, ellipsoids (OpenSim's result is a polyline of floor(chord / 1 mm)
// segments whose count changes, so even the exact path is not C1) and tori (an iterative
// closest-point search). Also not smoothed: a mass point crossing a tangent point (the path's
// curvature changes there; OpenSim's cylinder construction is not exactly tangent, so J has a
// small jump there too), and the cylinder's finite length (both tangent points beyond the ends:
// the exact library stops wrapping).
#include <string>
#include <vector>

#include "core/muscles/wrap/network.hpp"
#include "core/muscles/wrap/wrap_surface.hpp"

namespace redmax {

struct SmoothWrapOptions {
  /// transition width of the penetration d (m); <= 0: 0.05 times the radius
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

/// A muscle's mass points over one surface (frame s), with J = dx/d(p1, p2) and Jdot along
/// (p1dot, p2dot) for each; which model produced them.
struct WrapMassPoints {
  std::vector<Vec3> x;
  std::vector<Eigen::Matrix<double, 3, 6>> J, Jdot;
  bool used_network = false;  ///< false: the inputs left the network's training box (or no network)
};

/// The network's mass points at fractions alphas [D Eq. 5.38, 5.44], one batch for the muscle, with
/// exact Jdot. Inputs are scaled by 1 / radius before the network and positions back by radius
/// (wrapping is scale-equivariant; networks are trained in units of the surface size, so the
/// radius input is 1): J is scale-free, Jdot is evaluated along the scaled velocities. When the
/// scaled input leaves the network's training box, or net is null, the smooth model gives the points
/// instead (used_network false; callers warn and count, issue 7). Cylinder and sphere networks only
/// (8 inputs: origin, insertion, alpha, radius); std::invalid_argument otherwise.
void calcNetworkWrapPoints(const Mlp* net, const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                           const Vec3& p2dot, const std::vector<double>& alphas, WrapMassPoints& out, MlpWorkspace& ws,
                           const SmoothWrapOptions& fallback = {});

}  // namespace redmax
