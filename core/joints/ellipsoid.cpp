#include "core/joints/ellipsoid.hpp"

#include "core/joints/euler_joints.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

void Ellipsoid::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  // rotation part: the XYZ Euler block [D Eq. 4.30]
  static const SphericalEuler kXYZ{EulerSequence::XYZ};
  Mat3 R, Sr, Sr_dot;
  const Vec3 qd(qdot[0], qdot[1], qdot[2]);
  kXYZ.calcRotation(Vec3(q[0], q[1], q[2]), qd, R, Sr, Sr_dot);

  // translation along the ellipsoid "normal" n = R e_z, scaled by the radii (see header)
  const Mat3 D = radii.asDiagonal();
  const Vec3 ez = Vec3::UnitZ();
  const Mat3 A = R.transpose() * D * R;
  const Mat3 Ez = skew(ez);
  const Vec3 w = Sr * qd;
  const Mat3 Adot = A * skew(w) - skew(w) * A;

  out.resize(3);
  out.Q = makeE(R, D * (R * ez));
  out.S.topRows<3>() = Sr;
  out.S.bottomRows<3>() = -A * Ez * Sr;
  out.Sdot.topRows<3>() = Sr_dot;
  out.Sdot.bottomRows<3>() = -(Adot * Ez * Sr + A * Ez * Sr_dot);
}

}  // namespace redmax
