#pragma once
// Path maps: a muscle's mass points as a function of its active path points' world positions,
// independent of how those points move (the core's J_xr, or another engine's station Jacobians).
// For the P active points stacked as x = (x_0; ...; x_{P-1}) (3P) and N mass points:
//   x_a = x_a(x),   xdot_a = J_ax xdot,   xddot_a = J_ax xddot + Jdot_ax xdot
// with J_ax (3N x 3P) the Type I weights ((1 - alpha) I, alpha I) [D Eq. 5.10] for two active
// points, and the EOL construction J_ax = J_az (I; J_sx) [D Eq. 5.15, 5.23, 5.34] otherwise.
// The core's muscle Jacobian factors through it: J_ar = J_ax J_xr and
// Jdot_ar = Jdot_ax J_xr + J_ax Jdot_xr [D Eq. 5.4-5.5].
//
// The formulas are those of straight.hpp and via_point.hpp, run on a MuscleKinematics whose
// "coordinates" are the 3P point coordinates themselves (J_xr = I, Jdot_xr = 0), so nothing here
// re-derives them.
#include <string>
#include <vector>

#include "core/muscles/muscle_workspace.hpp"

namespace redmax {

/// Output (and scratch) of calcPathMap for one muscle. Reuse one per muscle: buffers are resized
/// only when P or N change.
struct PathMap {
  std::vector<Vec3> x_a;   // mass point positions, world                                  (N)
  MatX J_ax;               // d x_a / d x                                              (3N x 3P)
  MatX Jdot_ax;            // d/dt J_ax (valid with velocity)                          (3N x 3P)
  VecX Jdot_ax_xdot;       // bias Jdot_ax xdot (valid with velocity)                       (3N)
  bool velocity = false;   // true when Jdot_ax and the bias are valid
  MuscleKinematics mk;     // scratch: the path and Eulerian stages in point coordinates
};

/// Path map of a muscle's mass points `mp` for active path points at world positions x (P >= 2)
/// and, when xdot is non-null, velocities xdot (P, world, m/s). Throws MuscleError naming
/// `muscle_name` for a zero-length path or segment, std::invalid_argument for P < 2, sizes that
/// differ or an empty `mp`.
void calcPathMap(const std::vector<Vec3>& x, const std::vector<Vec3>* xdot, const MassPoints& mp,
                 PathMap& pm, const std::string& muscle_name = "");

/// Mass point accelerations xddot_a = J_ax xddot + Jdot_ax xdot (3N) from stacked path point
/// accelerations xddot (3P), after calcPathMap with velocities.
VecX calcMassPointAccelerations(const PathMap& pm, const VecX& xddot);

/// Stack P points into a 3P vector (x_0; x_1; ...).
VecX stackPoints(const std::vector<Vec3>& x);

// ---- Type III: one wrapping segment ----------------------------------------------------------
// The mass points of a segment x1 -> (surface s) -> x2 as a function of its end points and of the
// surface's pose (R = R_ws, p = p_ws, world), for engines that move the surface themselves (a
// Simbody frame). With r_i = x_i - p, the end points in s are p_i = R^T r_i, the wrap model gives
// w(p1, p2, alpha) and Jw = (Jw1, Jw2) in s [D Eq. 5.38, 5.44], and x_a = R w + p [D Eq. 5.39-5.41].
// The inputs' velocities are v = (xdot1, xdot2, omega, pdot) (12, world; omega the surface's
// angular velocity, pdot its origin's velocity). With B_i = R Jw_i R^T:
//   xdot_a  = J v,   J = (B_1, B_2, -[R w] + B_1 [r_1] + B_2 [r_2], I - B_1 - B_2)        (3 x 12)
//   xddot_a = J vdot + b,  vdot = (xddot1, xddot2, alpha, pddot),
//   b = w x (w x R w) + 2 w x (R Jw pdot_s) + R Jwdot pdot_s + R Jw pddot_s|_(vdot = 0)
// with pdot_s = (p1dot, p2dot), p_idot = R^T (rdot_i - w x r_i), pddot_i|_(vdot = 0) =
// -R^T (w x (rdot_i - w x r_i) + w x rdot_i), rdot_i = xdot_i - pdot, w = omega
// [D Eq. 5.51-5.57, written in world velocities instead of the reduced coordinates]. The wrap
// model is the core's (Muscle::wrap through calcWrapModelPoints, core/muscles/wrap_muscle.hpp):
// smooth or neural (exact J, Jwdot) or the exact library with finite differences.

/// Velocities of a wrapping segment's inputs (world; m/s, rad/s).
struct WrapSegmentVelocity {
  Vec3 xdot1 = Vec3::Zero(), xdot2 = Vec3::Zero();  ///< end points
  Vec3 omega = Vec3::Zero();                        ///< surface angular velocity
  Vec3 pdot = Vec3::Zero();                         ///< surface origin velocity
};

/// Output of calcWrapPathMap for one muscle (N mass points).
struct WrapPathMap {
  std::vector<Vec3> x_a;  ///< mass point positions, world                                    (N)
  MatX J;                 ///< d xdot_a / d v, columns (xdot1, xdot2, omega, pdot)       (3N x 12)
  VecX bias;              ///< b = xddot_a at vdot = 0 (valid with velocity)                  (3N)
  bool velocity = false;  ///< true when bias is valid
};

/// Mass points `mp` of the segment x1 -> surface -> x2 (world) for the surface at pose (R, p)
/// (world) with wrap model `wrap`; with `v` also the bias. Throws MuscleError naming
/// `muscle_name` (and the surface) for an end point inside the surface or coinciding ends,
/// std::invalid_argument for an empty `mp`.
void calcWrapPathMap(const WrapSurface& surface, const WrapMassOptions& wrap, const MassPoints& mp, const Vec3& x1,
                     const Vec3& x2, const Mat3& R, const Vec3& p, const WrapSegmentVelocity* v, WrapPathMap& out,
                     const std::string& muscle_name = "");

// ---- General path map (Types I, II, III) ------------------------------------------------------
// Any path the core takes with mass points, as a function of its P active points' world positions
// and of the poses of its W = path.wraps.size() wrap surface frames (Type I and II: W = 0). The
// inputs' velocities are v = (xdot_0, ..., xdot_{P-1}, omega_0, pdot_0, ..., omega_{W-1},
// pdot_{W-1}) (3P + 6W, world; omega_w the frame's angular velocity, pdot_w its origin's velocity):
//   xdot_a = J v,   xddot_a = J vdot + bias   (vdot: point accelerations, then (alpha_w, pddot_w)).
// Without wraps it is calcPathMap (J = J_ax, bias = Jdot_ax xdot). With wraps it is the core's
// segment construction (core/muscles/wrap_muscle.hpp: segments between the active points, the wrap
// choice of calcSegmentWraps, straight segments by the EOL construction, wrapped ones by the chain
// rule through the surface, alpha over the whole length) run on a MuscleKinematics whose
// "coordinates" are v itself: J_xr = (I 0), and for surface w J_om, J_p the selectors of its
// (omega_w, pdot_w) columns, all with zero time derivative; then J = J_ar and bias = Jdot_ar v.
// Origin -> one active surface -> insertion goes through calcWrapPathMap, which that construction
// reduces to (beta = alpha; equal to 1e-13 in tests/plugin/general_path_map_test.cpp).
// Nothing is re-derived here. The exact wrap model on a path other than origin -> one surface ->
// insertion: the core takes OpenSim's whole wrapped path (core/muscles/wrap/wrap_path.hpp) at alpha
// of its geometric length and differentiates it in q. That path depends on q only through the
// active points' world positions and the surfaces' poses (calcWrappedPathAt), so here x_a is the
// same function of the inputs, J its central differences in v's coordinates (step 1e-6 m or rad)
// and the bias its fourth-order second difference along v (displacements of 1e-4 per unit |v|,
// 1e-5 where that stencil straddles a kink of OpenSim's passes).
// Both are differences: they agree with the core's to the differences' error, not to round-off
// (docs/simbody.md gives the measured agreement).

/// Pose and spatial velocity of one wrap surface frame s (world): an input of calcGeneralPathMap.
struct SurfaceFrameState {
  Mat3 R = Mat3::Identity();  ///< R_ws
  Vec3 p = Vec3::Zero();      ///< p_ws (m)
  Vec3 omega = Vec3::Zero();  ///< angular velocity (rad/s)
  Vec3 pdot = Vec3::Zero();   ///< velocity of the frame's origin (m/s)
};

/// Output (and scratch) of calcGeneralPathMap for one muscle; reuse one per muscle.
struct GeneralPathMap {
  std::vector<Vec3> x_a;      ///< mass point positions, world                              (N)
  MatX J;                     ///< d xdot_a / d v                                (3N x (3P + 6W))
  VecX bias;                  ///< xddot_a at vdot = 0 (valid with velocity)                (3N)
  bool velocity = false;      ///< true when bias is valid
  std::vector<int> seg_wrap;  ///< per segment, the wrap object acting on it or -1 (W > 0;  (P-1)
                              ///< empty for the exact model beyond one wrapped segment)
  PathMap pm;                 ///< scratch: Types I and II
  WrapPathMap wmap;           ///< scratch: origin -> one surface -> insertion (calcWrapPathMap)
  MuscleKinematics mk;        ///< scratch: the segment construction in v's coordinates
};

/// v = (xdot_0, ..., xdot_{P-1}, omega_0, pdot_0, ...) (3P + 6W) from the point velocities and
/// the frames' omega, pdot: the vector calcGeneralPathMap's J multiplies.
VecX stackGeneralVelocities(const std::vector<Vec3>& xdot, const std::vector<SurfaceFrameState>& frames);

/// Mass points of `muscle` (its path, mass points and wrap options) for its active points `active`
/// (indices into muscle.path.points, P >= 2) at world positions x (P) with, when xdot is non-null,
/// velocities xdot (P), and its wrap surface frames `surfaces` (W = muscle.path.wraps.size(): every
/// wrap object, world; omega, pdot read only with xdot). Throws MuscleError naming the muscle for a
/// degenerate path, std::invalid_argument for sizes that do not fit.
void calcGeneralPathMap(const Muscle& muscle, const std::vector<int>& active, const std::vector<Vec3>& x,
                        const std::vector<Vec3>* xdot, const std::vector<SurfaceFrameState>& surfaces,
                        GeneralPathMap& out);

}  // namespace redmax
