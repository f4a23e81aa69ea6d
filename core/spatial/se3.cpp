#include "core/spatial/se3.hpp"

#include <algorithm>
#include <cmath>

namespace redmax {

Mat3 skew(const Vec3& a) {
  Mat3 S;
  S << 0, -a.z(), a.y(),
       a.z(), 0, -a.x(),
       -a.y(), a.x(), 0;
  return S;
}

Vec3 unskew(const Mat3& A) {
  // average the two copies of each entry so a slightly non-skew matrix (e.g. from FD) is handled
  return 0.5 * Vec3(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1));
}

Mat4 bracket6(const Vec6& phi) {
  Mat4 B = Mat4::Zero();
  B.topLeftCorner<3, 3>() = skew(phi.head<3>());
  B.topRightCorner<3, 1>() = phi.tail<3>();
  return B;
}

Vec6 unbracket6(const Mat4& B) {
  Vec6 phi;
  phi << unskew(B.topLeftCorner<3, 3>()), B.topRightCorner<3, 1>();
  return phi;
}

Mat4 makeE(const Mat3& R, const Vec3& p) {
  Mat4 E = Mat4::Identity();
  E.topLeftCorner<3, 3>() = R;
  E.topRightCorner<3, 1>() = p;
  return E;
}

Mat4 makeTranslation(const Vec3& p) { return makeE(Mat3::Identity(), p); }

Mat4 inverseE(const Mat4& E) {
  const Mat3 Rt = E.topLeftCorner<3, 3>().transpose();
  return makeE(Rt, -Rt * E.topRightCorner<3, 1>());
}

Mat6 Ad(const Mat4& E) {
  const Mat3 R = E.topLeftCorner<3, 3>();
  const Vec3 p = E.topRightCorner<3, 1>();
  Mat6 A;
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>().setZero();
  A.bottomLeftCorner<3, 3>() = skew(p) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

Mat6 AdInv(const Mat4& E) {
  // Ad(E^-1) = [[R^T, 0], [-R^T [p], R^T]]
  const Mat3 Rt = E.topLeftCorner<3, 3>().transpose();
  const Vec3 p = E.topRightCorner<3, 1>();
  Mat6 A;
  A.topLeftCorner<3, 3>() = Rt;
  A.topRightCorner<3, 3>().setZero();
  A.bottomLeftCorner<3, 3>() = -Rt * skew(p);
  A.bottomRightCorner<3, 3>() = Rt;
  return A;
}

Mat6 ad(const Vec6& phi) {
  const Mat3 w = skew(phi.head<3>());
  Mat6 A;
  A.topLeftCorner<3, 3>() = w;
  A.topRightCorner<3, 3>().setZero();
  A.bottomLeftCorner<3, 3>() = skew(phi.tail<3>());
  A.bottomRightCorner<3, 3>() = w;
  return A;
}

Mat6 Addot(const Mat4& E, const Vec6& phi) { return Ad(E) * ad(phi); }

Mat3x6 Gamma(const Vec3& x) {
  Mat3x6 G;
  G.leftCols<3>() = skew(x).transpose();
  G.rightCols<3>().setIdentity();
  return G;
}

Mat3 expSO3(const Vec3& w) {
  const double th2 = w.squaredNorm();
  const double th = std::sqrt(th2);
  const Mat3 W = skew(w);
  double a, b;  // R = I + a W + b W^2
  if (th < 1e-4) {
    // Taylor series: sin(t)/t and (1-cos t)/t^2 to O(t^4), below round-off for t < 1e-4
    a = 1.0 - th2 / 6.0 + th2 * th2 / 120.0;
    b = 0.5 - th2 / 24.0 + th2 * th2 / 720.0;
  } else {
    a = std::sin(th) / th;
    b = (1.0 - std::cos(th)) / th2;
  }
  return Mat3::Identity() + a * W + b * W * W;
}

Vec3 logSO3(const Mat3& R) {
  const double tr = R.trace();
  const double c = std::clamp(0.5 * (tr - 1.0), -1.0, 1.0);
  const Vec3 v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));  // = 2 sin(th) axis
  if (c > 1.0 - 1e-8) {
    // near identity: th/(2 sin th) = 1/2 + th^2/12 + ...; th^2 ~ |v|^2/4
    const double th2 = 0.25 * v.squaredNorm();
    return (0.5 + th2 / 12.0) * v;
  }
  const double th = std::acos(c);
  if (c > -0.99) {
    return th / (2.0 * std::sin(th)) * v;
  }
  // near pi, sin(th) is small: recover the axis from the symmetric part R + R^T = 2 cos I + 2(1-cos) a a^T
  const Mat3 B = 0.5 * (R + R.transpose()) - c * Mat3::Identity();  // = (1-c) a a^T
  int k;
  B.diagonal().maxCoeff(&k);
  Vec3 axis = B.col(k).normalized();  // B.col(k) = (1-c) a_k a
  // the sign of the axis comes from the skew part (v = 2 sin(th) a); use the stabler atan2 angle
  if (axis.dot(v) < 0) axis = -axis;
  const double s = 0.5 * v.dot(axis);  // sin(th) >= 0
  const double th_acc = std::atan2(s, c);
  return th_acc * axis;
}

Mat3 leftJacobianSO3(const Vec3& w) {
  const double th2 = w.squaredNorm();
  const double th = std::sqrt(th2);
  const Mat3 W = skew(w);
  double b, c;  // V = I + b W + c W^2
  if (th < 1e-4) {
    b = 0.5 - th2 / 24.0 + th2 * th2 / 720.0;
    c = 1.0 / 6.0 - th2 / 120.0 + th2 * th2 / 5040.0;
  } else {
    b = (1.0 - std::cos(th)) / th2;
    c = (th - std::sin(th)) / (th2 * th);
  }
  return Mat3::Identity() + b * W + c * W * W;
}

Mat4 expSE3(const Vec6& phi) {
  const Vec3 w = phi.head<3>();
  return makeE(expSO3(w), leftJacobianSO3(w) * phi.tail<3>());
}

Vec6 logSE3(const Mat4& E) {
  const Vec3 w = logSO3(E.topLeftCorner<3, 3>());
  Vec6 phi;
  phi.head<3>() = w;
  phi.tail<3>() = leftJacobianSO3(w).inverse() * E.topRightCorner<3, 1>();
  return phi;
}

Mat3 rotationAxisAngle(const Vec3& unit_axis, double angle) {
  // joints call this per axis per frame, most often with a Constant 0 angle (exactly I either way)
  if (angle == 0.0) return Mat3::Identity();
  return expSO3(unit_axis * angle);
}

Mat3 rotationUnitAxis(const Vec3& a, double angle) {
  if (angle == 0.0) return Mat3::Identity();
  const double s = std::sin(angle), c = std::cos(angle), t = 1.0 - c;
  Mat3 R;
  R << c + t * a.x() * a.x(), t * a.x() * a.y() - s * a.z(), t * a.x() * a.z() + s * a.y(),
       t * a.x() * a.y() + s * a.z(), c + t * a.y() * a.y(), t * a.y() * a.z() - s * a.x(),
       t * a.x() * a.z() - s * a.y(), t * a.y() * a.z() + s * a.x(), c + t * a.z() * a.z();
  return R;
}

Mat6 spatialInertia(double mass, const Vec3& com, const Mat3& inertia_com) {
  const Mat3 C = skew(com);
  Mat6 M;
  M.topLeftCorner<3, 3>() = inertia_com + mass * C * C.transpose();
  M.topRightCorner<3, 3>() = mass * C;
  M.bottomLeftCorner<3, 3>() = mass * C.transpose();
  M.bottomRightCorner<3, 3>() = mass * Mat3::Identity();
  return M;
}

}  // namespace redmax
