#include "core/integrators/implicit_solve.hpp"

#include <Eigen/Dense>

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

}  // namespace redmax::detail
