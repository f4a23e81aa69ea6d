// The Goldfarb-Idnani QP solver (core/dynamics/unilateral/qp_solver.hpp): KKT conditions at the
// solution, agreement with brute-force enumeration of active sets, redundant and degenerate
// constraints, infeasible input, warm starts.
#include "core/dynamics/unilateral/qp_solver.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace redmax {
namespace {

QpProblem randomProblem(std::mt19937& rng, int n, int me, int mi) {
  std::normal_distribution<double> N(0.0, 1.0);
  auto rnd = [&](int r, int c) {
    MatX m(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) m(i, j) = N(rng);
    return m;
  };
  QpProblem p;
  const MatX B = rnd(n, n);
  p.H = B * B.transpose() + 0.1 * MatX::Identity(n, n);
  p.g = rnd(n, 1);
  p.E = rnd(me, n);
  p.e = rnd(me, 1);
  p.C = rnd(mi, n);
  p.d = rnd(mi, 1);  // about half violated at the unconstrained minimum
  return p;
}

// the KKT conditions: stationarity, primal and dual feasibility, complementarity
void expectKkt(const QpProblem& p, const QpResult& r, double tol) {
  const VecX grad = p.H * r.x + p.g;
  VecX rhs = VecX::Zero(p.g.size());
  if (p.E.rows() > 0) rhs += p.E.transpose() * r.lambda_eq;
  if (p.C.rows() > 0) rhs += p.C.transpose() * r.lambda_in;
  EXPECT_LE((grad - rhs).cwiseAbs().maxCoeff(), tol) << "stationarity";
  if (p.E.rows() > 0) EXPECT_LE((p.E * r.x - p.e).cwiseAbs().maxCoeff(), tol) << "equalities";
  for (int k = 0; k < p.C.rows(); ++k) {
    const double s = p.C.row(k).dot(r.x) - p.d[k];
    EXPECT_GE(s, -tol) << "inequality " << k;
    EXPECT_GE(r.lambda_in[k], 0.0) << "multiplier " << k;
    EXPECT_LE(std::abs(s * r.lambda_in[k]), tol) << "complementarity " << k;
  }
}

// the optimum by trying every active set (small problems only): independent of the method
double bruteForceOptimum(const QpProblem& p, VecX* best_x) {
  const int n = static_cast<int>(p.H.rows()), me = static_cast<int>(p.E.rows()), mi = static_cast<int>(p.C.rows());
  double best = std::numeric_limits<double>::infinity();
  for (int mask = 0; mask < (1 << mi); ++mask) {
    std::vector<int> rows;
    for (int k = 0; k < mi; ++k)
      if (mask & (1 << k)) rows.push_back(k);
    const int m = me + static_cast<int>(rows.size());
    if (m > n) continue;
    MatX K = MatX::Zero(n + m, n + m);
    VecX b(n + m);
    K.topLeftCorner(n, n) = p.H;
    b.head(n) = -p.g;
    for (int i = 0; i < m; ++i) {
      const VecX a = i < me ? VecX(p.E.row(i).transpose()) : VecX(p.C.row(rows[i - me]).transpose());
      K.block(n + i, 0, 1, n) = a.transpose();
      K.block(0, n + i, n, 1) = a;
      b[n + i] = i < me ? p.e[i] : p.d[rows[i - me]];
    }
    const VecX sol = K.fullPivLu().solve(b);
    if ((K * sol - b).norm() > 1e-9) continue;
    const VecX x = sol.head(n);
    bool ok = true;
    for (int k = 0; k < mi; ++k) ok = ok && p.C.row(k).dot(x) - p.d[k] >= -1e-9;
    if (!ok) continue;
    const double obj = 0.5 * x.dot(p.H * x) + p.g.dot(x);
    if (obj < best) {
      best = obj;
      *best_x = x;
    }
  }
  return best;
}

TEST(QpSolver, UnconstrainedMinimum) {
  QpProblem p;
  p.H = Eigen::Matrix2d{{2.0, 0.5}, {0.5, 1.0}};
  p.g = Eigen::Vector2d(1.0, -1.0);
  const QpResult r = solveQp(p);
  EXPECT_LE((p.H * r.x + p.g).norm(), 1e-14);
  EXPECT_EQ(r.iterations, 0);
}

TEST(QpSolver, KktAndBruteForceOnRandomProblems) {
  std::mt19937 rng(7);
  int solved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 4, me = trial % 2, mi = 2 + trial % 6;
    const QpProblem p = randomProblem(rng, n, me, mi);
    QpResult r;
    try {
      r = solveQp(p);
    } catch (const QpError&) {
      // random inequalities can be infeasible: then brute force must find nothing either
      VecX x;
      EXPECT_EQ(bruteForceOptimum(p, &x), std::numeric_limits<double>::infinity()) << "trial " << trial;
      continue;
    }
    expectKkt(p, r, 1e-8);
    ++solved;
    VecX xb;
    const double best = bruteForceOptimum(p, &xb);
    EXPECT_NEAR(r.objective, best, 1e-8 * (1.0 + std::abs(best))) << "trial " << trial;
    EXPECT_LE((r.x - xb).norm(), 1e-6) << "trial " << trial;
  }
  EXPECT_GT(solved, 100);  // most random problems are feasible: the comparison is not vacuous
}

TEST(QpSolver, RedundantAndDuplicateConstraints) {
  // x >= 1 three times (one scaled), y >= 0 twice, x + y >= 1 (implied), and a redundant equality
  QpProblem p;
  p.H = MatX::Identity(2, 2);
  p.g = Eigen::Vector2d(0.0, 1.0);
  p.C = MatX{{1, 0}, {1, 0}, {2, 0}, {0, 1}, {0, 1}, {1, 1}};
  p.d = Eigen::VectorXd{{1, 1, 2, 0, 0, 1}};
  p.E = MatX{{1, -1}, {2, -2}};
  p.e = Eigen::Vector2d(1.0, 2.0);  // x - y = 1 twice
  const QpResult r = solveQp(p);
  EXPECT_NEAR(r.x[0], 1.0, 1e-12);
  EXPECT_NEAR(r.x[1], 0.0, 1e-12);
  expectKkt(p, r, 1e-10);
}

TEST(QpSolver, DegenerateVertex) {
  // three constraints through one point in 2-D (the optimum sits on all of them)
  QpProblem p;
  p.H = MatX::Identity(2, 2);
  p.g = Eigen::Vector2d(1.0, 1.0);
  p.C = MatX{{1, 0}, {0, 1}, {1, 1}};
  p.d = Eigen::Vector3d(0.0, 0.0, 0.0);
  const QpResult r = solveQp(p);
  EXPECT_LE(r.x.norm(), 1e-12);
  expectKkt(p, r, 1e-10);
}

TEST(QpSolver, InfeasibleInputIsAClearError) {
  QpProblem p;
  p.H = MatX::Identity(1, 1);
  p.g = VecX::Zero(1);
  p.C = MatX{{1.0}, {-1.0}};
  p.d = Eigen::Vector2d(1.0, 0.0);  // x >= 1 and x <= 0
  try {
    solveQp(p);
    FAIL() << "expected QpError";
  } catch (const QpError& e) {
    EXPECT_NE(std::string(e.what()).find("infeasible"), std::string::npos) << e.what();
  }
  QpProblem q;
  q.H = MatX::Identity(2, 2);
  q.g = VecX::Zero(2);
  q.E = MatX{{1, 1}, {2, 2}};
  q.e = Eigen::Vector2d(1.0, 3.0);  // inconsistent dependent equalities
  EXPECT_THROW(solveQp(q), QpError);
  QpProblem bad;
  bad.H = MatX{{1, 0}, {0, -1}};
  bad.g = VecX::Zero(2);
  EXPECT_THROW(solveQp(bad), QpError);
  bad.H = MatX::Identity(2, 2);
  bad.g = VecX::Zero(3);
  EXPECT_THROW(solveQp(bad), QpError);
  bad.g = Eigen::Vector2d(std::nan(""), 0.0);
  EXPECT_THROW(solveQp(bad), QpError);
}

TEST(QpSolver, WarmStartGivesTheSameSolutionWithNoMoreIterations) {
  std::mt19937 rng(11);
  int fewer = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const QpProblem p = randomProblem(rng, 6, 0, 12);
    QpResult cold;
    try {
      cold = solveQp(p);
    } catch (const QpError&) {
      continue;
    }
    QpOptions o;
    o.warm_active = &cold.active;
    // a nearby problem: the right-hand sides moved a little
    QpProblem q = p;
    q.d.array() += 1e-3;
    const QpResult c2 = solveQp(q);
    const QpResult w2 = solveQp(q, o);
    EXPECT_LE((c2.x - w2.x).norm(), 1e-9);
    EXPECT_LE(w2.iterations, c2.iterations) << "trial " << trial;
    expectKkt(q, w2, 1e-8);
    fewer += w2.iterations < c2.iterations;
  }
  EXPECT_GT(fewer, 0);  // the warm start saves drops somewhere
}

}  // namespace
}  // namespace redmax
