#pragma once
// REDMAX dynamics of the bare skeleton [D Sec. 4.4, 4.6.1]:
//   M_r = J_mr^T M_m J_mr,   f_r = J_mr^T (f_m - M_m Jdot_mr qdot) + tau_K + tau_D     [D Eq. 4.18, 4.76]
// with f_m the Coriolis and gravity wrenches ad(phi)^T M phi + Gamma(c)^T R^T m g [D Eq. 3.21-3.22].
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// M_r (nr x nr) from the block-diagonal maximal inertia; needs Stage::Position.
void calcSkeletonMass(const Model& model, const SkeletonWorkspace& ws, MatX& M_r);

/// maximal forces f_m (nm): Coriolis + gravity for every body; needs Stage::Velocity.
void calcMaximalForce(const Model& model, const SkeletonWorkspace& ws, VecX& f_m);

/// f_r (nr) of the skeleton: gravity, quadratic velocity vector and joint springs/dampers.
void calcSkeletonForce(const Model& model, const State& state, const SkeletonWorkspace& ws, VecX& f_r);

/// K_r = -d tau/dq and D_r = -d tau/dqdot of the joint springs and dampers (diagonal) [D Eq. 4.81]
void addJointStiffnessDamping(const Model& model, MatX& K_r, MatX& D_r);

/// O(n) recursive Newton-Euler inverse dynamics over the same model: tau such that
/// M_r qddot - f_r = tau (joint springs and dampers included in f_r). Independent of J_mr.
VecX inverseDynamicsRecursive(const Model& model, const State& state, const VecX& qddot);

double skeletonKineticEnergy(const Model& model, const SkeletonWorkspace& ws);
/// gravity (relative to the world origin) plus joint springs
double skeletonPotentialEnergy(const Model& model, const State& state, const SkeletonWorkspace& ws);

}  // namespace redmax
