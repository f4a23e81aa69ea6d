#pragma once
// SE(3)/se(3) algebra of [D ch. 3]. Notation (core/spatial/notation.md):
//   E_ab   4x4 pose of frame b in frame a, x_a = E_ab * x_b          [D Eq. 3.1-3.2]
//   phi    twist (omega; nu) in body coordinates                       [D Eq. 3.5]
//   Ad(E)  6x6 adjoint, phi_a = Ad(E_ab) phi_b                         [D Eq. 3.15]
//   ad(phi) spatial cross-product matrix, Addot = Ad(E) ad(phi)        [D Eq. 3.20]
//   Gamma(x) = ([x]^T  I), point velocity in body coords = Gamma(x) phi [D Eq. 3.13]
#include "core/spatial/types.hpp"

namespace redmax {

/// cross-product matrix [a], [a] b = a x b  [D Eq. 3.7]
Mat3 skew(const Vec3& a);
/// inverse of skew: the vector of the skew-symmetric part of A (A need not be exactly skew)
Vec3 unskew(const Mat3& A);
/// 4x4 matrix [phi] of a twist [D Eq. 3.6]
Mat4 bracket6(const Vec6& phi);
/// inverse of bracket6
Vec6 unbracket6(const Mat4& B);

/// rigid transform from rotation and translation
Mat4 makeE(const Mat3& R, const Vec3& p);
/// translation-only transform
Mat4 makeTranslation(const Vec3& p);
/// inverse of a rigid transform [D Eq. 3.4]
Mat4 inverseE(const Mat4& E);
/// apply E to a point
inline Vec3 transformPoint(const Mat4& E, const Vec3& x) {
  return E.topLeftCorner<3, 3>() * x + E.topRightCorner<3, 1>();
}

/// adjoint of a rigid transform [D Eq. 3.15]
Mat6 Ad(const Mat4& E);
/// adjoint of the inverse transform, without forming the inverse
Mat6 AdInv(const Mat4& E);
/// time derivative of Ad(E) for a frame moving with body twist phi: Ad(E) ad(phi) [D Eq. 3.19-3.20]
Mat6 Addot(const Mat4& E, const Vec6& phi);
/// spatial cross-product matrix [D Eq. 3.20]
Mat6 ad(const Vec6& phi);
/// point Jacobian in body coordinates, Gamma(x) = ([x]^T  I) [D Eq. 3.13]
Mat3x6 Gamma(const Vec3& x);

/// The products above without forming 6 x 6 matrices (the recursions' inner loops; E = (R, p)):
/// Ad(E) phi = (R w; R v + p x R w)
inline Vec6 adjointTimes(const Mat3& R, const Vec3& p, const Vec6& phi) {
  Vec6 out;
  const Vec3 Rw = R * phi.head<3>();
  out.head<3>() = Rw;
  out.tail<3>() = R * phi.tail<3>() + p.cross(Rw);
  return out;
}
/// Ad(E^-1) phi = (R^T w; R^T (v + w x p))
inline Vec6 adjointInvTimes(const Mat3& R, const Vec3& p, const Vec6& phi) {
  Vec6 out;
  out.head<3>() = R.transpose() * phi.head<3>();
  out.tail<3>() = R.transpose() * (phi.tail<3>() + phi.head<3>().cross(p));
  return out;
}
/// Ad(E^-1)^T w for a wrench w = (tau; f): (R tau + p x R f; R f), a child's wrench in its parent
inline Vec6 adjointInvTransposeTimes(const Mat3& R, const Vec3& p, const Vec6& w) {
  Vec6 out;
  const Vec3 Rf = R * w.tail<3>();
  out.head<3>() = R * w.head<3>() + p.cross(Rf);
  out.tail<3>() = Rf;
  return out;
}
/// ad(a) b = (wa x wb; wa x vb + va x wb)
inline Vec6 adTimes(const Vec6& a, const Vec6& b) {
  Vec6 out;
  out.head<3>() = a.head<3>().cross(b.head<3>());
  out.tail<3>() = a.head<3>().cross(b.tail<3>()) + a.tail<3>().cross(b.head<3>());
  return out;
}
/// ad(a)^T w = -(wa x tau + va x f; wa x f) for a wrench w = (tau; f)
inline Vec6 adTransposeTimes(const Vec6& a, const Vec6& w) {
  Vec6 out;
  out.head<3>() = -(a.head<3>().cross(w.head<3>()) + a.tail<3>().cross(w.tail<3>()));
  out.tail<3>() = -a.head<3>().cross(w.tail<3>());
  return out;
}

/// SO(3) exponential (Rodrigues), accurate for small |w| (Taylor series below 1e-4)
Mat3 expSO3(const Vec3& w);
/// SO(3) logarithm, returns w with |w| in [0, pi]; accurate near 0 and near pi
Vec3 logSO3(const Mat3& R);
/// SE(3) exponential of a twist (omega; nu)
Mat4 expSE3(const Vec6& phi);
/// SE(3) logarithm, inverse of expSE3 for |omega| < pi
Vec6 logSE3(const Mat4& E);
/// left Jacobian of SO(3), V(w) such that expSE3((w; v)).p = V(w) v
Mat3 leftJacobianSO3(const Vec3& w);

/// rotation about a unit axis by angle
Mat3 rotationAxisAngle(const Vec3& unit_axis, double angle);
/// the same by Rodrigues' c I + s [a] + (1 - c) a a^T directly (no norm, no W^2 product): equal to
/// rotationAxisAngle to round-off, but not bit for bit, so only callers whose results may move at
/// round-off use it (CustomJoint rotations; revolute joints keep expSO3, docs/notes.md)
Mat3 rotationUnitAxis(const Vec3& unit_axis, double angle);

/// spatial inertia about the body origin from mass, centre of mass c (body frame) and the
/// 3x3 inertia tensor about the COM in body axes: [[I_c + m[c][c]^T, m[c]], [m[c]^T, m I]]
Mat6 spatialInertia(double mass, const Vec3& com, const Mat3& inertia_com);

/// relative comparison that also works against a zero reference (docs/design.md §8):
/// |a - b| <= tol * (1 + |b|)
template <class A, class B>
bool nearRel(const A& a, const B& b, double tol) {
  return (a - b).norm() <= tol * (1.0 + b.norm());
}

}  // namespace redmax
