#include "core/dynamics/constraints/coordinate_coupler.hpp"

#include <algorithm>
#include <cmath>

namespace redmax {

void checkCoordinateIndices(const Model& model, const std::vector<int>& indices, const std::string& what) {
  for (size_t k = 0; k < indices.size(); ++k) {
    const int i = indices[k];
    if (i < 0 || i >= model.nr())
      throw ModelError(what + ": coordinate index " + std::to_string(i) + " out of range (model has " +
                       std::to_string(model.nr()) + " coordinates)");
    if (std::find(indices.begin(), indices.begin() + static_cast<long>(k), i) != indices.begin() + static_cast<long>(k))
      throw ModelError(what + ": coordinate '" + model.coordinates()[i].name + "' appears twice");
  }
}

CoordinateCoupler::CoordinateCoupler(const Model& model, int dependent, std::vector<int> independent,
                                     ConstraintFunctionPtr f, double scale, std::string name)
    : name_(std::move(name)), dep_(dependent), indep_(std::move(independent)), f_(std::move(f)),
      scale_(scale), nr_(model.nr()) {
  if (indep_.empty()) throw ModelError(name_ + ": no independent coordinate");
  if (indep_.size() > 6)
    throw ModelError(name_ + ": at most 6 independent coordinates, got " + std::to_string(indep_.size()));
  std::vector<int> all = indep_;
  all.push_back(dep_);
  checkCoordinateIndices(model, all, name_);
  if (!f_) throw ModelError(name_ + ": no coupling function");
  if (!acceptsArguments(*f_, static_cast<int>(indep_.size())))
    throw ModelError(name_ + ": coupling function takes " + std::to_string(f_->numArgs()) +
                     " arguments but " + std::to_string(indep_.size()) + " independent coordinates are given");
  if (!std::isfinite(scale_)) throw ModelError(name_ + ": non-finite scale factor");
}

VecJ CoordinateCoupler::gather(const VecX& v) const {
  VecJ x(indep_.size());
  for (size_t k = 0; k < indep_.size(); ++k) x[static_cast<long>(k)] = v[indep_[k]];
  return x;
}

void CoordinateCoupler::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace&,
                                         Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  if (model.nr() != nr_) throw ModelError(name_ + ": used with a model of a different size");
  const VecJ x = gather(s.q);
  const VecJ xdot = gather(s.qdot);
  FunctionValue fv;
  evaluateWithArguments(*f_, x, 2, fv);
  // reduced-coordinate constraint [D Eq. 4.103]: G_r qddot = -Gdot_r qdot
  G.setZero();
  for (size_t k = 0; k < indep_.size(); ++k) G(0, indep_[k]) += scale_ * fv.gradient[static_cast<long>(k)];
  G(0, dep_) = -1.0;
  rhs[0] = -scale_ * xdot.dot(fv.hessian * xdot);
}

void CoordinateCoupler::calcErrors(const Model& model, const State& s, const SkeletonWorkspace&,
                                   Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  if (model.nr() != nr_) throw ModelError(name_ + ": used with a model of a different size");
  const VecJ x = gather(s.q);
  const VecJ xdot = gather(s.qdot);
  FunctionValue fv;
  evaluateWithArguments(*f_, x, 1, fv);
  pos_err[0] = scale_ * fv.value - s.q[dep_];
  vel_err[0] = scale_ * fv.gradient.dot(xdot) - s.qdot[dep_];
}

}  // namespace redmax
