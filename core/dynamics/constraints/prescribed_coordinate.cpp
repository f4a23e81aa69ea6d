#include "core/dynamics/constraints/prescribed_coordinate.hpp"

namespace redmax {

PrescribedCoordinate::PrescribedCoordinate(const Model& model, int coordinate, ConstraintFunctionPtr trajectory,
                                           std::string name)
    : name_(std::move(name)), k_(coordinate), traj_(std::move(trajectory)), nr_(model.nr()) {
  if (k_ < 0 || k_ >= model.nr())
    throw ModelError("prescribed coordinate: index " + std::to_string(k_) + " out of range (model has " +
                     std::to_string(model.nr()) + " coordinates)");
  if (name_.empty()) name_ = "prescribed_" + model.coordinates[k_].name;
  if (!traj_) throw ModelError(name_ + ": no trajectory function");
  if (traj_->numArgs() != 1)
    throw ModelError(name_ + ": the trajectory must be a function of time only (1 argument), got " +
                     std::to_string(traj_->numArgs()));
}

std::shared_ptr<PrescribedCoordinate> PrescribedCoordinate::makeLocked(const Model& model, int coordinate,
                                                                       double value) {
  const std::string coord_name =
      coordinate >= 0 && coordinate < model.nr() ? model.coordinates[coordinate].name : std::to_string(coordinate);
  return std::make_shared<PrescribedCoordinate>(model, coordinate, makeConstantFunction(value),
                                                "locked_" + coord_name);
}

double PrescribedCoordinate::position(double t) const { return traj_->value(VecX::Constant(1, t)); }
double PrescribedCoordinate::velocity(double t) const { return traj_->gradient(VecX::Constant(1, t))[0]; }
double PrescribedCoordinate::acceleration(double t) const {
  return traj_->hessian(VecX::Constant(1, t))(0, 0);
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
  pos_err[0] = position(s.t) - s.q[k_];
  vel_err[0] = velocity(s.t) - s.qdot[k_];
}

}  // namespace redmax
