#pragma once
// Forward kinematics and the reduced-to-maximal Jacobian J_mr with its time derivative
// [D Alg. 1-2, Eq. 4.12-4.17].
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// Fills every stage of the workspace: joint Q/S/Sdot, body poses E_wi, J_mr, twists phi_i and
/// Jdot_mr. Only the entries whose column joint is an ancestor of the row body are written; the
/// rest stay zero from construction.
void calcKinematics(const Model& model, const State& state, SkeletonWorkspace& ws);

/// Poses only (no Jacobians), for drawing, markers and path points.
void calcBodyPoses(const Model& model, const VecX& q, std::vector<Mat4>& E_wi);

/// World position and velocity of a point fixed in body i (body coordinates x_i); needs Stage::Velocity.
Vec3 pointPosition(const SkeletonWorkspace& ws, int body, const Vec3& x_i);
Vec3 pointVelocity(const SkeletonWorkspace& ws, int body, const Vec3& x_i);

/// Jacobian of a body-fixed point's world velocity with respect to qdot (3 x nr):
/// J = R_i Gamma(x_i) J_mr(i,:)  [D Eq. 3.13, 4.1]; needs Stage::Position.
void pointJacobian(const Model& model, const SkeletonWorkspace& ws, int body, const Vec3& x_i,
                   Eigen::Ref<MatX> J);

/// Apply every joint's chart switch (exponential coordinates near |q| = 2 pi [D Sec. 4.5.8]).
/// Returns the number of joints reparameterized.
int reparameterizeJoints(const Model& model, State& state);

}  // namespace redmax
