#pragma once
// Coupler on reduced coordinates (OpenSim CoordinateCouplerConstraint): one dependent coordinate
// follows a function of independent ones,
//   C(q) = scale * f(q_i1, ..., q_in) - q_dep = 0,
// acting directly on q_r, so no J_mr factor [D Eq. 4.103]:
//   G   = scale * grad f (at the independent columns), -1 (at the dependent column)
//   rhs = -Gdot qdot = -scale * qdot_I^T Hess f qdot_I
// The same coupling can instead be eliminated with a CoordinateMap (hyper-reduced coordinates
// [D Sec. 4.6.2]); both give the same motion.
#include <vector>

#include "core/dynamics/constraint.hpp"
#include "core/dynamics/constraints/constraint_function.hpp"

namespace redmax {

class CoordinateCoupler final : public Constraint {
 public:
  /// dependent, independent: reduced-coordinate indices in [0, nr), all distinct, 1 to 6
  /// independent ones; f->numArgs() == independent.size() (or 0 for a constant). Throws
  /// ModelError on bad input.
  CoordinateCoupler(const Model& model, int dependent, std::vector<int> independent,
                    ConstraintFunctionPtr f, double scale = 1.0, std::string name = "coupler");
  std::string name() const override { return name_; }
  int rows() const override { return 1; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override;
  /// pos_err = scale f(q_I) - q_dep, vel_err = its time derivative
  void calcErrors(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override;

  int dependent() const { return dep_; }
  const std::vector<int>& independent() const { return indep_; }
  const ConstraintFunction& function() const { return *f_; }
  double scale() const { return scale_; }

 private:
  VecJ gather(const VecX& v) const;
  std::string name_;
  int dep_;
  std::vector<int> indep_;
  ConstraintFunctionPtr f_;
  double scale_;
  int nr_;
};

/// Checks a set of reduced-coordinate indices (in range, distinct); throws ModelError naming `what`.
void checkCoordinateIndices(const Model& model, const std::vector<int>& indices, const std::string& what);

}  // namespace redmax
