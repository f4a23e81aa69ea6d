#pragma once
// Forward dynamics by the tree's structure (issue 18; docs/performance.md §10), beside the dense
// route M qddot = f with M = J_mr^T M_m J_mr and a dense LDLT:
//   - CRBA: the skeleton's mass matrix by composite rigid bodies [Featherstone, RBDA Sec. 6.2]:
//     O(n d) for n bodies of depth d, without J_mr^T M_m J_mr; equal to calcSkeletonMass.
//   - LTDL: M = L^T D L over the coordinates' parent array lambda (lambda(k) < k), which has no
//     fill-in when every non-zero M(k, j), j < k, has j among k's ancestors [RBDA Sec. 6.5]; the
//     skeleton's M always has that pattern, muscle mass terms keep it when every muscle's
//     coordinates lie on one root-to-leaf path (checked per call; the System falls back to dense).
//   - ABA: the articulated-body algorithm [RBDA Sec. 7.3] for the bare skeleton (no term adds
//     mass, no constraints): O(n), neither M nor J_mr.
// Conventions as core/dynamics/skeleton_dynamics.hpp: body-frame twists (omega; v), wrenches
// (torque; force), X_i = Ad of the parent frame in body i, S_i = Ad_ij S the joint's twist map in i.
#include <optional>
#include <vector>

#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// How System::forwardDynamics solves M qddot = f (System::forward_route; docs/forward.md):
///   Auto         Articulated for a bare skeleton (no term adds mass, ForceTerm::addsMass),
///                TreeSparse with mass terms from kTreeSparseMinDof coordinates, else Dense;
///                Dense whenever there are constraints, a coordinate map or extra coordinates
///   Dense        M = J_mr^T M_m J_mr (+ terms), dense LDLT (KKT with constraints): the reference
///   TreeSparse   M by CRBA (+ terms), LTDL over the tree (needs no constraints, map, extras)
///   Articulated  ABA (needs a bare skeleton as above)
/// A route that does not apply, or fails at run time (a muscle coupling two branches for
/// TreeSparse, a non-positive articulated pivot), is replaced by Dense; DynamicsWorkspace::
/// last_route says which one ran.
enum class ForwardRoute { Auto, Dense, TreeSparse, Articulated };

/// "auto", "dense", "tree_sparse", "articulated"
const char* forwardRouteName(ForwardRoute r);

/// Auto takes TreeSparse over Dense from this many coordinates on (with mass terms).
/// Chosen from validation/bench/forward_structure_bench (docs/performance.md §10, measured).
inline constexpr int kTreeSparseMinDof = 16;

/// Scratch of the structured routes (one per DynamicsWorkspace; sized on first use).
struct StructuredForwardWorkspace {
  // CRBA
  std::vector<Mat6> Ic;              // composite inertia of each subtree, body frame     (nb)
  // LTDL
  std::vector<int> lambda;           // parent coordinate of each coordinate (-1: none)   (n)
  std::vector<int> stamp;            // pattern check scratch                              (n)
  MatX LD;                           // L (strictly lower) and D (diagonal)               (n x n)
  // ABA
  std::vector<JointKinematics> jk;   // per joint Q, S, Sdot                              (nb)
  std::vector<Mat6> Ad_ij;           // Ad of joint frame M in body i (constant)          (nb)
  std::vector<Mat6> X;               // Ad of the parent body frame in body i             (nb)
  std::vector<Mat6X> S, U;           // S_i, U_i = IA_i S_i                                (nb, 6 x nq)
  std::vector<MatJ> Dinv;            // (S_i^T IA_i S_i)^-1                                (nb, nq x nq)
  std::vector<VecJ> u;               // tau_i - S_i^T pA_i                                 (nb, nq)
  std::vector<Mat4> E_wi;            // poses                                              (nb)
  std::vector<Vec6> phi, c, pA, a;   // twist, velocity-product acceleration, bias force,
                                     // acceleration                                       (nb)
  std::vector<Mat6> IA;              // articulated inertia                                (nb)
  VecX tau;                          // applied generalized forces (terms, loads)          (nr)
  // the System's skeleton force by Newton-Euler at zero accelerations (its own, so that it never
  // disturbs an inverse dynamics begun in DynamicsWorkspace::rid)
  VecX qddot0;                       // zeros                                              (nr)
  std::optional<RecursiveIdWorkspace> rid;
  /// size everything but tau for `model` (a no-op when sized)
  void resize(const Model& model);
};

/// M_r (nr x nr, both triangles) by CRBA from the position stage of `sk` (Ad_ip and the diagonal
/// blocks of J_mr). Equal to calcSkeletonMass to round-off.
void calcSkeletonMassCrba(const Model& model, const SkeletonWorkspace& sk, StructuredForwardWorkspace& fw, MatX& M_r);

/// The coordinates' parent array: the previous coordinate of the same joint, else the last
/// coordinate of the nearest ancestor joint that has coordinates, else -1. Always lambda[k] < k.
void coordinateParents(const Model& model, std::vector<int>& lambda);

/// True if every non-zero M(k, j), j < k, of the lower triangle has j on k's chain of parents
/// (the pattern LTDL needs; `stamp` is scratch of size n).
bool hasTreePattern(const MatX& M, const std::vector<int>& lambda, std::vector<int>& stamp);

/// LTDL of the symmetric M (lower triangle read) into LD: M = L^T D L. False when a pivot is not
/// positive and finite (M not positive definite); LD is then unusable.
bool factorLTDL(const MatX& M, const std::vector<int>& lambda, MatX& LD);
/// x := M^-1 x with the factor of factorLTDL (no allocation)
void solveLTDL(const MatX& LD, const std::vector<int>& lambda, VecX& x);

/// ABA: qddot of the bare skeleton with gravity, velocity products, joint springs and dampers and
/// the applied generalized forces tau (nr; empty: none). False if an articulated pivot
/// S^T IA S is not positive definite (massless subtree): qddot is then not set.
bool articulatedBodyForward(const Model& model, const State& s, const VecX& tau, StructuredForwardWorkspace& fw,
                            VecX& qddot);

}  // namespace redmax
