#pragma once
// Linear solves shared by the implicit integrators (bdf1, sdirk2).
#include "core/dynamics/system.hpp"

namespace redmax::detail {

/// Solve [A G^T; G 0] [x; lambda] = [a; b] for the implicit matrix A = M + c1 D + c2 K (ndof x
/// ndof; G may have zero rows). A is symmetric for joint springs and dampers but a ForceTerm may
/// add a non-symmetric K or D; then the System's symmetric KKT solver (which reads one triangle)
/// is bypassed for a pivoted LU of the full matrix.
VecX solveImplicit(const MatX& A, const MatX& G, const VecX& a, const VecX& b, VecX* lambda);

/// The same with a sparse A (bdf1's sparse route): A factored once (simplicial LDL^T with AMD
/// ordering when A is symmetric and the factorisation succeeds, else sparse LU with COLAMD), the
/// constraints by the Schur complement G A^-1 G^T (nc solves) with a complete orthogonal
/// decomposition, so redundant rows get the minimum-norm multiplier as in System::solveKKT.
/// Throws std::runtime_error when A is singular.
VecX solveImplicitSparse(const Eigen::SparseMatrix<double>& A, const MatX& G, const VecX& a, const VecX& b,
                         VecX* lambda);

}  // namespace redmax::detail
