#include "core/deformable/node_constraint.hpp"

#include "core/dynamics/constraints/body_point.hpp"

namespace redmax {

NodeConstraint::NodeConstraint(const Model& model, int index, int body, const Vec3& point_body, std::string name)
    : name_(std::move(name)), index_(index), body_(body), point_(point_body) {
  if (name_.empty()) name_ = "node_at_" + std::to_string(index);
  if (body < 0 || body >= model.nb())
    throw ModelError(name_ + ": body " + std::to_string(body) + " of a model with " + std::to_string(model.nb()));
  if (index < model.nr())
    throw ModelError(name_ + ": node coordinates at " + std::to_string(index) + ", inside the skeleton's " +
                     std::to_string(model.nr()));
  if (!point_body.allFinite()) throw ModelError(name_ + ": non-finite point");
}

void NodeConstraint::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                      Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  detail::PointKinematics p;
  detail::calcPointKinematics(model, ws, s.qdot.head(model.nr()), body_, point_, p);
  G.leftCols(model.nr()) = -p.J;
  G.middleCols<3>(index_) = Mat3::Identity();
  rhs = p.a_bias;  // xddot = J_p qddot + a_bias
}

void NodeConstraint::calcErrors(const Model& model, const State& s, const SkeletonWorkspace& ws,
                                Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  detail::PointKinematics p;
  detail::calcPointKinematics(model, ws, s.qdot.head(model.nr()), body_, point_, p);
  pos_err = s.q.segment<3>(index_) - p.p;
  vel_err = s.qdot.segment<3>(index_) - p.v;
}

}  // namespace redmax
