#include "core/dynamics/constraints/point_constraint.hpp"

#include <cmath>

#include "core/dynamics/constraints/body_point.hpp"

namespace redmax {

using detail::calcPointKinematics;
using detail::calcRotationKinematics;
using detail::PointKinematics;
using detail::RotationKinematics;

namespace {

void checkPair(const Model& model, int a, int b, const std::string& name) {
  detail::checkBodyIndex(model, a, name);
  detail::checkBodyIndex(model, b, name);
  if (a == b) throw ModelError(name + ": both points are on the same body (" + std::to_string(a) + ")");
}

void checkFinite(const Vec3& x, const std::string& name) {
  if (!x.allFinite()) throw ModelError(name + ": non-finite point or axis");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// PointConstraint

PointConstraint::PointConstraint(const Model& model, int body_a, const Vec3& x_a, int body_b,
                                 const Vec3& x_b, std::string name)
    : name_(std::move(name)), body_a_(body_a), body_b_(body_b), x_a_(x_a), x_b_(x_b),
      nb_(model.nb()), nr_(model.nr()) {
  checkPair(model, body_a, body_b, name_);
  checkFinite(x_a, name_);
  checkFinite(x_b, name_);
}

void PointConstraint::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                       Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  detail::checkModelSize(model, nb_, nr_, name_);
  PointKinematics a, b;
  calcPointKinematics(model, ws, s.qdot, body_a_, x_a_, a);
  calcPointKinematics(model, ws, s.qdot, body_b_, x_b_, b);
  // G_m J_mr and -(Gdot_m J_mr + G_m Jdot_mr) qdot [D Eq. 4.98-4.101] without the projection
  G = a.J - b.J;
  rhs = -(a.a_bias - b.a_bias);
}

void PointConstraint::calcErrors(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                 Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  detail::checkModelSize(model, nb_, nr_, name_);
  PointKinematics a, b;
  calcPointKinematics(model, ws, s.qdot, body_a_, x_a_, a);
  calcPointKinematics(model, ws, s.qdot, body_b_, x_b_, b);
  pos_err = a.p - b.p;
  vel_err = a.v - b.v;
}

// ---------------------------------------------------------------------------------------------
// HingePointConstraint

HingePointConstraint::HingePointConstraint(const Model& model, int body_a, const Vec3& x_a, int body_b,
                                           const Vec3& x_b, int axis_body, const Vec3& axis,
                                           std::string name)
    : name_(std::move(name)), body_a_(body_a), body_b_(body_b), axis_body_(axis_body), x_a_(x_a),
      x_b_(x_b), nb_(model.nb()), nr_(model.nr()) {
  checkPair(model, body_a, body_b, name_);
  detail::checkBodyIndex(model, axis_body, name_);
  checkFinite(x_a, name_);
  checkFinite(x_b, name_);
  checkFinite(axis, name_);
  const double n = axis.norm();
  if (!(n > 1e-12)) throw ModelError(name_ + ": hinge axis has zero length");
  const Vec3 a = axis / n;
  // two directions orthonormal to the axis [D Eq. 4.97]: start from the coordinate axis along
  // which |a| is smallest, so the cross products are far from degenerate
  Vec3 v1 = Vec3::Zero();
  int k = 0;
  a.cwiseAbs().minCoeff(&k);
  v1[k] = 1.0;
  const Vec3 v2 = a.cross(v1).normalized();
  v1 = v2.cross(a).normalized();
  U_.col(0) = v1;
  U_.col(1) = v2;
}

struct HingePointConstraint::Geometry {
  PointKinematics a, b;
  RotationKinematics k;
  Vec3 d, ddot;
};

HingePointConstraint::Geometry HingePointConstraint::calcGeometry(const Model& model, const State& s,
                                                                  const SkeletonWorkspace& ws) const {
  detail::checkModelSize(model, nb_, nr_, name_);
  Geometry g;
  calcPointKinematics(model, ws, s.qdot, body_a_, x_a_, g.a);
  calcPointKinematics(model, ws, s.qdot, body_b_, x_b_, g.b);
  calcRotationKinematics(model, ws, s.qdot, axis_body_, g.k);
  g.d = g.a.p - g.b.p;
  g.ddot = g.a.v - g.b.v;
  return g;
}

void HingePointConstraint::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                            Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  const Geometry g = calcGeometry(model, s, ws);
  const PointKinematics &a = g.a, &b = g.b;
  const RotationKinematics& k = g.k;
  const Vec3 &d = g.d, &ddot = g.ddot;
  for (int j = 0; j < 2; ++j) {
    // C_j = v_j . d with v_j = R_k u_j; vdot_j = omega x v_j. The terms in d vanish on the
    // constraint manifold (and entirely for a world axis, the dissertation's case [D Eq. 4.98,
    // 4.100]) but keep G = dC/dq exact everywhere, which the position projection relies on.
    const Vec3 v = k.R * U_.col(j);
    const Vec3 vxd = v.cross(d);
    G.row(j) = v.transpose() * (a.J - b.J) + vxd.transpose() * k.J;
    const Vec3 vdot = k.omega.cross(v);
    const double bias = k.alpha_bias.dot(vxd) + k.omega.cross(vdot).dot(d) + 2.0 * vdot.dot(ddot) +
                        v.dot(a.a_bias - b.a_bias);
    rhs[j] = -bias;
  }
}

void HingePointConstraint::calcErrors(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                      Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  const Geometry g = calcGeometry(model, s, ws);
  const RotationKinematics& k = g.k;
  const Vec3 &d = g.d, &ddot = g.ddot;
  for (int j = 0; j < 2; ++j) {
    const Vec3 v = k.R * U_.col(j);
    pos_err[j] = v.dot(d);
    vel_err[j] = k.omega.cross(v).dot(d) + v.dot(ddot);
  }
}

}  // namespace redmax
