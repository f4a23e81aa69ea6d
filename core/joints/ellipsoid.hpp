#pragma once
// Ellipsoid joint: Simbody's MobilizedBody::Ellipsoid as OpenSim uses it (EllipsoidJoint, and the
// first stage of ScapulothoracicJoint; docs/opensim_compatibility.md §3.2). The child frame M
// slides on an ellipsoid fixed in F while it turns, its z axis kept along the ellipsoid's
// position-dependent "normal" n:
//   R = Rx(q1) Ry(q2) Rz(q3)  (body-fixed XYZ, as SphericalEuler XYZ),   n = R e_z,
//   p = D n,  D = diag(a, b, c) (the semi-axes along F's x, y, z)
// so Q = (R, p). With w = S_r qdot the body angular velocity (S_r: the XYZ Euler block),
//   pdot = D R [w] e_z = -D R [e_z] w,   v_M = R^T pdot:
//   S    = [ S_r ; -A [e_z] S_r ],                 A = R^T D R
//   Sdot = [ Sdot_r ; -(Adot [e_z] S_r + A [e_z] Sdot_r) ],   Adot = A [w] - [w] A.
// qdot = dq/dt (Euler rates). Simbody's Ellipsoid uses u = angular velocity in F instead; that
// is a velocity map, not a different motion, and belongs to the OpenSim-compatibility switch.
// Note that p = D n is not a point of the ellipsoid surface unless the radii are equal (it is
// Simbody's definition, kept so poses match OpenSim).
#include <cmath>

#include "core/joints/joint_kinematics.hpp"

namespace redmax {

struct Ellipsoid {
  static constexpr int kNq = 3;
  Vec3 radii = Vec3::Ones();  // semi-axes a, b, c along F's x, y, z (m), any sign accepted

  int nq() const { return 3; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
  /// gimbal-lock measure of the XYZ Euler angles, |cos q2|
  double singularityDistance(const VecJ& q) const { return std::abs(std::cos(q[1])); }
};

}  // namespace redmax
