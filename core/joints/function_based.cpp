#include "core/joints/function_based.hpp"

#include <cmath>
#include <string>

#include "core/joints/product_of_exponentials.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

namespace {
using Mat3X = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 6>;
const char* kAxisNames[6] = {"rotation1", "rotation2", "rotation3",
                             "translation1", "translation2", "translation3"};

}  // namespace

FunctionBased::FunctionBased(int nq, std::array<TransformAxis, 6> axes, bool compat)
    : simbody_compat(compat), nq_(nq), axes_(std::move(axes)) {
  if (nq < 0 || nq > 6)
    throw JointError("function-based joint: " + std::to_string(nq) + " coordinates (must be 0..6)");
  // parallel axes make R or p lose a direction; OpenSim rejects them with this test on raw axes
  for (int base : {0, 3})
    for (int i = base; i < base + 3; ++i)
      for (int j = i + 1; j < base + 3; ++j)
        if (axes_[i].axis.cross(axes_[j].axis).norm() < 1e-5)
          throw JointError(std::string("function-based joint: ") + kAxisNames[i] + " and " +
                           kAxisNames[j] + " axes are parallel or zero");
  for (int k = 0; k < 6; ++k) {
    TransformAxis& ax = axes_[k];
    const std::string where = std::string("function-based joint, ") + kAxisNames[k] + ": ";
    if (!ax.axis.allFinite() || ax.axis.norm() == 0.0) throw JointError(where + "axis is zero or not finite");
    ax.axis.normalize();
    for (int c : ax.coordinates)
      if (c < 0 || c >= nq)
        throw JointError(where + "coordinate index " + std::to_string(c) + " outside 0.." +
                         std::to_string(nq - 1));
    const int m = static_cast<int>(ax.coordinates.size());
    if (!ax.function) {
      if (m == 0) ax.function = std::make_shared<const ConstantFunction>(0.0);
      else if (m == 1) ax.function = std::make_shared<const LinearFunction>(1.0, 0.0);
      else throw JointError(where + std::to_string(m) + " coordinates but no function");
    }
    if (ax.function->numArgs() != m)
      throw JointError(where + ax.function->typeName() + " takes " +
                       std::to_string(ax.function->numArgs()) + " arguments but " +
                       std::to_string(m) + " coordinates are listed");
    kind_[k] = AxisKind::General;
    if (const auto* c = dynamic_cast<const ConstantFunction*>(ax.function.get())) {
      kind_[k] = AxisKind::Constant;
      intercept_[k] = c->constant();
    } else if (const auto* l = dynamic_cast<const LinearFunction*>(ax.function.get()); l && m == 1) {
      kind_[k] = AxisKind::Linear1;
      slope_[k] = l->coefficients()[0];
      intercept_[k] = l->coefficients()[1];
    }
  }
}

void FunctionBased::evalAxis(int k, const VecJ& q, const VecJ& qdot, int order, double& v,
                             VecJ& grad, VecJ& graddot) const {
  const TransformAxis& ax = axes_[k];
  if (kind_[k] != AxisKind::General) {
    grad.setZero(nq_);
    graddot.setZero(nq_);
    if (kind_[k] == AxisKind::Constant) {
      v = intercept_[k];
      return;
    }
    const int c = ax.coordinates[0];
    v = slope_[k] * q[c] + intercept_[k];
    grad[c] = slope_[k];
    return;
  }
  const int m = static_cast<int>(ax.coordinates.size());
  VecJ x(m), xd(m);
  for (int j = 0; j < m; ++j) {
    x[j] = q[ax.coordinates[j]];
    xd[j] = qdot[ax.coordinates[j]];
  }
  FunctionValue fv;
  ax.function->evaluate(x, order, fv);
  v = fv.value;
  grad.setZero(nq_);
  graddot.setZero(nq_);
  if (order < 1 || m == 0) return;
  // chain rule into the joint's q: scatter by coordinate index (+= handles repeated indices)
  for (int j = 0; j < m; ++j) grad[ax.coordinates[j]] += fv.gradient[j];
  if (order < 2) return;
  const VecJ hd = fv.hessian * xd;
  for (int j = 0; j < m; ++j) graddot[ax.coordinates[j]] += hd[j];
}

double FunctionBased::spatialCoordinate(int k, const VecJ& q) const {
  double v;
  VecJ g, gd;
  evalAxis(k, q, VecJ::Zero(nq_), 0, v, g, gd);
  return v;
}

double FunctionBased::singularityDistance(const VecJ& q) const {
  for (int k = 0; k < 3; ++k)
    if (axes_[k].coordinates.empty()) return 1.0;
  const Mat3 R1 = rotationAxisAngle(axes_[0].axis, spatialCoordinate(0, q));
  const Mat3 R2 = rotationAxisAngle(axes_[1].axis, spatialCoordinate(1, q));
  Mat3 W;
  W << axes_[0].axis, R1 * axes_[1].axis, R1 * R2 * axes_[2].axis;
  return std::abs(W.determinant());
}

void FunctionBased::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  if (simbody_compat) {
    calcSimbody(q, qdot, out);
    return;
  }
  // exact: translations (they commute) then the body-fixed rotations, as one product
  detail::beginProduct(nq_, out);
  double v;
  VecJ g, gd;
  for (int k : {3, 4, 5, 0, 1, 2}) {
    const TransformAxis& ax = axes_[k];
    evalAxis(k, q, qdot, 2, v, g, gd);
    if (ax.coordinates.empty() && v == 0.0) continue;  // identity factor
    Vec6 xi = Vec6::Zero();
    if (k < 3) xi.head<3>() = ax.axis;
    else xi.tail<3>() = ax.axis;
    detail::appendFactor(xi, v, g, gd, qdot, out);
  }
}

void FunctionBased::calcSimbody(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  const int n = nq_;
  double v[6];
  Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6> Fq(6, n), Fqdot(6, n);  // d(spatial)/dq, its rate
  for (int k = 0; k < 6; ++k) {
    VecJ g, gd;
    evalAxis(k, q, qdot, 2, v[k], g, gd);
    Fq.row(k) = g.transpose();
    Fqdot.row(k) = gd.transpose();
  }
  const Vec3 a1 = axes_[0].axis, a2 = axes_[1].axis, a3 = axes_[2].axis;
  const Mat3 R1 = rotationUnitAxis(a1, v[0]);
  const Mat3 R12 = R1 * rotationUnitAxis(a2, v[1]);
  const Mat3 R = R12 * rotationUnitAxis(a3, v[2]);
  Mat3 At;
  At << axes_[3].axis, axes_[4].axis, axes_[5].axis;
  out.resize(n);
  out.Q = makeE(R, At * Vec3(v[3], v[4], v[5]));
  if (n == 0) return;

  // W with the true angles, and W for H with Constant angles taken as 0 (Simbody's buildH); the
  // two differ only where rotation1 or rotation2 is a nonzero Constant
  Mat3 W;
  W << a1, R1 * a2, R12 * a3;
  Mat3 Wh = W;
  const bool const1 = axes_[0].coordinates.empty() && v[0] != 0.0;
  const bool const2 = axes_[1].coordinates.empty() && v[1] != 0.0;
  if (const1 || const2) {
    auto angleForH = [&](int k) { return axes_[k].coordinates.empty() ? 0.0 : v[k]; };
    const Mat3 R1h = rotationUnitAxis(a1, angleForH(0));
    Wh << a1, R1h * a2, R1h * rotationUnitAxis(a2, angleForH(1)) * a3;
  }

  // column by column in fixed-size 3-vectors (the 3 x n dynamic products were most of the cost)
  Mat3X Hang = Mat3X::Zero(3, n);  // 3 x n, in F
  Vec3 Hq = Vec3::Zero();
  for (int c = 0; c < n; ++c) {
    Hang.col(c) = Wh * Fq.col(c).head<3>();
    Hq += Hang.col(c) * qdot[c];
  }
  // Simbody's Wdot: omega_a from mobility 0 alone, omega_b from all but mobility 2
  const Vec3 w_a = Hang.col(0) * qdot[0];
  const Vec3 w_b = n > 2 ? Vec3(Hq - Hang.col(2) * qdot[2]) : Hq;
  Mat3 Wdot;
  Wdot << Vec3::Zero(), w_a.cross(Vec3(W.col(1))), w_b.cross(Vec3(W.col(2)));

  // to M: S = R^T H; d/dt R^T = -[w] R^T with w = R^T H_ang qdot, the angular velocity Simbody
  // gives the body (V_FM = H u); it differs from the true one only for nonzero Constant rotations
  const Mat3 Rt = R.transpose();
  const Vec3 w = Rt * Hq;
  for (int c = 0; c < n; ++c) {
    const Vec3 s_ang = Rt * Hang.col(c), s_lin = Rt * (At * Fq.col(c).tail<3>());
    const Vec3 hd_ang = Wdot * Fq.col(c).head<3>() + W * Fqdot.col(c).head<3>();
    const Vec3 hd_lin = At * Fqdot.col(c).tail<3>();
    out.S.col(c) << s_ang, s_lin;
    out.Sdot.col(c) << Rt * hd_ang - w.cross(s_ang), Rt * hd_lin - w.cross(s_lin);
  }
}

}  // namespace redmax
