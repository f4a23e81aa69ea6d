#include "core/dynamics/constraints/prescribed_point.hpp"

#include "core/dynamics/constraints/body_point.hpp"

namespace redmax {

PrescribedPoint::PrescribedPoint(const Model& model, int body, const Vec3& point, PointTrajectory trajectory,
                                 std::string name)
    : name_(std::move(name)), body_(body), x_(point), traj_(std::move(trajectory)), nb_(model.nb()),
      nr_(model.nr()) {
  if (name_.empty()) name_ = "prescribed_point";
  if (body < 0 || body >= model.nb())
    throw ModelError(name_ + ": body index " + std::to_string(body) + " out of range (model has " +
                     std::to_string(model.nb()) + " bodies)");
  if (!point.allFinite()) throw ModelError(name_ + ": non-finite point");
  if (!traj_) throw ModelError(name_ + ": no trajectory");
}

PointSample PrescribedPoint::evaluate(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                      detail::PointKinematics& p) const {
  detail::checkModelSize(model, nb_, nr_, name_);
  detail::calcPointKinematics(model, ws, s.qdot, body_, x_, p);
  return traj_(s.t);
}

void PrescribedPoint::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                       Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  detail::PointKinematics p;
  const PointSample tgt = evaluate(model, s, ws, p);
  // -(J qddot + a_bias) = -xddot_p: the sign makes lambda the applied force (see the header)
  G = -p.J;
  rhs = p.a_bias - tgt.a;
}

void PrescribedPoint::calcErrors(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                 Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  detail::PointKinematics p;
  const PointSample tgt = evaluate(model, s, ws, p);
  pos_err = tgt.x - p.p;
  vel_err = tgt.v - p.v;
}

}  // namespace redmax
