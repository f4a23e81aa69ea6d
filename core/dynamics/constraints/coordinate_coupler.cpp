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
      throw ModelError(what + ": coordinate '" + model.coordinates[i].name + "' appears twice");
  }
}

CoordinateCoupler::CoordinateCoupler(const Model& model, int dependent, std::vector<int> independent,
                                     ConstraintFunctionPtr f, double scale, std::string name)
    : name_(std::move(name)), dep_(dependent), indep_(std::move(independent)), f_(std::move(f)),
      scale_(scale), nr_(model.nr()) {
  if (indep_.empty()) throw ModelError(name_ + ": no independent coordinate");
  std::vector<int> all = indep_;
  all.push_back(dep_);
  checkCoordinateIndices(model, all, name_);
  if (!f_) throw ModelError(name_ + ": no coupling function");
  if (f_->numArgs() != static_cast<int>(indep_.size()))
    throw ModelError(name_ + ": coupling function takes " + std::to_string(f_->numArgs()) +
                     " arguments but " + std::to_string(indep_.size()) + " independent coordinates are given");
  if (!std::isfinite(scale_)) throw ModelError(name_ + ": non-finite scale factor");
}

VecX CoordinateCoupler::gather(const VecX& v) const {
  VecX x(indep_.size());
  for (size_t k = 0; k < indep_.size(); ++k) x[static_cast<long>(k)] = v[indep_[k]];
  return x;
}

void CoordinateCoupler::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace&,
                                         Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  if (model.nr() != nr_) throw ModelError(name_ + ": used with a model of a different size");
  const VecX x = gather(s.q);
  const VecX xdot = gather(s.qdot);
  const VecX g = f_->gradient(x);
  // reduced-coordinate constraint [D Eq. 4.103]: G_r qddot = -Gdot_r qdot
  G.setZero();
  for (size_t k = 0; k < indep_.size(); ++k) G(0, indep_[k]) += scale_ * g[static_cast<long>(k)];
  G(0, dep_) = -1.0;
  rhs[0] = -scale_ * xdot.dot(f_->hessian(x) * xdot);
}

void CoordinateCoupler::calcErrors(const Model& model, const State& s, const SkeletonWorkspace&,
                                   Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  if (model.nr() != nr_) throw ModelError(name_ + ": used with a model of a different size");
  const VecX x = gather(s.q);
  const VecX xdot = gather(s.qdot);
  pos_err[0] = scale_ * f_->value(x) - s.q[dep_];
  vel_err[0] = scale_ * f_->gradient(x).dot(xdot) - s.qdot[dep_];
}

}  // namespace redmax
