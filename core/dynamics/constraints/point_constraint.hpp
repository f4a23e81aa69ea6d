#pragma once
// Loop-closing point constraints on maximal coordinates [D Sec. 4.6.4, Eq. 4.96-4.101].
//
//   PointConstraint       3 rows: point x_a on body A and point x_b on body B coincide (a ball-
//                         and-socket loop closure; OpenSim PointConstraint).
//   HingePointConstraint  2 rows: the same, but only along the two directions orthogonal to a hinge
//                         axis [D Eq. 4.97-4.98], for planar loops where the 3-row version leaves a
//                         redundant (all-zero) row and a singular KKT system.
//
// Either body may be the world (index -1; its "body coordinates" are world coordinates). With
// G_m the maximal-coordinate Jacobian of the point velocities, every G here is G_m J_mr (reduced,
// nr columns) and rhs = -(Gdot_m J_mr + G_m Jdot_mr) qdot_r [D Eq. 4.101, 4.105]. The
// position error C is the world-frame separation p_a - p_b (projected for the hinge version) and
// G = dC/dq_r exactly.
#include "core/dynamics/constraint.hpp"

namespace redmax {

class PointConstraint final : public Constraint {
 public:
  /// body_a, body_b in [-1, nb) and different; x_a, x_b in the respective body frames.
  /// Throws ModelError on bad indices.
  PointConstraint(const Model& model, int body_a, const Vec3& x_a, int body_b, const Vec3& x_b,
                  std::string name = "point");
  std::string name() const override { return name_; }
  int rows() const override { return 3; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override;
  /// pos_err = p_a - p_b (world), vel_err = its time derivative
  void calcErrors(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override;

 private:
  std::string name_;
  int body_a_, body_b_;
  Vec3 x_a_, x_b_;
  int nb_, nr_;
};

class HingePointConstraint final : public Constraint {
 public:
  /// As PointConstraint, enforced along the two unit directions orthogonal to `axis` (any length
  /// > 0), which is fixed in body `axis_body` (-1: world; a planar loop's common hinge axis).
  /// Rows are v_k . (p_a - p_b), k = 1, 2, with v_k built from the axis as in [D Eq. 4.97].
  HingePointConstraint(const Model& model, int body_a, const Vec3& x_a, int body_b, const Vec3& x_b,
                       int axis_body, const Vec3& axis, std::string name = "hinge_point");
  std::string name() const override { return name_; }
  int rows() const override { return 2; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override;
  void calcErrors(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override;

  /// the two directions orthogonal to the axis, in the axis body's frame (columns)
  const Eigen::Matrix<double, 3, 2>& directions() const { return U_; }

 private:
  struct Geometry;  // both points, the axis frame, their separation d and its rate
  Geometry calcGeometry(const Model& model, const State& s, const SkeletonWorkspace& ws) const;
  std::string name_;
  int body_a_, body_b_, axis_body_;
  Vec3 x_a_, x_b_;
  Eigen::Matrix<double, 3, 2> U_;
  int nb_, nr_;
};

}  // namespace redmax
