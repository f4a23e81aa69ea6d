#pragma once
// A free deformable node tied to a point of a skeleton body by a bilateral constraint: the issue's
// alternative to carrying the node on the body through J_am [D Eq. 4.90-4.91]. The node keeps its
// 3 extra coordinates x (System::addExtraCoordinates) and
//   C = x - p(q_r) = 0,   p = E_wi X_i,
//   G = dC/dq = [-J_p  I_3]   (J_p = R Gamma(X_i) J_mr(i,:), the point's Jacobian [D Eq. 4.96]),
//   G qddot = rhs = Jdot_p qdot_r   (from d^2 C / dt^2 = 0),
// so the multipliers are the force the body applies to the node (-G^T lambda acts on x as +lambda
// and on q_r as -J_p^T lambda). Both ways give the same motion; the constraint keeps M and K of the
// node in node space (the KKT system couples it), the J_am way folds them into q_r.
#include "core/dynamics/constraint.hpp"

namespace redmax {

class NodeConstraint final : public Constraint {
 public:
  /// node coordinates at index..index+2 of the System's q (extra coordinates), body point X_i in
  /// body `body`'s frame. Throws ModelError for a body out of range or index inside q_r.
  NodeConstraint(const Model& model, int index, int body, const Vec3& point_body, std::string name = "");

  std::string name() const override { return name_; }
  int rows() const override { return 3; }
  bool actsOnExtraCoordinates() const override { return true; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override;
  /// pos_err = x - p, vel_err = xdot - J_p qdot_r
  void calcErrors(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override;

  int index() const { return index_; }
  int body() const { return body_; }
  const Vec3& point() const { return point_; }

 private:
  std::string name_;
  int index_, body_;
  Vec3 point_;
};

}  // namespace redmax
