#include "core/dynamics/constraints/prescribed_coordinate.hpp"

namespace redmax {

PrescribedCoordinate::PrescribedCoordinate(const Model& model, int coordinate, ConstraintFunctionPtr trajectory,
                                           std::string name)
    : name_(std::move(name)), k_(coordinate), traj_(std::move(trajectory)), nr_(model.nr()) {
  if (k_ < 0 || k_ >= model.nr())
    throw ModelError("prescribed coordinate: index " + std::to_string(k_) + " out of range (model has " +
                     std::to_string(model.nr()) + " coordinates)");
  if (name_.empty()) name_ = "prescribed_" + model.coordinates()[k_].name;
  if (!traj_) throw ModelError(name_ + ": no trajectory function");
  if (!acceptsArguments(*traj_, 1))
    throw ModelError(name_ + ": the trajectory must be a function of time only (1 argument), got " +
                     std::to_string(traj_->numArgs()) + " arguments");
}

std::shared_ptr<PrescribedCoordinate> PrescribedCoordinate::makeLocked(const Model& model, int coordinate,
                                                                       double value) {
  const std::string coord_name =
      coordinate >= 0 && coordinate < model.nr() ? model.coordinates()[coordinate].name : std::to_string(coordinate);
  return std::make_shared<PrescribedCoordinate>(model, coordinate, makeConstantFunction(value),
                                                "locked_" + coord_name);
}

void PrescribedCoordinate::trajectory(double t, double& q, double& qdot, double& qddot) const {
  FunctionValue fv;
  evaluateWithArguments(*traj_, VecJ::Constant(1, t), 2, fv);
  q = fv.value;
  qdot = fv.gradient[0];
  qddot = fv.hessian(0, 0);
}

double PrescribedCoordinate::position(double t) const {
  double q, qd, qdd;
  trajectory(t, q, qd, qdd);
  return q;
}
double PrescribedCoordinate::velocity(double t) const {
  double q, qd, qdd;
  trajectory(t, q, qd, qdd);
  return qd;
}
double PrescribedCoordinate::acceleration(double t) const {
  double q, qd, qdd;
  trajectory(t, q, qd, qdd);
  return qdd;
}

void PrescribedCoordinate::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace&,
                                            Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  if (model.nr() != nr_) throw ModelError(name_ + ": used with a model of a different size");
  // -qddot_k = -qddot_p(t): the sign makes lambda the actuating force (see the header)
  // [D Eq. 4.109]; pG_r is constant so there is no Gdot term
  G.setZero();
  G(0, k_) = -1.0;
  rhs[0] = -acceleration(s.t);
}

void PrescribedCoordinate::calcErrors(const Model& model, const State& s, const SkeletonWorkspace&,
                                      Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  if (model.nr() != nr_) throw ModelError(name_ + ": used with a model of a different size");
  double q, qd, qdd;
  trajectory(s.t, q, qd, qdd);
  pos_err[0] = q - s.q[k_];
  vel_err[0] = qd - s.qdot[k_];
}

}  // namespace redmax
