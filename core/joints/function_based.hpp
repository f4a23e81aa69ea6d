#pragma once
// OpenSim CustomJoint / Simbody FunctionBased mobilizer (docs/opensim_compatibility.md §3.3).
//
// Six transform axes: rotation1..3 then translation1..3. Axis k has a unit direction, a list of
// coordinate indices into this joint's q (the function's arguments, in order) and a function:
//   theta_k = f_k(q[idx_k]) (k = 1..3),   d_k = f_{k+3}(q[idx_{k+3}])
//   X_FM = (R, p),  R = R(theta_1, a_1) R(theta_2, a_2) R(theta_3, a_3)   (body-fixed)
//                    p = d_1 t_1 + d_2 t_2 + d_3 t_3                      (in F, not rotated)
// As a product of exponentials Q = T(t_1 d_1) T(t_2 d_2) T(t_3 d_3) R(a_1 th_1) R(a_2 th_2)
// R(a_3 th_3) (translations commute), so the exact S and Sdot, second derivatives of the functions
// included, come from the recursion in core/joints/product_of_exponentials.hpp.
//
// simbody_compat = true reproduces Simbody's FunctionBased mobilizer instead of exact kinematics:
//   H (in F): angular W dtheta/dq with W = [a_1, R_1 a_2, R_1 R_2 a_3], where theta of an axis
//     whose function takes no coordinates (a Constant) is taken as 0 (Q keeps the true value);
//     linear [t_1 t_2 t_3] dd/dq.
//   Hdot: angular Wdot dtheta/dq + W d(dtheta/dq)/dt with Simbody's approximate
//     Wdot = [0, w_a x W_2, w_b x W_3], w_a = angular part of H (u_0, 0, ...), w_b = angular part
//     of H u with u_2 zeroed (when nq > 2); W here uses the true constants.
//   S = blockdiag(R^T, R^T) H,  Sdot = -blockdiag([w], [w]) S + blockdiag(R^T, R^T) Hdot,
//   where w = R^T H_ang qdot is the angular velocity Simbody gives M (V_FM = H u; the true one
//   except for nonzero Constant rotations).
// It equals exact kinematics when rotation k depends only on mobility k-1 (pelvis/hip-like
// joints) and no Constant rotation is nonzero; it differs, in Sdot, when one coordinate drives
// several rotations (coupled knees), and in S when a nonzero Constant rotation precedes others.
#include <array>
#include <vector>

#include "core/joints/functions.hpp"
#include "core/joints/joint_kinematics.hpp"

namespace redmax {

/// One of the six transform axes.
struct TransformAxis {
  Vec3 axis = Vec3::UnitX();      // direction (normalized by FunctionBased)
  std::vector<int> coordinates;   // indices into the joint's q, in argument order
  AxisFunctionPtr function;       // null: LinearFunction(1, 0) with one coordinate,
                                  //       Constant(0) with none (as OpenSim)
};

class FunctionBased {
 public:
  /// nq: number of independent coordinates (0..6). axes: rotation1..3, translation1..3.
  /// Throws JointError when: nq is out of range; an axis is zero or not finite; a coordinate
  /// index is outside [0, nq); a function's argument count differs from its coordinate list;
  /// two coordinates are listed without a function; two rotation axes, or two translation axes,
  /// are parallel (|a_i x a_j| < 1e-5 on the raw axes, OpenSim's test).
  FunctionBased(int nq, std::array<TransformAxis, 6> axes, bool simbody_compat = false);

  int nq() const { return nq_; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;

  /// the axes as used: unit directions, null functions replaced
  const std::array<TransformAxis, 6>& axes() const { return axes_; }
  /// value of spatial coordinate k (theta_1..3, d_1..3) at q
  double spatialCoordinate(int k, const VecJ& q) const;
  /// Gimbal-lock measure of the rotation sequence when all three rotations are driven by
  /// coordinates: |det [a_1, R_1 a_2, R_1 R_2 a_3]| (1 for orthonormal axes away from lock);
  /// otherwise 1. (S can also lose rank where function gradients vanish; that is not reported.)
  double singularityDistance(const VecJ& q) const;

  /// Reproduce Simbody's approximate velocity terms (see the file comment). Default: exact.
  bool simbody_compat = false;

 private:
  // spatial coordinate k: value, gradient in q (nq) and its time derivative (Hessian qdot)
  void evalAxis(int k, const VecJ& q, const VecJ& qdot, int order, double& v, VecJ& grad,
                VecJ& graddot) const;
  void calcSimbody(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;

  int nq_ = 0;
  std::array<TransformAxis, 6> axes_;
  // the functions most axes carry, evaluated without the virtual call and Hessian (per frame, per
  // axis): a Constant, or a LinearFunction of one coordinate (slope, intercept)
  enum class AxisKind { General, Constant, Linear1 };
  std::array<AxisKind, 6> kind_{};
  std::array<double, 6> slope_{}, intercept_{};
};

}  // namespace redmax
