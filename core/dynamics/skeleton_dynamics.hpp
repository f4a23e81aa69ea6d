#pragma once
// REDMAX dynamics of the bare skeleton [D Sec. 4.4, 4.6.1]:
//   M_r = J_mr^T M_m J_mr,   f_r = J_mr^T (f_m - M_m Jdot_mr qdot) + tau_K + tau_D     [D Eq. 4.18, 4.76]
// with f_m the Coriolis and gravity wrenches ad(phi)^T M phi + Gamma(c)^T R^T m g [D Eq. 3.21-3.22].
#include <vector>

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

/// What recursive Newton-Euler inverse dynamics writes (sized once; no allocation per call).
struct RecursiveIdWorkspace {
  explicit RecursiveIdWorkspace(const Model& model);
  std::vector<JointKinematics> jk;  // per joint Q, S, Sdot                         (nb)
  std::vector<Mat3> R_im;           // joint frame M in body i: rotation (constant) (nb)
  std::vector<Vec3> p_im;           //   and translation (constant)                 (nb)
  std::vector<Mat3> R_pi;           // body i in its parent body: rotation          (nb)
  std::vector<Vec3> p_pi;           //   and translation                            (nb)
  std::vector<Mat6X> S_i;           // Ad_ij S: joint twist map in body i           (nb, 6 x nq)
  std::vector<Mat4> E_wi;           // body poses in world                         (nb)
  std::vector<Vec6> phi, phidot;    // body twists and their rates, body coords    (nb)
  std::vector<Vec6> w;              // wrench each body must get from its joint     (nb)
  BodyMotion motion() const { return {E_wi, phi, phidot}; }
};

/// Forward pass of recursive inverse dynamics: joint kinematics, poses, twists, their rates
/// phidot = J_mr qddot + Jdot_mr qdot, and each body's net wrench w = M phidot - ad(phi)^T M phi
/// - gravity [D Eq. 3.21-3.22]. Loads added to ws.w before the backward pass (body coordinates)
/// are wrenches the bodies additionally need: subtract external loads, add extra inertia.
void recursiveIdForward(const Model& model, const State& state, const VecX& qddot, RecursiveIdWorkspace& ws);
/// Backward pass: tau = S_i^T w_i with every w_i passed on to the parent (Ad_ip^T w_i), minus the
/// joint springs and dampers; tau (nr) is overwritten.
void recursiveIdBackward(const Model& model, const State& state, RecursiveIdWorkspace& ws, VecX& tau);

/// O(n) recursive Newton-Euler inverse dynamics over the same model: tau such that
/// M_r qddot - f_r = tau (joint springs and dampers included in f_r). Independent of J_mr.
VecX inverseDynamicsRecursive(const Model& model, const State& state, const VecX& qddot);
/// the same in a caller-owned workspace (no allocation)
void inverseDynamicsRecursive(const Model& model, const State& state, const VecX& qddot,
                              RecursiveIdWorkspace& ws, VecX& tau);

double skeletonKineticEnergy(const Model& model, const SkeletonWorkspace& ws);
/// gravity (relative to the world origin) plus joint springs
double skeletonPotentialEnergy(const Model& model, const State& state, const SkeletonWorkspace& ws);

}  // namespace redmax
