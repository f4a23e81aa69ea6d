// Static optimization's per-frame program against closed-form optima, and its optimality checked
// independently of IPOPT (converter/analyze/static_optimization.hpp):
//   - one joint, two identical muscles: equal shares a = tau / (2 F r);
//   - one muscle and a reserve actuator, exponent 2: a_i = tau c_i / sum c_j^2;
//   - the same with exponent 3: 3 a_i^2 = -lambda c_i, so a_i = tau sqrt(c_i) / sum c_j^1.5;
//   - an upper bound that binds: the other control takes the rest;
//   - bounds that cannot supply the moment: not converged, named, never a result;
//   - bad input (sizes, lower > upper, exponent <= 1): std::invalid_argument.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "converter/analyze/static_optimization.hpp"

namespace redmax::osim {
namespace {

StaticOptimizationProblem oneJoint(const std::vector<double>& c, double tau, double lo = 0.0, double hi = 1.0) {
  StaticOptimizationProblem p;
  p.A = MatX(1, c.size());
  for (size_t i = 0; i < c.size(); ++i) p.A(0, i) = c[i];
  p.b = VecX::Constant(1, tau);
  p.lower = VecX::Constant(c.size(), lo);
  p.upper = VecX::Constant(c.size(), hi);
  return p;
}

TEST(StaticOptimization, TwoIdenticalMusclesShareEqually) {
  const double F = 800.0, r = 0.03, tau = 10.0;
  const auto p = oneJoint({F * r, F * r}, tau);
  const auto res = solveStaticOptimization(p);
  ASSERT_TRUE(res.converged) << res.status;
  EXPECT_NEAR(res.x[0], tau / (2 * F * r), 1e-9);
  EXPECT_NEAR(res.x[1], tau / (2 * F * r), 1e-9);
  EXPECT_LE(res.constraint_violation, 1e-9 * tau);
  EXPECT_GT(res.iterations, 0);
}

TEST(StaticOptimization, MuscleAndReserveExponentTwoAndThreeMatchTheirClosedForms) {
  const double cm = 1000.0 * 0.04, cr = 10.0, tau = 20.0;
  auto p = oneJoint({cm, cr}, tau, -1.0, 1.0);
  auto res = solveStaticOptimization(p);
  ASSERT_TRUE(res.converged) << res.status;
  const double s2 = cm * cm + cr * cr;
  EXPECT_NEAR(res.x[0], tau * cm / s2, 1e-10);
  EXPECT_NEAR(res.x[1], tau * cr / s2, 1e-10);
  p.exponent = 3.0;
  res = solveStaticOptimization(p);
  ASSERT_TRUE(res.converged) << res.status;
  const double s3 = std::pow(cm, 1.5) + std::pow(cr, 1.5);
  EXPECT_NEAR(res.x[0], tau * std::sqrt(cm) / s3, 1e-9);
  EXPECT_NEAR(res.x[1], tau * std::sqrt(cr) / s3, 1e-9);
  // the exponent changes the answer: 3 puts more on the weaker actuator than 2
  EXPECT_GT(res.x[1], tau * cr / s2 * 1.5);
}

TEST(StaticOptimization, BindingUpperBoundLeavesTheRestToTheOther) {
  // unbounded optimum would be (0.6, 0.3); the first is capped at 0.5
  const auto p = oneJoint({100.0, 50.0}, 75.0, 0.0, 0.5);
  auto q = p;
  q.upper[1] = 1.0;
  const auto res = solveStaticOptimization(q);
  ASSERT_TRUE(res.converged) << res.status;
  EXPECT_NEAR(res.x[0], 0.5, 1e-7);
  EXPECT_NEAR(res.x[1], (75.0 - 50.0) / 50.0, 1e-7);
  const auto rep = checkOptimality(q, res.x, 1e-6);
  EXPECT_EQ(rep.at_bounds, 1);
  EXPECT_LE(rep.bound_sign, 1e-9);
  EXPECT_LE(rep.equality, 1e-8);
}

TEST(StaticOptimization, RandomFramesSatisfyTheKktConditions) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  double worst_stat = 0, worst_eq = 0, worst_sign = 0;
  int iterations = 0;
  for (int trial = 0; trial < 20; ++trial) {
    StaticOptimizationProblem p;
    const int ndof = 3, n = 9;
    p.A = MatX(ndof, n);
    for (int j = 0; j < ndof; ++j)
      for (int i = 0; i < n; ++i) p.A(j, i) = 40.0 * U(rng);
    VecX a(n);
    for (int i = 0; i < n; ++i) a[i] = 0.3 + 0.2 * U(rng);
    p.b = p.A * a;  // feasible: a is inside [0.01, 1]
    p.lower = VecX::Constant(n, 0.01);
    p.upper = VecX::Constant(n, 1.0);
    p.exponent = trial % 2 ? 3.0 : 2.0;
    const auto res = solveStaticOptimization(p);
    ASSERT_TRUE(res.converged) << res.status;
    const auto rep = checkOptimality(p, res.x, 1e-6);
    worst_stat = std::max(worst_stat, rep.stationarity);
    worst_sign = std::max(worst_sign, rep.bound_sign);
    worst_eq = std::max(worst_eq, rep.equality / p.b.lpNorm<Eigen::Infinity>());
    iterations += res.iterations;
    EXPECT_LE(rep.stationarity, 2e-8) << "trial " << trial;  // measured 2.4e-9
    EXPECT_LE(rep.bound_sign, 1e-7) << "trial " << trial;
    EXPECT_LE(rep.equality, 1e-12 * p.b.lpNorm<Eigen::Infinity>()) << "trial " << trial;
    EXPECT_LE(rep.bound_violation, 1e-12) << "trial " << trial;
    // no better feasible point nearby: moving along the constraints' null space raises the objective
    const MatX N = Eigen::FullPivLU<MatX>(p.A).kernel();
    auto f = [&](const VecX& x) { return x.array().abs().pow(p.exponent).sum(); };
    for (int k = 0; k < N.cols(); ++k)
      for (double s : {-1e-3, 1e-3}) {
        const VecX y = res.x + s * N.col(k);
        if ((y.array() < p.lower.array()).any() || (y.array() > p.upper.array()).any()) continue;
        EXPECT_GE(f(y), f(res.x) - 1e-12) << "trial " << trial;
      }
  }
  std::printf("[ measured ] 20 random frames (3 DoF, 9 controls): stationarity %.2e, bound sign %.2e, "
              "equality %.2e of |b|, %.1f IPOPT iterations per frame\n",
              worst_stat, worst_sign, worst_eq, iterations / 20.0);
}

TEST(StaticOptimization, BoundsThatCannotSupplyTheMomentAreAFailureNotAResult) {
  const auto p = oneJoint({10.0, 10.0}, 100.0);  // at most 20 N m
  const auto res = solveStaticOptimization(p);
  EXPECT_FALSE(res.converged);
  EXPECT_FALSE(res.status.empty());
  EXPECT_GT(res.constraint_violation, 1.0);
  auto q = oneJoint({10.0}, 1.0);
  q.A = MatX::Zero(2, 1);
  q.A(0, 0) = 10.0;
  q.b = VecX::Constant(2, 1.0);  // nothing acts on the second coordinate
  const auto r2 = solveStaticOptimization(q);
  EXPECT_FALSE(r2.converged);
  EXPECT_NE(r2.status.find("coordinate 1"), std::string::npos) << r2.status;
}

TEST(StaticOptimization, BadInputIsAnError) {
  auto p = oneJoint({1.0, 2.0}, 1.0);
  p.lower[1] = 2.0;
  EXPECT_THROW(solveStaticOptimization(p), std::invalid_argument);
  p = oneJoint({1.0, 2.0}, 1.0);
  p.exponent = 1.0;
  EXPECT_THROW(solveStaticOptimization(p), std::invalid_argument);
  p = oneJoint({1.0, 2.0}, 1.0);
  p.b = VecX::Zero(2);
  EXPECT_THROW(solveStaticOptimization(p), std::invalid_argument);
  p = oneJoint({1.0, 2.0}, std::nan(""));
  EXPECT_THROW(solveStaticOptimization(p), std::invalid_argument);
}

}  // namespace
}  // namespace redmax::osim
