#include "core/deformable/node_solver.hpp"

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <stdexcept>

namespace redmax {

namespace {

// rows and columns `dofs` of A
SparseMat restrict(const SparseMat& A, const std::vector<int>& dofs) {
  std::vector<int> map(A.rows(), -1);
  for (size_t i = 0; i < dofs.size(); ++i) map[dofs[i]] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(A.nonZeros());
  for (int c = 0; c < A.outerSize(); ++c) {
    if (map[c] < 0) continue;
    for (SparseMat::InnerIterator it(A, c); it; ++it)
      if (map[it.row()] >= 0) t.emplace_back(map[it.row()], map[c], it.value());
  }
  SparseMat B(dofs.size(), dofs.size());
  B.setFromTriplets(t.begin(), t.end());
  return B;
}

void check(const NodeSpaceProblem& p, const VecX& x) {
  if (!p.body) throw std::invalid_argument("node-space problem without a body");
  if (static_cast<int>(p.fixed.size()) != p.body->numNodes() || x.size() != 3 * p.body->numNodes())
    throw std::invalid_argument("node-space problem: sizes do not match the body's nodes");
}

}  // namespace

std::vector<int> NodeSpaceProblem::freeDofs() const {
  std::vector<int> d;
  for (size_t n = 0; n < fixed.size(); ++n)
    if (!fixed[n])
      for (int c = 0; c < 3; ++c) d.push_back(static_cast<int>(3 * n + c));
  return d;
}

StaticResult solveStatic(const NodeSpaceProblem& p, VecX& x, double tol, int max_iter) {
  check(p, x);
  const std::vector<int> dofs = p.freeDofs();
  StaticResult r;
  ElasticEvaluation ev;
  VecX g(dofs.size());
  Eigen::SimplicialLDLT<SparseMat> ldlt;
  for (r.iterations = 0;; ++r.iterations) {
    evalElastic(*p.body, x, true, ev);
    for (size_t i = 0; i < dofs.size(); ++i) g[i] = ev.f[dofs[i]] + p.body->mass[dofs[i] / 3] * p.gravity[dofs[i] % 3];
    r.residual = g.size() ? g.lpNorm<Eigen::Infinity>() : 0.0;
    if (!std::isfinite(r.residual)) throw std::runtime_error("solveStatic: non-finite force");
    if (r.residual <= tol) {
      r.converged = true;
      return r;
    }
    if (r.iterations >= max_iter) return r;
    const SparseMat K = restrict(ev.K, dofs);
    if (r.iterations == 0) ldlt.analyzePattern(K);
    ldlt.factorize(K);
    if (ldlt.info() != Eigen::Success) throw std::runtime_error("solveStatic: stiffness factorisation failed");
    const VecX dx = ldlt.solve(g);  // K dx = f
    for (size_t i = 0; i < dofs.size(); ++i) x[dofs[i]] += dx[i];
  }
}

ModalResult lowestMode(const NodeSpaceProblem& p, const VecX& x, double tol, int max_iter) {
  check(p, x);
  const std::vector<int> dofs = p.freeDofs();
  ElasticEvaluation ev;
  evalElastic(*p.body, x, true, ev);
  const SparseMat K = restrict(ev.K, dofs), M = restrict(nodeMassMatrix(*p.body), dofs);
  Eigen::SimplicialLDLT<SparseMat> ldlt(K);
  if (ldlt.info() != Eigen::Success) throw std::runtime_error("lowestMode: stiffness factorisation failed");
  // inverse iteration: v <- K^-1 M v converges to the mode of the smallest omega^2 (a degenerate
  // pair, such as a square beam's two bending modes, gives one vector of their plane: same omega)
  VecX v = VecX::Ones(static_cast<Eigen::Index>(dofs.size()));
  ModalResult r;
  double last = 0.0;
  for (r.iterations = 1; r.iterations <= max_iter; ++r.iterations) {
    v = ldlt.solve(M * v);
    v /= std::sqrt(v.dot(M * v));
    const double rq = v.dot(K * v);  // omega^2 (v is M-normalised)
    if (!(rq > 0)) throw std::runtime_error("lowestMode: the stiffness is not positive definite");
    if (r.iterations > 1 && std::abs(rq - last) <= tol * rq) {
      r.omega = std::sqrt(rq);
      r.converged = true;
      return r;
    }
    last = rq;
  }
  r.omega = std::sqrt(last);
  return r;
}

void implicitStepSystem(const NodeSpaceProblem& p, const VecX& x, const VecX& v, double h, SparseMat& A, VecX& rhs) {
  check(p, x);
  const std::vector<int> dofs = p.freeDofs();
  const int n = static_cast<int>(dofs.size());
  const DeformableBody& b = *p.body;
  ElasticEvaluation ev;
  evalElastic(b, x, true, ev);
  VecX vf(n), f(n);
  for (int i = 0; i < n; ++i) vf[i] = v[dofs[i]];
  const SparseMat K = restrict(ev.K, dofs);
  // the free rows and columns of M_x: lumped (diagonal) or consistent; fixed nodes do not move, so
  // their columns do not act
  const SparseMat M = restrict(nodeMassMatrix(b), dofs);
  // f + D v with f = elastic - D v + M g: the damping force cancels, leaving elastic + gravity
  // (M_x g per node is the node's lumped mass times g, for both mass models)
  for (int i = 0; i < n; ++i) f[i] = ev.f[dofs[i]] + b.mass[dofs[i] / 3] * p.gravity[dofs[i] % 3];
  rhs = M * vf + h * f;
  A = (h * b.rayleigh_stiffness + h * h) * K + (1.0 + h * b.rayleigh_mass) * M;
}

void stepNodeSpace(const NodeSpaceProblem& p, VecX& x, VecX& v, double h, LinearSolve solve) {
  SparseMat A;
  VecX rhs, vnew;
  implicitStepSystem(p, x, v, h, A, rhs);
  if (solve == LinearSolve::Sparse) {
    Eigen::SimplicialLDLT<SparseMat> ldlt(A);
    if (ldlt.info() != Eigen::Success) throw std::runtime_error("stepNodeSpace: factorisation failed");
    vnew = ldlt.solve(rhs);
  } else {
    vnew = MatX(A).ldlt().solve(rhs);
  }
  const std::vector<int> dofs = p.freeDofs();
  for (size_t i = 0; i < dofs.size(); ++i) {
    v[dofs[i]] = vnew[i];
    x[dofs[i]] += h * vnew[i];
  }
}

}  // namespace redmax
