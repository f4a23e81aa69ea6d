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

}  // namespace redmax
