#pragma once
// Type I musculotendons: a straight line from origin to insertion [D Sec. 5.3.1]. A mass point at
// fraction alpha moves with the weighted average of the two ends,
//   x_a = (1 - alpha) x_ori + alpha x_ins,   J_ax = ((1 - alpha) I, alpha I)     [D Eq. 5.10]
// and alpha is constant, so J_ar = J_ax J_xm J_mr and Jdot_ar = J_ax Jdot_xr [D Eq. 5.11].
// A Type II path whose conditional points are all inactive (two active points) is handled here
// too: with no internal point the EOL construction reduces exactly to these formulas.
#include "core/muscles/muscle_workspace.hpp"

namespace redmax {

/// 3 x 6 J_ax of one mass point on (xdot_ori, xdot_ins) [D Eq. 5.10]
Eigen::Matrix<double, 3, 6> calcJ_ax(double alpha);

/// Mass points of a path with exactly two active points, after calcPathPoints: x_a, segment (0),
/// beta (= alpha), J_ar (and Jdot_ar with mk.velocity).
void calcStraightMassPoints(const MassPoints& mp, MuscleKinematics& mk);

}  // namespace redmax
