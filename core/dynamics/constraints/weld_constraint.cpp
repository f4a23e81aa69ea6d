#include "core/dynamics/constraints/weld_constraint.hpp"

#include "core/dynamics/constraints/body_point.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

using detail::calcPointKinematics;
using detail::calcRotationKinematics;
using detail::PointKinematics;
using detail::RotationKinematics;

namespace {

void checkRigid(const Mat4& E, const std::string& name) {
  const Mat3 R = E.topLeftCorner<3, 3>();
  const bool ok = E.allFinite() && (R.transpose() * R - Mat3::Identity()).norm() <= 1e-9 &&
                  R.determinant() > 0.0 && E.row(3).isApprox(Vec4(0, 0, 0, 1).transpose());
  if (!ok) throw ModelError(name + ": frame is not a rigid transform");
}

}  // namespace

WeldConstraint::WeldConstraint(const Model& model, int body_a, const Mat4& E_af, int body_b,
                               const Mat4& E_bg, std::string name)
    : name_(std::move(name)), body_a_(body_a), body_b_(body_b), E_af_(E_af), E_bg_(E_bg),
      nb_(model.nb()), nr_(model.nr()) {
  detail::checkBodyIndex(model, body_a, name_);
  detail::checkBodyIndex(model, body_b, name_);
  if (body_a == body_b) throw ModelError(name_ + ": both frames are on the same body");
  checkRigid(E_af, name_);
  checkRigid(E_bg, name_);
}

void WeldConstraint::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                      Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  detail::checkModelSize(model, nb_, nr_, name_);
  RotationKinematics ra, rb;
  PointKinematics pa, pb;
  calcRotationKinematics(model, ws, s.qdot, body_a_, ra);
  calcRotationKinematics(model, ws, s.qdot, body_b_, rb);
  calcPointKinematics(model, ws, s.qdot, body_a_, E_af_.topRightCorner<3, 1>(), pa);
  calcPointKinematics(model, ws, s.qdot, body_b_, E_bg_.topRightCorner<3, 1>(), pb);
  // rotational rows: world angular velocities; d/dt (R omega_i) = R omegadot_i
  G.topRows(3) = ra.J - rb.J;
  rhs.head(3) = -(ra.alpha_bias - rb.alpha_bias);
  // translational rows: the frame origins as in the point constraint [D Eq. 4.99-4.101]
  G.bottomRows(3) = pa.J - pb.J;
  rhs.tail(3) = -(pa.a_bias - pb.a_bias);
}

void WeldConstraint::calcErrors(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  detail::checkModelSize(model, nb_, nr_, name_);
  RotationKinematics ra, rb;
  PointKinematics pa, pb;
  calcRotationKinematics(model, ws, s.qdot, body_a_, ra);
  calcRotationKinematics(model, ws, s.qdot, body_b_, rb);
  calcPointKinematics(model, ws, s.qdot, body_a_, E_af_.topRightCorner<3, 1>(), pa);
  calcPointKinematics(model, ws, s.qdot, body_b_, E_bg_.topRightCorner<3, 1>(), pb);
  // R_wF R_wG^T = R_wa R_af R_bg^T R_wb^T; its derivative at identity is [omega_a - omega_b]
  const Mat3 R_wf = ra.R * E_af_.topLeftCorner<3, 3>();
  const Mat3 R_wg = rb.R * E_bg_.topLeftCorner<3, 3>();
  pos_err.head(3) = logSO3(R_wf * R_wg.transpose());
  pos_err.tail(3) = pa.p - pb.p;
  vel_err.head(3) = ra.omega - rb.omega;
  vel_err.tail(3) = pa.v - pb.v;
}

}  // namespace redmax
