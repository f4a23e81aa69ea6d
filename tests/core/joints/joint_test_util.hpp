#pragma once
// Finite-difference helpers shared by the joint tests (docs/design.md §8: central differences, h ~ 1e-6,
// compared with nearRel).
#include <random>

#include "core/joints/joint.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::test {

constexpr double kH = 1e-6;     // central-difference step
constexpr double kFdTol = 1e-6;  // relative tolerance of FD comparisons

inline JointKinematics calcJoint(const Joint& j, const VecJ& q, const VecJ& qdot) {
  JointKinematics k;
  j.calc(q, qdot, k);
  return k;
}
inline JointKinematics calcJoint(const Joint& j, const VecJ& q) {
  return calcJoint(j, q, VecJ::Zero(q.size()));
}

/// [S_k] = Q^-1 (Q(q + h e_k) - Q(q - h e_k)) / 2h as 4 x 4 matrices (the full bracket, so the
/// bottom row and the skew symmetry are checked too)
inline Mat4 fdBracketColumn(const Joint& j, const VecJ& q, int k, double h = kH) {
  VecJ qp = q, qm = q;
  qp[k] += h;
  qm[k] -= h;
  const Mat4 Q = calcJoint(j, q).Q;
  return inverseE(Q) * (calcJoint(j, qp).Q - calcJoint(j, qm).Q) / (2 * h);
}

/// (S(q + h qdot) - S(q - h qdot)) / 2h
inline Mat6X fdSdot(const Joint& j, const VecJ& q, const VecJ& qdot, double h = kH) {
  const VecJ qp = q + h * qdot, qm = q - h * qdot;
  return (calcJoint(j, qp).S - calcJoint(j, qm).S) / (2 * h);
}

/// Q is a proper rigid transform: orthonormal rotation with det 1, bottom row (0 0 0 1)
inline bool isRigid(const Mat4& Q, double tol = 1e-12) {
  const Mat3 R = Q.topLeftCorner<3, 3>();
  return (R.transpose() * R - Mat3::Identity()).norm() < tol && std::abs(R.determinant() - 1) < tol &&
         Q.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 0.0) && Q.allFinite();
}

inline VecJ randomVecJ(int n, std::mt19937& rng, double lo = -1.0, double hi = 1.0) {
  std::uniform_real_distribution<double> u(lo, hi);
  VecJ v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

}  // namespace redmax::test
