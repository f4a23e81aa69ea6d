#pragma once
// Prescribed (and locked) reduced coordinates: hybrid dynamics [D Sec. 4.6.5, Eq. 4.109-4.110].
// Coordinate k follows a given function of time q_p(t) (with exact first and second
// derivatives); locked coordinates are the constant case (OpenSim `locked`, and `prescribed`
// with a prescribed_function).
//
// Sign convention. The System solves [M G^T; G 0] [qddot; lambda] = [f; rhs], i.e.
//   M qddot = f - G^T lambda.
// The row used here is G = -e_k^T with rhs = -qddot_p(t), so -G^T lambda = e_k lambda and
//   M qddot = f + e_k lambda:
// the multiplier of this row IS the generalized force (torque for a rotational coordinate, force
// for a translational one) that an actuator on coordinate k must apply to produce the prescribed
// motion; with every coordinate prescribed, the multipliers equal the inverse-dynamics torques.
// Consistently, the position error is C = q_p(t) - q_k (so G = dC/dq) and the velocity error is
// dC/dt = qdot_p(t) - qdot_k.
#include "core/dynamics/constraint.hpp"
#include "core/dynamics/constraints/constraint_function.hpp"

namespace redmax {

class PrescribedCoordinate final : public Constraint {
 public:
  /// coordinate in [0, nr); trajectory: a function of time t (one argument, or none for a
  /// constant). Throws ModelError.
  PrescribedCoordinate(const Model& model, int coordinate, ConstraintFunctionPtr trajectory,
                       std::string name = "");
  /// a locked coordinate: held at `value`
  static std::shared_ptr<PrescribedCoordinate> makeLocked(const Model& model, int coordinate, double value);

  std::string name() const override { return name_; }
  int rows() const override { return 1; }
  bool isPrescribed() const override { return true; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override;
  /// pos_err = q_p(t) - q_k, vel_err = qdot_p(t) - qdot_k
  void calcErrors(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override;

  int coordinate() const { return k_; }
  /// q_p(t), qdot_p(t), qddot_p(t)
  double position(double t) const;
  double velocity(double t) const;
  double acceleration(double t) const;
  /// q_p, qdot_p, qddot_p at t in one evaluation
  void trajectory(double t, double& q, double& qdot, double& qddot) const;

 private:
  std::string name_;
  int k_;
  ConstraintFunctionPtr traj_;
  int nr_;
};

}  // namespace redmax
