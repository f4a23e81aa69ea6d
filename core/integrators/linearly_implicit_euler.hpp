#pragma once
#include "core/integrators/integrator.hpp"

namespace redmax {

/// Linearly implicit backward Euler ("bdf1") [D Eq. 4.78-4.82]: the forces at the end of the
/// step are linearised about the start, f(q+, qdot+) ~ f - K (q+ - q) - D (qdot+ - qdot) with
/// K = -df/dq, D = -df/dqdot from System::calcStiffnessDamping (joint springs and dampers and
/// every ForceTerm's implicit part), and q+ = q + h qdot+, giving
///   (M + h D + h^2 K) qdot+ = M qdot + h (f + D qdot),   q+ = q + h qdot+.
/// Our f already contains the damping force -D qdot at the old velocity; adding h D qdot back
/// leaves the damping entirely implicit, which is [D Eq. 4.79-4.80] (there f excludes it).
/// Gravity and velocity-product terms stay explicit (they are not in K, D). First order;
/// unconditionally stable for linear springs and dampers. Constraints as in SymplecticEuler:
/// velocity-level KKT rows with the implicit matrix in place of M. Hard unilateral constraints
/// (System::unilateral(): joint limits, contacts with friction and restitution) add a QP on the
/// contact impulses to this step (core/dynamics/unilateral/unilateral.hpp, docs/contact.md §6).
/// With extra coordinates (deformable nodes) and IntegratorOptions::linear_solver the same step is
/// assembled and solved sparse (System::calcSparseMatrices, detail::solveImplicitSparse): equal
/// to the dense step to round-off, O(nnz) memory instead of O(ndof^2).
/// the number of coordinates from which linear_solver "auto" takes the sparse route (measured:
/// docs/deformable.md §5)
inline constexpr int kSparseStepFrom = 150;

class LinearlyImplicitEuler final : public FixedStepIntegrator {
 public:
  /// throws std::invalid_argument for a linear_solver other than auto, dense or sparse
  explicit LinearlyImplicitEuler(const IntegratorOptions& opt);
  /// whether a step of sys takes the sparse route (throws ModelError when "sparse" is asked for
  /// a system that only the dense route takes)
  bool sparseRoute(const System& sys) const;
  std::string name() const override { return "bdf1"; }
  /// one step of size h (state.t += h)
  void step(const System& sys, State& state, double h, DynamicsWorkspace& ws) override;
  bool handlesUnilateral() const override { return true; }

 private:
  UnilateralRows rows_;        // this step's candidate rows (kept to reuse their storage)
  UnilateralWarmStart warm_;   // the last step's active contacts
  Eigen::SparseMatrix<double> M_, K_, D_;  // the sparse route's matrices (kept for their storage)
};

}  // namespace redmax
