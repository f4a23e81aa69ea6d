#pragma once
// Dense strictly convex quadratic programs by the dual active-set method of Goldfarb and Idnani
// (1983, "A numerically stable dual method for solving strictly convex quadratic programs"):
//
//   min 1/2 x^T H x + g^T x   subject to   E x = e,   C x >= d            (H symmetric positive definite)
//
// The method starts at the unconstrained minimum -H^-1 g and adds violated constraints one at a
// time (dropping an active inequality when its multiplier would turn negative), keeping the
// factors J = L^-T Q and R of the active normals up to date with Givens rotations. Every iterate
// is dual feasible, so it ends at the optimum after finitely many steps, with no starting point
// to supply and no phase one; it fits the small dense QPs of contact and joint limits (tens of
// variables and constraints per step; docs/contact.md §6 says why it is ours and not a library's).
//
// At the solution (QpResult):  H x + g = E^T lambda_eq + C^T lambda_in,  lambda_in >= 0,
//                              lambda_in_k (C_k x - d_k) = 0,  E x = e,  C x >= d.
#include <stdexcept>
#include <vector>

#include "core/spatial/types.hpp"

namespace redmax {

struct QpProblem {
  MatX H;  // (n x n) symmetric positive definite
  VecX g;  // (n)
  MatX E;  // (me x n) equality rows (may be empty)
  VecX e;  // (me)
  MatX C;  // (mi x n) inequality rows (may be empty)
  VecX d;  // (mi)
};

struct QpOptions {
  int max_iterations = 0;   // adds plus drops; 0: 10 (n + me + mi) + 10
  double tolerance = 1e-10; // a constraint counts as violated below -tolerance (1 + |d_k|)
  /// warm start: inequality indices (into C) that were active in a related problem; they are
  /// tried first while violated, so that the method does not first add and later drop others.
  /// The dual method still starts from the unconstrained minimum (the adds remain).
  const std::vector<int>* warm_active = nullptr;
};

struct QpResult {
  VecX x;
  VecX lambda_eq;           // (me)
  VecX lambda_in;           // (mi), >= 0, zero for inactive rows
  std::vector<int> active;  // active inequality indices, in the order they were added
  int iterations = 0;       // adds plus drops
  double objective = 0.0;
};

/// The QP has no solution: inconsistent equalities, inequalities that cannot hold together, an
/// H that is not positive definite, mismatched sizes, or no convergence within max_iterations.
class QpError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Solve the QP (throws QpError as above). Redundant (linearly dependent but consistent)
/// equality rows are skipped; dependent inequalities are handled by the method itself.
QpResult solveQp(const QpProblem& p, const QpOptions& opt = {});

}  // namespace redmax
