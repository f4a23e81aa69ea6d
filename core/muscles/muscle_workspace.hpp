#pragma once
// Everything derived from (Model, State, Muscle) for one musculotendon, grouped by stage
// (docs/design.md §4). Written by the algorithms in path_kinematics.hpp,
// via_point.hpp, straight.hpp and muscle_kinematics.hpp, in that order.
//
// Sizes: P active path points (changes only when a conditional point switches), n = P - 2 internal
// points, N mass points, nr reduced coordinates. Rows of stacked point quantities are 3 per point.
// Jacobians are kept in reduced coordinates: the dissertation's J_xm (maps body twists q_m to path
// point velocities [D Eq. 5.9, 5.37]) is stored as one 3 x 6 block per point (the only nonzero
// block of its row) and is chained with the matching rows of J_mr at once, J_xr = J_xm J_mr
// [D Eq. 5.4]; moving points add a column through their coordinate that has no J_xm counterpart.
// Column compaction: a path can only be moved by the coordinates of the joints above its bodies
// (and the coordinates driving its moving points). Those k coordinates, `cols`, are fixed by the
// model and the path, so every Jacobian below has k columns, column j standing for coordinate
// cols[j]; expandColumns() gives the nr-column matrix. (With a 6-dof root every path still skips
// most limb coordinates, so this saves most of the work on full-body models.)
// Buffers are resized only when P changes, so steady-state evaluation does not allocate.
#include <stdexcept>
#include <vector>

#include "core/muscles/mass_points.hpp"
#include "core/muscles/wrap/network_model.hpp"

namespace redmax {

/// A wrap model's points over one surface (frame s): WrapMassPoints (x, J = dx/d(p1, p2) 3x6, Jdot
/// = dJ/dt along (p1dot, p2dot, alphadot)) plus, when asked for, the derivative along the fraction.
struct WrapModelPoints : WrapMassPoints {
  std::vector<Vec3> x_alpha;     ///< dx/dalpha (m)
  std::vector<Vec3> x_alphadot;  ///< d/dt dx/dalpha along (p1dot, p2dot, alphadot)
};

/// Pose and motion of one wrap surface frame s (world): R = R_ws, p = p_ws (m), its angular
/// velocity omega (rad/s) and origin velocity pdot (m/s), with J_om = d omega / d qdot and J_p =
/// d pdot / d qdot in mk's compact columns (3 x k each) and their time derivatives [D Eq. 5.39-5.41].
struct WrapSurfaceMotion {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();
  MatX J_om, J_p, Jdot_om, Jdot_p;
  Vec3 omega = Vec3::Zero(), pdot = Vec3::Zero();
};

/// Buffers of the Type III segment construction (core/muscles/wrap_muscle.cpp), kept between calls
/// so that an evaluation at the sizes of the last one does not allocate (the allocations were a
/// seventh of a 20-point muscle's cost, docs/performance.md §7)
struct WrapStageScratch {
  std::vector<int> seg_wrap, idx;
  std::vector<double> betas, betadots, betadot;
  std::vector<WrapSurfaceMotion> surfaces;
  MatX J_mb, Jdot_mb;  // a surface body's rows of J_mr, Jdot_mr
  struct Ends {        // a wrapped segment's ends in its surface frame, A_j = dp_j/dq and d/dt
    Vec3 p1 = Vec3::Zero(), p2 = Vec3::Zero(), p1dot = Vec3::Zero(), p2dot = Vec3::Zero();
    MatX A1, A2, A1dot, A2dot;
  };
  std::vector<Ends> ends;
  MatX B, T;  // R A_j and the bracket of its rate
  VecX L, Ld;
  MatX J_L, Jdot_L;
  WrapModelPoints points;
  MatX stackJ, stackD, coefJ, coefD, outJ, outD;  // a segment's stacked rows, its points' coefficients, products
};

struct MuscleKinematics {
  // columns (model- and path-dependent only): initMuscleKinematics
  std::vector<int> cols;            // reduced coordinates that can move the path, ascending  (k)
  std::vector<int> col_of;          // compact column of each coordinate, -1 if not in cols  (nr, or up
                                    // to the last node coordinate with Node points, path.hpp)

  // path stage, position: calcPathPoints
  std::vector<int> active;          // indices into path.points of the active points, in order (P)
  std::vector<Vec3> x_b;            // point locations in their body frames (moving ones evaluated) (P)
  std::vector<Vec3> x_w;            // point positions, world                                  (P)
  std::vector<Mat3x6> J_xm;         // R_b Gamma(x_b): the point's block of J_xm [D Eq. 5.8-5.9] (P)
  MatX J_xr;                        // J_xm J_mr (+ moving-point column)                    (3P x k)
  VecX l;                           // segment lengths l_i = |x_{i+1} - x_i| [D Eq. 5.18]      (P-1)
  std::vector<Vec3> dxbar;          // unit segment directions [D Eq. 5.19] (0 if l_i = 0)    (P-1)
  double length = 0.0;              // path length, sum of l_i (m)

  // path stage, velocity
  std::vector<Vec3> xdot_w;         // point velocities, world                                 (P)
  std::vector<Mat3x6> Jdot_xm;      // R_b ([omega_b] Gamma(x_b) + Gamma(xdot_b)) [D Eq. 5.11]  (P)
  MatX Jdot_xr;                     // d/dt J_xr                                            (3P x k)
  VecX ldot;                        // segment lengthening speeds [D Eq. 5.27]                (P-1)
  double lengthening_speed = 0.0;   // d length / dt (m/s)

  // Eulerian stage (P >= 3): calcEulerianCoordinates [D Sec. 5.3.2.1]
  VecX s;                           // Eulerian coordinates, equal strain: s_i = (arc length to i) / length,
                                    // so s_0 = 0, s_{P-1} = 1 and s is the arc fraction alpha (P)
  MatX J_sx;                        // internal s rate per stacked point velocity [D Eq. 5.23] (n x 3P)
  MatX J_sr;                        // J_sx J_xr placed in rows 1..P-2, rows 0 and P-1 zero    (P x k)
  VecX sdot;                        // (P), ends zero
  MatX Jdot_sx;                     // [D Eq. 5.24]                                          (n x 3P)
  MatX Jdot_sr;                     // Jdot_sx J_xr + J_sx Jdot_xr in rows 1..P-2              (P x k)

  // mass-point stage: calcMassPointKinematics
  std::vector<Vec3> x_a;            // mass point positions, world                            (N)
  std::vector<int> segment;         // segment i (between active points i, i+1) of each point (N)
  std::vector<double> beta;         // fraction within that segment [D Eq. 5.29]             (N)
  MatX J_ar;                        // J_am J_mr = J_az J_zm J_mr [D Eq. 5.4, 5.15]         (3N x k)
  MatX Jdot_ar;                     // Jdot_am J_mr + J_am Jdot_mr [D Eq. 5.5]              (3N x k)
  // fibre-following placement only (core/muscles/fibre_placement.hpp); empty otherwise. Then
  // J_ar is dx_a/dq at fixed muscle states, Jdot_ar its total time derivative, and
  // xdot_a = J_ar qdot + v_z, xddot_a = J_ar qddot + Jdot_ar qdot + a_z
  VecX J_aT;                        // dx_a / d(tendon length) at fixed q                     (3N)
  VecX v_z;                         // point velocities from the muscle states' rates          (3N)
  VecX a_z;                         // their time derivative                                   (3N)
  MatX seg_lq, seg_lqdot;           // scratch: dl_i/dq and its time derivative, per segment (P-1 x k)

  bool velocity = false;            // true when the velocity-stage fields are valid

  // wrap-model scratch (Type III, Neural): network buffers, and outcomes counted since this
  // workspace was made (callers sum them: WrapFallbackMonitor::add)
  NetworkWrapWorkspace network;
  WrapFallbackCounts wrap_counts;
  WrapStageScratch wrap_scratch;
};

/// Columns of a path on `model` (cols, col_of) and buffers sized for all its points; the
/// algorithms call it themselves when mk was not set up for this path.
void initMuscleKinematics(const Model& model, const Muscle& muscle, MuscleKinematics& mk);
void initMuscleKinematics(const Model& model, const MusclePath& path, MuscleKinematics& mk);

/// The nr-column form of a compact Jacobian J (rows x k) of mk: column cols[j] = J.col(j).
MatX expandColumns(const MatX& J, const MuscleKinematics& mk, int nr);
/// v restricted to mk.cols (k), e.g. qdot for J_ar * qdot
VecX gatherColumns(const VecX& v, const MuscleKinematics& mk);
/// the same into a caller-owned buffer (no allocation once it has the size)
void gatherColumns(const VecX& v, const MuscleKinematics& mk, VecX& out);
/// full[cols[j]] += compact[j]: a compact generalized force back into all coordinates
void scatterAddColumns(const VecX& compact, const MuscleKinematics& mk, VecX& full);

/// One MuscleKinematics per muscle, in the order of the muscle list it was built for.
struct MuscleWorkspace {
  MuscleWorkspace() = default;
  MuscleWorkspace(const Model& model, const std::vector<Muscle>& muscles);
  std::vector<MuscleKinematics> muscles;
};

/// A muscle path cannot be evaluated at this configuration (e.g. a zero-length segment under mass
/// points); the message names the muscle and the segment.
class MuscleError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace redmax
