#pragma once
// Everything derived from (Model, State, Muscle) for one musculotendon, grouped by stage
// (STYLE.md Model/State/Workspace). Written by the algorithms in path_kinematics.hpp,
// via_point.hpp, straight.hpp and muscle_kinematics.hpp, in that order.
//
// Sizes: P active path points (changes only when a conditional point switches), n = P - 2 internal
// points, N mass points, nr reduced coordinates. Rows of stacked point quantities are 3 per point.
// Jacobians are kept in reduced coordinates: the dissertation's J_xm (maps body twists q_m to path
// point velocities [D Eq. 5.9, 5.37]) is stored as one 3 x 6 block per point (the only nonzero
// block of its row) and is chained with the matching rows of J_mr at once, J_xr = J_xm J_mr
// [D Eq. 5.4]; moving points add a column through their coordinate that has no J_xm counterpart.
// Buffers are resized only when P changes, so steady-state evaluation does not allocate.
#include <stdexcept>
#include <vector>

#include "core/muscles/mass_points.hpp"

namespace redmax {

struct MuscleKinematics {
  // path stage, position: calcPathPoints
  std::vector<int> active;          // indices into path.points of the active points, in order (P)
  std::vector<Vec3> x_b;            // point locations in their body frames (moving ones evaluated) (P)
  std::vector<Vec3> x_w;            // point positions, world                                  (P)
  std::vector<Mat3x6> J_xm;         // R_b Gamma(x_b): the point's block of J_xm [D Eq. 5.8-5.9] (P)
  MatX J_xr;                        // J_xm J_mr (+ moving-point column)                   (3P x nr)
  VecX l;                           // segment lengths l_i = |x_{i+1} - x_i| [D Eq. 5.18]      (P-1)
  std::vector<Vec3> dxbar;          // unit segment directions [D Eq. 5.19] (0 if l_i = 0)    (P-1)
  double length = 0.0;              // path length, sum of l_i (m)

  // path stage, velocity
  std::vector<Vec3> xdot_w;         // point velocities, world                                 (P)
  std::vector<Mat3x6> Jdot_xm;      // R_b ([omega_b] Gamma(x_b) + Gamma(xdot_b)) [D Eq. 5.11]  (P)
  MatX Jdot_xr;                     // d/dt J_xr                                           (3P x nr)
  VecX ldot;                        // segment lengthening speeds [D Eq. 5.27]                (P-1)
  double lengthening_speed = 0.0;   // d length / dt (m/s)

  // Eulerian stage (P >= 3): calcEulerianCoordinates [D Sec. 5.3.2.1]
  VecX s;                           // Eulerian coordinates, equal strain: s_i = (arc length to i) / length,
                                    // so s_0 = 0, s_{P-1} = 1 and s is the arc fraction alpha (P)
  MatX J_sx;                        // internal s rate per stacked point velocity [D Eq. 5.23] (n x 3P)
  MatX J_sr;                        // J_sx J_xr placed in rows 1..P-2, rows 0 and P-1 zero   (P x nr)
  VecX sdot;                        // (P), ends zero
  MatX Jdot_sx;                     // [D Eq. 5.24]                                          (n x 3P)
  MatX Jdot_sr;                     // Jdot_sx J_xr + J_sx Jdot_xr in rows 1..P-2             (P x nr)

  // mass-point stage: calcMassPointKinematics
  std::vector<Vec3> x_a;            // mass point positions, world                            (N)
  std::vector<int> segment;         // segment i (between active points i, i+1) of each point (N)
  std::vector<double> beta;         // fraction within that segment [D Eq. 5.29]             (N)
  MatX J_ar;                        // J_am J_mr = J_az J_zm J_mr [D Eq. 5.4, 5.15]        (3N x nr)
  MatX Jdot_ar;                     // Jdot_am J_mr + J_am Jdot_mr [D Eq. 5.5]             (3N x nr)

  bool velocity = false;            // true when the velocity-stage fields are valid
};

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
