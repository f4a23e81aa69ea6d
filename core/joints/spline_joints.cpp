#include "core/joints/spline_joints.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/joints/product_of_exponentials.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

CumulativeBasis::CumulativeBasis(double u) {
  const double u2 = u * u, u3 = u2 * u;
  // sums of the rows of B qv [D Eq. 4.64, 4.68]; they add up to 1 + u (linear precision)
  Bt << (5.0 + 3.0 * u - 3.0 * u2 + u3) / 6.0, (1.0 + 3.0 * u + 3.0 * u2 - 2.0 * u3) / 6.0,
      u3 / 6.0;
  dBt << 0.5 * (1.0 - u) * (1.0 - u), 0.5 * (1.0 + 2.0 * u - 2.0 * u2), 0.5 * u2;
  ddBt << u - 1.0, 1.0 - 2.0 * u, u;
}

SplineCurve::SplineCurve(std::vector<Mat4> control_frames) : frames_(std::move(control_frames)) {
  const int n = static_cast<int>(frames_.size());
  if (n < 4)
    throw JointError("spline curve joint needs at least 4 control frames, got " + std::to_string(n));
  for (int i = 0; i < n; ++i) {
    const Mat4& C = frames_[i];
    const Mat3 R = C.topLeftCorner<3, 3>();
    const bool rigid = C.allFinite() && (R.transpose() * R - Mat3::Identity()).norm() < 1e-9 &&
                       R.determinant() > 0 && C.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1));
    if (!rigid)
      throw JointError("spline curve joint: control frame " + std::to_string(i) +
                       " is not a rigid transform");
  }
  deltas_.assign(n, Vec6::Zero());
  for (int i = 1; i < n; ++i) {
    const Mat4 D = inverseE(frames_[i - 1]) * frames_[i];
    deltas_[i] = logSE3(D);
    if (deltas_[i].head<3>().norm() > 3.14159265358979323846 - 1e-6)
      throw JointError("spline curve joint: control frames " + std::to_string(i - 1) + " and " +
                       std::to_string(i) + " differ by a rotation of pi or more");
  }
}

void SplineCurve::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  // segment and local parameter; end segments extrapolate (see the header)
  // (compared as doubles first: a NaN or huge q must not reach the int conversion)
  const int last = numSegments() - 1;
  const double fl = std::floor(q[0]);
  const int s = fl >= last ? last : (fl > 0.0 ? static_cast<int>(fl) : 0);
  const double u = q[0] - s;
  const CumulativeBasis basis(u);
  // [D Alg. 3] as a product of exponentials with theta_i = B~_i(u), dtheta/dq = B~_i'(u)
  detail::beginProduct(1, out);
  VecJ g(1), gd(1);
  for (int i = 0; i < 3; ++i) {
    g[0] = basis.dBt[i];
    gd[0] = basis.ddBt[i] * qdot[0];
    detail::appendFactor(deltas_[s + 1 + i], basis.Bt[i], g, gd, qdot, out);
  }
  out.Q = frames_[s] * out.Q;  // a constant left factor does not change the body Jacobian
}

namespace {
// B qv, B qv', B qv'' for the basis matrix of [D Eq. 4.64]
void basisVectors(double t, Vec4& b, Vec4& db, Vec4& ddb) {
  const double t2 = t * t, t3 = t2 * t;
  b << (1.0 - 3.0 * t + 3.0 * t2 - t3) / 6.0, (4.0 - 6.0 * t2 + 3.0 * t3) / 6.0,
      (1.0 + 3.0 * t + 3.0 * t2 - 3.0 * t3) / 6.0, t3 / 6.0;
  db << (-3.0 + 6.0 * t - 3.0 * t2) / 6.0, (-12.0 * t + 9.0 * t2) / 6.0,
      (3.0 + 6.0 * t - 9.0 * t2) / 6.0, 0.5 * t2;
  ddb << (6.0 - 6.0 * t) / 6.0, (-12.0 + 18.0 * t) / 6.0, (6.0 - 18.0 * t) / 6.0, t;
}
}  // namespace

SplineSurface::SplineSurface(const std::array<Mat4, 6>& control) : control_(control) {
  for (int k = 0; k < 6; ++k)
    if (!control_[k].allFinite())
      throw JointError("spline surface joint: control values of coordinate " + std::to_string(k) +
                       " are not finite");
}

void SplineSurface::evalCoordinate(int k, const VecJ& q, double& f, Vec2& grad,
                                   Eigen::Matrix2d& hess) const {
  Vec4 b1, db1, ddb1, b2, db2, ddb2;
  basisVectors(q[0], b1, db1, ddb1);
  basisVectors(q[1], b2, db2, ddb2);
  const Mat4& C = control_[k];
  const Vec4 Cb2 = C * b2, Cdb2 = C * db2;
  // [D Eq. 4.71-4.72]
  f = b1.dot(Cb2);
  grad << db1.dot(Cb2), b1.dot(Cdb2);
  hess(0, 0) = ddb1.dot(Cb2);
  hess(1, 1) = b1.dot(C * ddb2);
  hess(0, 1) = hess(1, 0) = db1.dot(Cdb2);
}

void SplineSurface::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  // [D Alg. 4]: translations e_1..e_3 then rotations e_4..e_6 [D Eq. 4.73]
  static const Vec6 kBasis[6] = {
      (Vec6() << 0, 0, 0, 1, 0, 0).finished(), (Vec6() << 0, 0, 0, 0, 1, 0).finished(),
      (Vec6() << 0, 0, 0, 0, 0, 1).finished(), (Vec6() << 1, 0, 0, 0, 0, 0).finished(),
      (Vec6() << 0, 1, 0, 0, 0, 0).finished(), (Vec6() << 0, 0, 1, 0, 0, 0).finished()};
  detail::beginProduct(2, out);
  const Vec2 qd(qdot[0], qdot[1]);
  for (int k = 0; k < 6; ++k) {
    double f;
    Vec2 g;
    Eigen::Matrix2d H;
    evalCoordinate(k, q, f, g, H);
    detail::appendFactor(kBasis[k], f, VecJ(g), VecJ(H * qd), qdot, out);
  }
}

}  // namespace redmax
