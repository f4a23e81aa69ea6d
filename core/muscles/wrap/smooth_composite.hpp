#pragma once
// Several smooth wrap surfaces on one path segment (issue 22): OpenSim applies the wrap objects
// of a segment in turn and repeats the passes (up to 8, until the length settles within 0.5 mm;
// core/muscles/wrap/wrap_path.hpp), a construction with no derivative. Its converged path
// p1 -> S_1 -> S_2 -> ... -> S_K -> p2 is a fixed point: each surface wraps the segment between
// where the path leaves the surface before it and where it reaches the surface after it,
//   surface k on (e_{k-1}, s_{k+1}),  e_0 = p1, s_{K+1} = p2,
//   e_k = w_k r2_k + (1 - w_k) e_{k-1}   (where the path leaves surface k),
//   s_k = w_k r1_k + (1 - w_k) s_{k+1}   (where it reaches surface k),
// with r1_k, r2_k the tangent points of surface k's wrapped path on its segment and w_k its smooth
// model's blend weight (core/muscles/wrap/smooth.hpp). Where every w_k is 0 or 1 these are the
// library's tangent points (a surface with w = 0 is transparent: the next one sees the segment
// the library gives it), so the fixed point is the library's converged path; inside a band each
// map is C2 in its inputs, and so is the fixed point wherever it is nondegenerate (I - dF/dx
// invertible; implicit function theorem). Solved by Newton on values from one sweep of the
// passes, then lifted over Jet numbers by two Newton steps with the converged Jacobian (each step
// doubles the order of the correct Taylor terms: exact first and second derivatives).
// The path. Surface k's smooth curve c_k runs from e_{k-1} to s_{k+1} (the single-surface smooth
// model on that segment, length T_k); it starts at arc position sigma_k of the composite path,
// sigma_1 = 0, sigma_{k+1} = sigma_k + w_k (|e_{k-1} r1_k| + arc_k) (where the library's path
// leaves surface k). From sigma_{k+1} the path fades from c_k to c_{k+1} by a quintic smoothstep
// of the arc position over h_k = a b / (a + b) (a = T_k - w_k lead_k, c_k's straight tail; b =
// T_{k+1}), shorter than both, so each curve is evaluated on its own length; where every w is 0 or
// 1 both curves run along the same straight piece there, so the fade changes nothing and the
// path is the library's: p1 -> r1_1 -> arc -> r2_1 -> r1_2 -> ... -> p2. Length L = sigma_K + T_K;
// a mass point at fraction alpha sits at arc position alpha L. Positions are C2 in the inputs
// (the fade's joints are C2 in the arc position); a mass point crossing a tangent point has the
// curvature jump of the library's path there (C1), as with one surface.
// Order. The surfaces are taken along the segment in the order of the straight line's closest
// approach to each (the cylinder's axis, the other shapes' centres): the order of the library's
// converged path whenever both wrap at well separated places along the segment (Rajagopal2016's
// gastrocnemii: condyles, then shank). The order switches where two closest approaches coincide;
// there the path jumps unless a switching surface has w = 0 (the library's own passes are then
// order-dependent too).
// Inputs and derivatives. All in one frame (the world): the ends p1, p2 and each surface's pose
// (R_k, p_k: x_world = R_k x_s + p_k) with their rates. Derivatives are with respect to
// u = (p1, p2, R_1 (row-major), p_1, ..., R_K, p_K, alpha): N = 7 + 12 K inputs, the rotation
// entries taken as independent (the maps are polynomial in them), so that the chain rule to
// generalized coordinates is dR/dq_j = [J_om e_j] R, and Jdot its time derivative.
// Limits: K <= 3 (the Jet sizes instantiated); a degenerate fixed point (surfaces touching each
// other, or a path bent back so that a surface's tangent point runs through the next surface)
// throws std::invalid_argument when Newton does not converge.
#include <vector>

#include "core/geometry/wrap_surface.hpp"
#include "core/spatial/types.hpp"

namespace redmax {

/// A surface of the composition: its pose (and rate) in the common frame.
struct CompositeWrapSurface {
  const WrapSurface* surface = nullptr;
  Mat3 R = Mat3::Identity();   ///< x_common = R x_s + p
  Vec3 p = Vec3::Zero();
  Mat3 Rdot = Mat3::Zero();    ///< dR/dt ([omega] R for a rigid motion)
  Vec3 pdot = Vec3::Zero();
};

/// The composition's result (common frame). Columns of the derivatives: u of the header,
/// N = 7 + 12 K; the caller's surface order.
struct CompositeWrapResult {
  int inputs = 0;                 ///< N
  std::vector<int> order;         ///< the surfaces (caller's indices) along the segment
  std::vector<double> weights;    ///< each surface's blend weight, caller's order
  double length = 0.0;            ///< L (m)
  Eigen::RowVectorXd J_L, Jdot_L; ///< dL/du, d/dt along the inputs' rates
  double length_rate = 0.0;       ///< dL/dt
  std::vector<Vec3> x;            ///< points at the fractions
  std::vector<MatX> J, Jdot;      ///< 3 x N each
  int newton_iterations = 0;
};

/// Points at fractions `alphas` (clamped to [0, 1]) moving at `alphadots` (empty: zero) of the
/// composed path p1 -> surfaces -> p2, and its length. width: each surface's band (<= 0: 0.05 of
/// its size). Throws std::invalid_argument for 0 or more than 3 surfaces, an unsupported surface
/// (smoothWrapUnsupportedReason), or a fixed point Newton cannot find.
void calcSmoothCompositeWrap(const std::vector<CompositeWrapSurface>& surfaces, const Vec3& p1, const Vec3& p2,
                             const Vec3& p1dot, const Vec3& p2dot, const std::vector<double>& alphas,
                             const std::vector<double>& alphadots, double width, CompositeWrapResult& out);

/// Values only: the composed path's points at `alphas` and its length (for lengths and tests).
double calcSmoothCompositeWrapPoints(const std::vector<CompositeWrapSurface>& surfaces, const Vec3& p1,
                                     const Vec3& p2, const std::vector<double>& alphas, double width,
                                     std::vector<Vec3>& x);

}  // namespace redmax
