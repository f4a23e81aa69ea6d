// bdf1's sparse route for systems with deformable nodes (System::calcSparseMatrices,
// detail::solveImplicitSparse; docs/deformable.md §5): the sparse M, K, D and f equal the dense
// ones, and a sparse run equals a dense run, with and without constraints, with a muscle through a
// node and Rayleigh damping (whose attached-node terms make K non-symmetric, so the LU branch runs
// as well as the LDL^T one).
#include <gtest/gtest.h>

#include <cstdio>

#include <random>

#include "core/integrators/implicit_solve.hpp"
#include "core/integrators/integrator.hpp"
#include "core/integrators/linearly_implicit_euler.hpp"
#include "tests/core/deformable/coupled_scene.hpp"

namespace redmax {
namespace {

using namespace test::coupled;

double relDiff(const MatX& a, const MatX& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1e-300, b.cwiseAbs().maxCoeff());
}

TEST(SparseStep, MatricesEqualTheDenseOnes) {
  for (AttachBy by : {AttachBy::Jacobian, AttachBy::Constraint}) {
    Scene sc = makeScene(by, Insertion::FarNode, 0.5, true);
    // stiffness-proportional damping too (its attached-node terms reach K)
    for (std::uint32_t seed : {1u, 2u}) {
      const State s = randomState(sc, seed);
      State sz = s;
      sz.z = sc.sys.defaultState().z;
      DynamicsWorkspace wd(sc.sys), wsp(sc.sys);
      wd.controls = wsp.controls = VecX::Constant(1, 0.3);
      sc.sys.calcMassAndForce(sz, wd);
      sc.sys.calcStiffnessDamping(sz, wd);
      Eigen::SparseMatrix<double> M, K, D;
      sc.sys.calcSparseMatrices(sz, wsp, true, M, K, D);
      const double eM = relDiff(MatX(M), wd.M), eK = relDiff(MatX(K), wd.K), eD = relDiff(MatX(D), wd.D);
      const double ef = relDiff(wsp.f, wd.f);
      std::printf("[ measured ] %s seed %u: M %.1e, K %.1e, D %.1e, f %.1e; nonzeros %.1f%% of %d^2\n",
                  by == AttachBy::Jacobian ? "carried" : "tied", seed, eM, eK, eD, ef,
                  100.0 * M.nonZeros() / (double(M.rows()) * M.rows()), static_cast<int>(M.rows()));
      EXPECT_LE(eM, 1e-15);  // the same sums in another order
      EXPECT_LE(eK, 1e-14);
      EXPECT_LE(eD, 1e-15);
      EXPECT_LE(ef, 1e-15);
      EXPECT_GT(wd.K.cwiseAbs().maxCoeff(), 1.0);
    }
  }
}

// a bdf1 run of `sc` from a deformed moving state, with the given linear solver
State run(const Scene& sc, const std::string& solver, int steps) {
  State s = randomState(sc, 7);
  s.z = sc.sys.defaultState().z;
  if (sc.sys.numConstraintRows() > 0) {
    DynamicsWorkspace ws(sc.sys);
    sc.sys.projectPositions(s, ws, 1e-14);
    sc.sys.projectVelocities(s, ws);
  }
  IntegratorOptions io;
  io.dt = 1e-3;
  io.linear_solver = solver;
  auto integ = makeIntegrator("bdf1", io);
  integ->advance(sc.sys, s, steps * io.dt);
  return s;
}

TEST(SparseStep, RunsEqualTheDenseRoute) {
  for (AttachBy by : {AttachBy::Jacobian, AttachBy::Constraint}) {
    const Scene sc = makeScene(by, Insertion::FarNode, 0.5, true);
    const State d = run(sc, "dense", 100), s = run(sc, "sparse", 100);
    const double eq = (d.q - s.q).cwiseAbs().maxCoeff(), ev = relDiff(s.qdot, d.qdot);
    std::printf("[ measured ] %s, 100 steps of 1 ms: q differs by %.2e, qdot by %.2e relative\n",
                by == AttachBy::Jacobian ? "carried" : "tied", eq, ev);
    EXPECT_LE(eq, 1e-11);  // measured 1.1e-14 (carried), 1.1e-12 (tied: KKT solves in another order)
    EXPECT_LE(ev, 1e-10);  // measured 1.8e-14, 1.4e-11
    EXPECT_GT((d.q - randomState(sc, 7).q).cwiseAbs().maxCoeff(), 1e-2);  // it moved
  }
}

TEST(SparseStep, SolverEqualsTheDenseSolveSymmetricOrNotWithRedundantRows) {
  // A = banded SPD (LDL^T branch), then with a non-symmetric perturbation (LU branch); G with a
  // repeated row (redundant: minimum-norm multipliers, as System::solveKKT)
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const int n = 40, m = 4;
  MatX A = MatX::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    A(i, i) = 4.0 + u(rng);
    if (i + 1 < n) A(i, i + 1) = A(i + 1, i) = u(rng);
  }
  MatX G = MatX::Zero(m, n);
  for (int j = 0; j < n; ++j) G(0, j) = G(1, j) = u(rng), G(2, j) = u(rng);
  G.row(3) = G.row(2);
  VecX a(n), b(m);
  for (int i = 0; i < n; ++i) a[i] = u(rng);
  b << 0.3, 0.3, -0.2, -0.2;  // consistent with the repeated rows
  for (bool symmetric : {true, false}) {
    MatX Ad = A;
    if (!symmetric) Ad(3, 7) += 0.5;
    VecX ld, ls;
    const VecX xd = detail::solveImplicit(Ad, G, a, b, &ld);
    const VecX xs = detail::solveImplicitSparse(Ad.sparseView(), G, a, b, &ls);
    const double ex = relDiff(xs, xd);
    std::printf("[ measured ] %s: x %.1e relative, constraint residual %.1e\n", symmetric ? "symmetric" : "non-symmetric",
                ex, (G * xs - b).cwiseAbs().maxCoeff());
    EXPECT_LE(ex, 5e-15);  // measured 1.9e-16 .. 3.8e-16
    EXPECT_LE((G * xs - b).cwiseAbs().maxCoeff(), 1e-15);
    // the multipliers that act, G^T lambda, agree (lambda itself splits over the repeated rows)
    EXPECT_LE(relDiff(G.transpose() * ls, G.transpose() * ld), 1e-13);
    if (symmetric) {
      EXPECT_LE(relDiff(ls, ld), 1e-13);  // both minimum-norm
    }
  }
  // a singular A is an error, not a NaN
  MatX Z = MatX::Zero(3, 3);
  EXPECT_THROW(detail::solveImplicitSparse(Z.sparseView(), MatX(), VecX::Ones(3), VecX(), nullptr), std::runtime_error);
}

TEST(SparseStep, RouteChoiceAndBadOptions) {
  IntegratorOptions io;
  io.linear_solver = "cholesky";
  EXPECT_THROW(makeIntegrator("bdf1", io), std::invalid_argument);
  const Scene small = makeScene(AttachBy::Jacobian, Insertion::FarNode, 0.5, false);
  io.linear_solver = "auto";
  LinearlyImplicitEuler auto_euler(io);
  EXPECT_FALSE(auto_euler.sparseRoute(small.sys));  // 27 coordinates: dense
  io.linear_solver = "sparse";
  LinearlyImplicitEuler sparse_euler(io);
  EXPECT_TRUE(sparse_euler.sparseRoute(small.sys));
  // a system without extra coordinates takes the sparse route only when asked
  System bare(scenes::revoluteChain(3));
  EXPECT_FALSE(auto_euler.sparseRoute(bare));
  EXPECT_TRUE(sparse_euler.sparseRoute(bare));
}

}  // namespace
}  // namespace redmax
