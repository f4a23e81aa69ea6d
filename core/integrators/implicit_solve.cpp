#include "core/integrators/implicit_solve.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>

#include <stdexcept>

namespace redmax::detail {

VecX solveImplicit(const MatX& A, const MatX& G, const VecX& a, const VecX& b, VecX* lambda) {
  const double scale = A.cwiseAbs().maxCoeff();
  const bool symmetric = (A - A.transpose()).cwiseAbs().maxCoeff() <= 1e-13 * scale;
  if (symmetric) return System::solveKKT(A, G, a, b, lambda);
  const int n = static_cast<int>(A.rows());
  const int m = static_cast<int>(G.rows());
  if (m == 0) {
    if (lambda) lambda->resize(0);
    return A.partialPivLu().solve(a);
  }
  MatX K = MatX::Zero(n + m, n + m);
  K.topLeftCorner(n, n) = A;
  K.topRightCorner(n, m) = G.transpose();
  K.bottomLeftCorner(m, n) = G;
  VecX r(n + m);
  r << a, b;
  const VecX x = K.fullPivLu().solve(r);
  if (lambda) *lambda = x.tail(m);
  return x.head(n);
}

VecX solveImplicitSparse(const Eigen::SparseMatrix<double>& A, const MatX& G, const VecX& a, const VecX& b,
                         VecX* lambda) {
  using SparseMat = Eigen::SparseMatrix<double>;
  const SparseMat At = A.transpose();
  const SparseMat asym = A - At;
  const double scale = A.nonZeros() > 0 ? A.coeffs().cwiseAbs().maxCoeff() : 0.0;
  const bool symmetric = asym.nonZeros() == 0 || asym.coeffs().cwiseAbs().maxCoeff() <= 1e-13 * scale;
  // one factorisation serves a and the constraint columns
  Eigen::SimplicialLDLT<SparseMat> ldlt;
  Eigen::SparseLU<SparseMat, Eigen::COLAMDOrdering<int>> lu;
  bool use_ldlt = false;
  if (symmetric) {
    ldlt.compute(A);
    use_ldlt = ldlt.info() == Eigen::Success && (ldlt.vectorD().array() != 0.0).all();
  }
  if (!use_ldlt) {
    lu.analyzePattern(A);
    lu.factorize(A);
    if (lu.info() != Eigen::Success)
      throw std::runtime_error("sparse implicit matrix is singular: " + lu.lastErrorMessage());
  }
  auto solve = [&](const auto& rhs) -> MatX { return use_ldlt ? MatX(ldlt.solve(rhs)) : MatX(lu.solve(rhs)); };
  const VecX Ainv_a = solve(a);
  const int m = static_cast<int>(G.rows());
  if (m == 0) {
    if (lambda) lambda->resize(0);
    return Ainv_a;
  }
  const MatX Ainv_Gt = solve(G.transpose());
  const MatX S = G * Ainv_Gt;
  const VecX lam = S.completeOrthogonalDecomposition().solve(G * Ainv_a - b);
  if (lambda) *lambda = lam;
  return Ainv_a - Ainv_Gt * lam;
}

}  // namespace redmax::detail
