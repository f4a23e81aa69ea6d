#pragma once
// Path points of a musculotendon: active set, world positions and velocities [D Eq. 5.8], their
// Jacobians J_xr = J_xm J_mr and d/dt [D Eq. 5.9, 5.11, 5.37], plus the moving-point terms, and
// the path length and lengthening speed.
//
// For a point at x_b(q) in body b with pose (R, p):
//   x_w    = R x_b + p
//   xdot_w = R Gamma(x_b) phi_b + R x_b'(q_k) qdot_k                          [D Eq. 5.8]
//   J_xr   = R Gamma(x_b) J_mr(b) + R x_b' e_k^T
//   Jdot_xr = R ([omega] Gamma(x_b) + Gamma(xdot_b)) J_mr(b) + R Gamma(x_b) Jdot_mr(b)
//             + R ([omega] x_b' + x_b'' qdot_k) e_k^T                          [D Eq. 5.11]
// with Gamma(xdot_b) = ([xdot_b]^T 0) and xdot_b = x_b' qdot_k (moving points only).
#include "core/muscles/muscle_workspace.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// Active points, x_b, x_w, J_xm blocks, J_xr, segment lengths and directions, path length; with
/// `velocity` also xdot_w, Jdot_xm, Jdot_xr, ldot and the lengthening speed. Needs the skeleton
/// workspace at Stage::Position (Stage::Velocity with `velocity`) for the same state.
void calcPathPoints(const Model& model, const State& state, const SkeletonWorkspace& sk,
                    const MusclePath& path, MuscleKinematics& mk, bool velocity = true);

/// Segment stage of calcPathPoints from mk.x_w (and mk.xdot_w with `velocity`) alone: l, dxbar,
/// length (and ldot, lengthening_speed) [D Eq. 5.17-5.19, 5.27]. Used by core/muscles/path_map.hpp,
/// which fills the points from another source.
void calcPathSegments(MuscleKinematics& mk, bool velocity);

/// Path length (m) at configuration q from body poses only (no Jacobians), e.g. for length
/// reports: polyline through the active points; with wrap objects in `path.wraps`, OpenSim's
/// wrapped length (calcWrappedPath in core/muscles/wrap/wrap_path.hpp); a path that only counts
/// its wraps (num_wraps > 0, wraps empty) gets the polyline. E_wi from calcBodyPoses(model, q, E_wi).
double calcPathLength(const Model& model, const MusclePath& path, const VecX& q,
                      const std::vector<Mat4>& E_wi);

/// The points of `path` active at q (indices into path.points, conditional points switched as
/// isPathPointActive says) and their world positions from the body poses E_wi at q.
void calcActivePoints(const MusclePath& path, const VecX& q, const std::vector<Mat4>& E_wi, std::vector<int>& active,
                      std::vector<Vec3>& x_w);

/// Location of point p in its body frame at q, with d/dq and d2/dq2 along its coordinate (zero
/// unless it is a moving point with a coordinate, inside its clamp range).
void calcPointLocation(const PathPoint& p, const VecX& q, Vec3& x_b, Vec3& dx_b, Vec3& ddx_b);

/// d(location)/dq of a moving point (body frame) at its coordinate's value q_c as given, not
/// clamped: OpenSim's MovingPathPoint::getdPointdQ and getVelocity, which differentiate at the
/// unclamped value while the location is clamped to the range. Zero for other points.
Vec3 calcPointLocationDerivativeUnclamped(const PathPoint& p, double q_c);

}  // namespace redmax
