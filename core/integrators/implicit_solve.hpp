#pragma once
// Linear solves shared by the implicit integrators (bdf1, sdirk2).
#include "core/dynamics/system.hpp"

namespace redmax::detail {

/// Solve [A G^T; G 0] [x; lambda] = [a; b] for the implicit matrix A = M + c1 D + c2 K (ndof x
/// ndof; G may have zero rows). A is symmetric for joint springs and dampers but a ForceTerm may
/// add a non-symmetric K or D; then the System's symmetric KKT solver (which reads one triangle)
/// is bypassed for a pivoted LU of the full matrix.
VecX solveImplicit(const MatX& A, const MatX& G, const VecX& a, const VecX& b, VecX* lambda);

}  // namespace redmax::detail
