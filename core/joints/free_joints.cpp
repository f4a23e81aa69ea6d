#include "core/joints/free_joints.hpp"

#include <cmath>

#include "core/spatial/se3.hpp"

namespace redmax {

void Free2D::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  const double c = std::cos(q[2]), s = std::sin(q[2]);
  out.resize(3);
  Mat3 R = Mat3::Identity();
  R(0, 0) = c;
  R(0, 1) = -s;
  R(1, 0) = s;
  R(1, 1) = c;
  out.Q = makeE(R, Vec3(q[0], q[1], 0.0));
  // [D Eq. 4.55]: the translational rows hold the rows of R_z (columns of R^T)
  out.S.block<3, 1>(3, 0) = Vec3(c, -s, 0.0);
  out.S.block<3, 1>(3, 1) = Vec3(s, c, 0.0);
  out.S(2, 2) = 1.0;
  // d/dt R^T e_x = -thetadot e_z x R^T e_x
  out.Sdot.block<3, 1>(3, 0) = Vec3(-s, -c, 0.0) * qdot[2];
  out.Sdot.block<3, 1>(3, 1) = Vec3(c, -s, 0.0) * qdot[2];
}

void Free3D::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  const int ir = rotationOffset(), it = translationOffset();
  const Vec3 r = q.segment<3>(ir), rd = qdot.segment<3>(ir);
  const Vec3 p = q.segment<3>(it), pd = qdot.segment<3>(it);
  Mat3 R, Sh, Shd;
  if (rotation == FreeRotation::Exponential) {
    SphericalExp::calcRotation(r, rd, R, Sh, Shd);
  } else {
    SphericalEuler{sequence}.calcRotation(r, rd, R, Sh, Shd);
  }
  out.resize(6);
  // the column blocks: rows 0-2 angular, rows 3-5 linear
  auto Sr = out.S.middleCols<3>(ir);
  auto St = out.S.middleCols<3>(it);
  auto Sdr = out.Sdot.middleCols<3>(ir);
  auto Sdt = out.Sdot.middleCols<3>(it);
  if (order == FreeOrder::TranslationThenRotation) {
    // [D Eq. 4.58-4.59]
    out.Q = makeE(R, p);
    Sr.topRows<3>() = Sh;
    St.bottomRows<3>() = R.transpose();
    Sdr.topRows<3>() = Shd;
    Sdt.bottomRows<3>() = -skew(Sh * rd) * R.transpose();
  } else {
    // [D Eq. 4.61-4.62]
    out.Q = makeE(R, R * p);
    Sr.topRows<3>() = Sh;
    Sr.bottomRows<3>() = -skew(p) * Sh;
    St.bottomRows<3>().setIdentity();
    Sdr.topRows<3>() = Shd;
    Sdr.bottomRows<3>() = -skew(pd) * Sh - skew(p) * Shd;
  }
}

double Free3D::singularityDistance(const VecJ& q) const {
  const Vec3 r = q.segment<3>(rotationOffset());
  if (rotation == FreeRotation::Exponential) return SphericalExp::rotationSingularityDistance(r);
  return SphericalEuler{sequence}.gimbalDistance(VecJ(r));
}

bool Free3D::reparameterize(VecJ& q, VecJ& qdot) const {
  if (rotation != FreeRotation::Exponential) return false;
  const int ir = rotationOffset();
  Vec3 r = q.segment<3>(ir), rd = qdot.segment<3>(ir);
  if (!SphericalExp::reparameterizeRotation(r, rd)) return false;
  q.segment<3>(ir) = r;
  qdot.segment<3>(ir) = rd;
  return true;
}

}  // namespace redmax
