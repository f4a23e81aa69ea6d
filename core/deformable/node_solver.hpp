#pragma once
// Deformable bodies on their own, in node space (no skeleton): nodes free or fixed where they are.
// Used for the static checks (cantilever, patch test) and the speed study of dense against sparse
// solves (docs/deformable.md §5). The System assembles dense matrices; this path keeps K, D and M
// sparse, which the coupled System path does not.
#include <vector>

#include "core/deformable/deformable_body.hpp"

namespace redmax {

/// Which of the 3N node coordinates move (the others stay where x puts them).
struct NodeSpaceProblem {
  const DeformableBody* body = nullptr;
  std::vector<char> fixed;  // per node (N): 1 = fixed in the world
  Vec3 gravity = Vec3::Zero();
  /// indices of the moving coordinates (3 per free node, in node order)
  std::vector<int> freeDofs() const;
};

struct StaticResult {
  int iterations = 0;
  double residual = 0.0;  // max |force| on the free coordinates at the end (N)
  bool converged = false;
};

/// The lowest natural angular frequency (rad/s) of small vibrations about positions x (3N, usually
/// the rest positions): the smallest eigenvalue of K phi = omega^2 M phi over the moving
/// coordinates, with the body's mass matrix (lumped or consistent, DeformableBody::node_mass) and
/// its exact stiffness at x, by inverse iteration (sparse LDLT of K) until the Rayleigh quotient
/// changes by less than tol relative. Throws std::runtime_error when K is singular (a free body).
struct ModalResult {
  double omega = 0.0;  // rad/s
  int iterations = 0;
  bool converged = false;
};
ModalResult lowestMode(const NodeSpaceProblem& p, const VecX& x, double tol = 1e-12, int max_iter = 500);

/// Static equilibrium of elastic forces and gravity by Newton's method with the exact stiffness
/// (sparse LDLT), starting from x (3N), which it updates; stops when max |f| <= tol (N).
StaticResult solveStatic(const NodeSpaceProblem& p, VecX& x, double tol = 1e-10, int max_iter = 50);

enum class LinearSolve { Dense, Sparse };

/// The linear system of one step below over the free coordinates (freeDofs order): the sparse
/// matrix A = M + h D + h^2 K and rhs = M v + h (f + D v), for callers with their own solver.
void implicitStepSystem(const NodeSpaceProblem& p, const VecX& x, const VecX& v, double h, SparseMat& A, VecX& rhs);

/// One linearly implicit Euler step [D Eq. 4.78-4.82] of the free nodes:
///   (M + h D + h^2 K) v+ = M v + h (f + D v),   x+ = x + h v+,
/// K the exact stiffness, D = alpha M + beta K, f elastic + damping + gravity. Dense: Eigen's LDLT
/// of the dense matrix; Sparse: Eigen's SimplicialLDLT. x, v: 3N.
void stepNodeSpace(const NodeSpaceProblem& p, VecX& x, VecX& v, double h, LinearSolve solve);

}  // namespace redmax
