#pragma once
// Joints whose transform is a product of one-parameter exponentials,
//   Q(q) = exp([xi_1] theta_1(q)) exp([xi_2] theta_2(q)) ... exp([xi_n] theta_n(q)),
// with constant twists xi_k and scalar functions theta_k of the joint coordinates. Euler-angle
// joints, the spline joints [D Alg. 3-4] and OpenSim's function-based joint are all of this form.
// Appending the factors left to right gives Q, S and Sdot by the recursion of [D Alg. 3, 4]:
//   S    <- xi_k grad_k^T + Ad(E_k^-1) S
//   Sdot <- xi_k graddot_k^T + Ad(E_k^-1) Sdot - ad(xi_k thetadot_k) Ad(E_k^-1) S
// where E_k = exp([xi_k] theta_k), thetadot_k = grad_k . qdot and graddot_k = d(grad_k)/dt
// (the Hessian of theta_k times qdot). The Sdot line uses d/dt Ad(E^-1) = -ad(E^-1 Edot) Ad(E^-1).
#include "core/joints/joint_kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::detail {

/// exp([xi] theta) for a constant twist xi (pure rotations and translations take a cheap path)
Mat4 expTwist(const Vec6& xi, double theta);

/// Start a product: out.Q = I, S and Sdot zero with nq columns.
inline void beginProduct(int nq, JointKinematics& out) {
  out.resize(nq);
  out.Q.setIdentity();
}

/// Right-multiply out.Q by exp([xi] theta) and update S and Sdot (see the file comment).
/// grad and graddot have nq entries (the joint's coordinate count); qdot is the joint velocity.
void appendFactor(const Vec6& xi, double theta, const VecJ& grad, const VecJ& graddot,
                  const VecJ& qdot, JointKinematics& out);

}  // namespace redmax::detail
