#pragma once
// Type III mass points: a muscle whose path wraps over surfaces [D Sec. 5.3.3, Eq. 5.38-5.57].
//
// Supported shapes (wrapMassPointsUnsupportedReason() says why another is refused; validateMuscle
// throws it): any path points (fixed, conditional, moving) and any wrap objects, with
//   Smooth  every active surface one the smooth model takes (smoothWrapUnsupportedReason); where
//           wrap ranges share a segment, up to three cylinders and spheres, composed there
//           (core/muscles/wrap_composite.hpp, issue 22);
//   Exact   anything the exact library takes (several wraps on one segment included).
//
// Segments. The active path points split the path into segments (i, i+1). A wrap object acts on
// one segment within its range: Smooth picks the candidate segment whose straight line penetrates
// the surface most (OpenSim tries every segment of the range and keeps a mandatory wrap or the
// smallest length change; the two agree whenever one segment meets the surface, and the choice
// only switches where the penetrations are equal, which is continuous while both are <= 0). A
// segment with an end inside the surface takes no wrap (OpenSim's InsideRadius; the points jump
// there as OpenSim's path does), except on origin -> surface -> insertion, where it is an error.
// Segment lengths L_i: straight |x_{i+1} - x_i|, or the wrap model's length of the wrapped segment
// (smooth: exact wrapped length outside the band, blended inside). Mass points keep their arc
// fraction alpha of the whole length: s_i = (L_0 + ... + L_{i-1}) / sum L (Eulerian coordinates of
// the path points, as Type II's equal strain gives over a polyline, core/muscles/via_point.hpp);
// a point with s_i <= alpha < s_{i+1} sits at beta = (alpha - s_i) / (s_{i+1} - s_i) of its
// segment [D Eq. 5.29]. J_s, Jdot_s follow from differentiating s_i = S_i / sum L.
//   straight segment  x_a = (1 - beta) x_i + beta x_{i+1}, J_ar = J_az J_zr with via_point's
//                     calcJ_az / calcJdot_az [D Eq. 5.30-5.36] (EOL sliding across via points);
//   wrapped segment   x_a = R w(p1, p2, beta) + p over its surface (below), beta moving with
//                     J_beta = -((1 - beta) J_s_i + beta J_s_{i+1}) / Delta s.
//
// Chain rule through a surface. The surface frame s moves rigidly with its body b: E_ws = E_wb
// E_bs (R = R_ws, p = p_ws). The segment's ends in s are p1 = R^T (x_i - p), p2 = R^T (x_{i+1} - p)
// [D Eq. 5.39-5.41], the wrap model gives w(p1, p2, beta) in s with Jw = (Jw1, Jw2) = dw/d(p1, p2)
// and w_b = dw/dbeta [D Eq. 5.38, 5.44], and the mass point is x_a = R w + p. With omega the body's
// angular velocity (world), J_om = R_wb J_mr(b, omega rows) and J_p = R_wb Gamma(x_bs) J_mr(b) the
// surface origin's point Jacobian (x_bs = E_bs's translation) [D Eq. 5.8-5.9]:
//   A_i   = dp_i/dq = R^T (J_xi - J_p + [x_i - p] J_om)                          (i = 1, 2)
//   J_ar  = R (Jw1 A_1 + Jw2 A_2 + w_b J_beta) - [R w] J_om + J_p   J_ori, J_ins, J_base [D Eq. 5.45-5.50]
//   Jdot_ar = [omega] R Jw' + R (Jwdot A + Jw Adot + w_bdot J_beta + w_b Jdot_beta) - [d(R w)/dt] J_om
//             - [R w] Jdot_om + Jdot_p,     Jw' = Jw A + w_b J_beta
//   Adot_i = R^T (-[omega] (J_xi - J_p + [r_i] J_om) + Jdot_xi - Jdot_p + [rdot_i] J_om + [r_i] Jdot_om)
// with r_i = x_i - p, d(R w)/dt = omega x R w + R (Jw (p1dot, p2dot) + w_b betadot), and Jwdot,
// w_bdot the time derivatives along (p1dot, p2dot, betadot) [D Eq. 5.51-5.57]. A world surface has
// J_om = J_p = 0. With two path points and one wrap (origin -> surface -> insertion) beta = alpha
// and J_beta = 0: the dissertation's case.
//
// Wrap models (Muscle::wrap):
//   Smooth (default)  core/muscles/wrap/smooth.hpp: exact wrapped path away from the contact
//                     change, C2 blend across it; J and Jdot exact (dual numbers). The mass matrix
//                     is continuous, so the energy is conserved to integrator error.
//   Exact             the exact library (core/geometry/wrap_surface.hpp). Origin -> one
//                     surface -> insertion: J by central differences on the end points and Jdot by
//                     central differences of that J along (p1dot, p2dot) (the dissertation's route,
//                     [D Eq. 5.58]). Any other shape: the whole path as OpenSim computes it
//                     (core/muscles/wrap/wrap_path.hpp: the segment each wrap lands on, several
//                     wraps on one segment, OpenSim's passes) with x_a at alpha of its geometric
//                     length, J by central differences in q and Jdot by mixed central differences
//                     along qdot. Positions are continuous at a contact change but J jumps there,
//                     so the kinetic energy jumps: the dissertation's motivation for a smooth model.
//   Neural            a trained network (core/muscles/wrap/network_model.hpp) on the segments the
//                     smooth model takes, scaled by the surface size: exact J and Jdot of the
//                     network; the smooth model wherever the network cannot answer (outside its
//                     training box, another surface type, a quadrant wrap, beyond the cylinder's
//                     length), counted in the muscle's workspace (MuscleKinematics::wrap_counts).
// Dispatch: calcWrapModelPoints() is the one place where a surface-frame wrap model is chosen
// (p1, p2, fractions -> w, Jw, Jwdot) among the three.
// Columns: a wrap surface on a body that moves no path point adds its body's coordinates to the
// muscle's compact columns (initWrapMuscleColumns; calcMuscleKinematics calls it).
#include <string>
#include <vector>

#include "core/muscles/muscle_workspace.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// "" when `muscle`'s path is a supported Type III shape for mass points (header) under
/// muscle.wrap.model, else a sentence saying why not.
std::string wrapMassPointsUnsupportedReason(const Muscle& muscle);

/// OpenSim's 1-based range of a PathWrap as 0-based first and last point indices (< 1: the ends)
/// of a path of np points.
void wrapRange(const PathWrap& w, int np, int& lo, int& hi);
/// The candidate segments [first, last) of wrap w over the active points (indices into the path's
/// np points; OpenSim's applyWrapObjects: from the first active point at/after the range's begin to
/// the last one at/before its end); false when there is none.
bool wrapSegments(const PathWrap& w, const std::vector<int>& active, int np, int& first, int& last);
/// True when the smooth (and network) wrap model refuses the segment p1 -> p2 (frame s): an end
/// inside the surface, or input it cannot take (OpenSim gives such a segment no wrap).
bool endInsideSurface(const WrapSurface& surface, const Vec3& p1, const Vec3& p2);

/// Stages of the segment construction shared by the one-surface route and the composition
/// (core/muscles/wrap_composite.cpp). From the segments' lengths L (model lengths of wrapped
/// segments), their rates and rows dL/dq, d/dt dL/dq: the active points' Eulerian coordinates
/// s_i = S_i / sum L with J_sr, sdot, Jdot_sr (mk.s, sdot, J_sr, Jdot_sr sized P = L.size() + 1
/// with their ends set); MuscleError naming the muscle for a zero-length segment.
void calcEulerianFromSegmentLengths(const VecX& L, const VecX& Ld, const MatX& J_L, const MatX& Jdot_L, bool vel,
                                    const std::string& muscle_name, MuscleKinematics& mk);
/// A straight segment i's entries of those: L[i] = l_i, dl_i/dq and (with vel) its rate.
void straightSegmentLengthRow(const MuscleKinematics& mk, int i, bool vel, VecX& L, VecX& Ld, MatX& J_L, MatX& Jdot_L);
/// Each mass point's segment and fraction beta in it from mk.s (and betadot with mk.velocity),
/// with mk's mass-point outputs sized.
void locateWrapMassPoints(const MassPoints& mp, MuscleKinematics& mk, std::vector<double>& betadot);
/// Type II's EOL construction for the mass points on straight segments (seg_wrap[i] < 0); J_zr,
/// Jdot_zr: scratch.
void calcStraightSegmentMassPoints(const std::vector<int>& seg_wrap, const std::vector<double>& betadot, MatX& J_zr,
                                   MatX& Jdot_zr, MuscleKinematics& mk);

/// Make mk's compact columns cover every coordinate that moves the path's points or its wrap
/// surfaces' bodies (re-initialising mk when they do not; no-op when they already do).
void initWrapMuscleColumns(const Model& model, const Muscle& muscle, MuscleKinematics& mk);

/// Mass points of a supported Type III muscle after calcPathPoints (mk.x_w, J_xr; with
/// mk.velocity also xdot_w, Jdot_xr) for the same state: x_a (world), J_ar and (with mk.velocity)
/// Jdot_ar in mk's compact columns; segment (between active points segment, segment + 1) and beta
/// (fraction of that segment's length), and the Eulerian coordinates s of the active points (arc
/// fractions; the segment construction also fills J_sr, sdot, Jdot_sr). Needs the columns of initWrapMuscleColumns and the
/// skeleton workspace of `state`. Throws MuscleError (naming the muscle) when an end point lies
/// inside the surface of origin -> surface -> insertion, ends coincide or a segment has zero
/// length, std::logic_error for an unsupported shape.
void calcWrapMassPoints(const Model& model, const State& state, const SkeletonWorkspace& sk, const Muscle& muscle,
                        MuscleKinematics& mk);
/// The same without the state: enough for the smooth model and for origin -> surface -> insertion;
/// the exact model on other shapes needs q (std::logic_error).
void calcWrapMassPoints(const Model& model, const SkeletonWorkspace& sk, const Muscle& muscle,
                        MuscleKinematics& mk);

/// WrapModelPoints and WrapSurfaceMotion: core/muscles/muscle_workspace.hpp (the stage's scratch holds them).

/// THE wrap-model dispatch point: mass points at fractions `alphas` of the wrapped segment p1 -> p2
/// (frame s) by options.model, moving with (p1dot, p2dot) and fraction rates `alphadots` (empty:
/// all zero). `with_alpha` also fills x_alpha and x_alphadot (the exact model cannot: it has no
/// alpha derivative; std::logic_error). Without `velocity` Jdot is zero. `network` holds the Neural
/// model's buffers; `wrap_name` (the WrapObject) picks its network (WrapMassOptions::networkFor);
/// returns its outcome (None for the other models). Throws
/// std::invalid_argument for an end point inside the surface or an unsupported surface.
NetworkWrapEval calcWrapModelPoints(const WrapMassOptions& options, const WrapSurface& surface, const Vec3& p1,
                                    const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot,
                                    const std::vector<double>& alphas, const std::vector<double>& alphadots,
                                    bool with_alpha, bool velocity, WrapModelPoints& out, NetworkWrapWorkspace& network,
                                    const std::string& wrap_name = {});

/// The wrap model's length of the wrapped segment p1 -> p2 (frame s) with dL/d(p1, p2) and its time
/// derivative (the smooth model's; every model that distributes points over several segments uses
/// it: the Exact model on such paths goes through the whole OpenSim path instead).
SmoothWrapLength calcWrapModelLength(const WrapMassOptions& options, const WrapSurface& surface, const Vec3& p1,
                                     const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot);

/// The segment construction's choice (header, "Segments"): for each segment between consecutive
/// active points (active: indices into muscle.path.points, x_w: their world positions, P >= 1),
/// the index into muscle.path.wraps of the wrap object acting on it, or -1 (straight). Each active
/// wrap takes the free candidate of its range penetrating most, skipping segments with an end
/// inside the surface (except origin -> surface -> insertion, which always takes its wrap).
/// Surface poses from the body poses E_wi (calcBodyPoses). Used by the mass points and by
/// `redmax lengths --wrap smooth|neural`.
std::vector<int> calcSegmentWraps(const Muscle& muscle, const std::vector<int>& active, const std::vector<Vec3>& x_w,
                                  const std::vector<Mat4>& E_wi);

/// The segment construction of the header on surfaces whose motion is given instead of taken from
/// the skeleton: seg_wrap from calcSegmentWraps (one entry per segment), surfaces[w] for each wrap
/// object w of muscle.path.wraps (only those named in seg_wrap are read), mk after the path stage
/// (x_w, J_xr, l, dxbar, active; with mk.velocity xdot_w, Jdot_xr) with its columns. Fills what
/// calcWrapMassPoints fills; it is that function's route for the smooth and neural models and for
/// origin -> surface -> insertion, open to an engine that moves the surfaces itself
/// (core/muscles/path_map.hpp's calcGeneralPathMap). Throws as calcWrapMassPoints,
/// std::invalid_argument for sizes that do not fit.
void calcWrapMassPointsOnSurfaces(const Muscle& muscle, const std::vector<int>& seg_wrap,
                                  const std::vector<WrapSurfaceMotion>& surfaces, MuscleKinematics& mk);

/// The exact library's points at fractions alphas over one surface (frame s), with J = dx/d(p1, p2)
/// by central differences of step h (m; <= 0: 1e-5 times the surface size) and, when
/// `with_jdot`, Jdot by central differences of J along (p1dot, p2dot) (else zero). calcWrap runs
/// once per stencil point for all alphas (1 + 12 + 24 calls with Jdot).
void calcExactWrapPointsFd(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                           const Vec3& p2dot, const std::vector<double>& alphas, WrapMassPoints& out,
                           double h = 0.0, bool with_jdot = true);

}  // namespace redmax
