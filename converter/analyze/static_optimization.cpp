#include "converter/analyze/static_optimization.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace redmax::osim {
namespace {

using Ipopt::Index;
using Ipopt::Number;

// d/dx |x|^p
double objectiveSlope(double v, double p) { return p * std::pow(std::abs(v), p - 1.0) * (v < 0.0 ? -1.0 : 1.0); }

// The frame's program for IPOPT; rows of A without any actuator are left out by the caller.
class FrameProgram : public Ipopt::TNLP {
 public:
  FrameProgram(const StaticOptimizationProblem& p, const std::vector<int>& rows, const VecX& x0)
      : p_(p), rows_(rows), x0_(x0) {
    for (int r = 0; r < static_cast<int>(rows_.size()); ++r)
      for (int i = 0; i < p_.A.cols(); ++i)
        if (p_.A(rows_[r], i) != 0.0) nz_.push_back({r, i});
  }
  VecX x, lambda;
  Ipopt::SolverReturn status = Ipopt::INTERNAL_ERROR;

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = static_cast<Index>(p_.A.cols());
    m = static_cast<Index>(rows_.size());
    nnz_jac_g = static_cast<Index>(nz_.size());
    nnz_h_lag = n;  // diagonal objective, linear constraints
    index_style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l, Number* g_u) override {
    for (Index i = 0; i < n; ++i) x_l[i] = p_.lower[i], x_u[i] = p_.upper[i];
    for (Index r = 0; r < m; ++r) g_l[r] = g_u[r] = p_.b[rows_[r]];
    return true;
  }
  bool get_starting_point(Index n, bool init_x, Number* xs, bool init_z, Number*, Number*, Index,
                          bool init_lambda, Number*) override {
    if (!init_x || init_z || init_lambda) return false;
    for (Index i = 0; i < n; ++i) xs[i] = x0_[i];
    return true;
  }
  bool eval_f(Index n, const Number* xs, bool, Number& f) override {
    f = 0.0;
    for (Index i = 0; i < n; ++i) f += std::pow(std::abs(xs[i]), p_.exponent);
    return true;
  }
  bool eval_grad_f(Index n, const Number* xs, bool, Number* g) override {
    for (Index i = 0; i < n; ++i) g[i] = objectiveSlope(xs[i], p_.exponent);
    return true;
  }
  bool eval_g(Index n, const Number* xs, bool, Index m, Number* g) override {
    for (Index r = 0; r < m; ++r) {
      double s = 0.0;
      for (Index i = 0; i < n; ++i) s += p_.A(rows_[r], i) * xs[i];
      g[r] = s;
    }
    return true;
  }
  bool eval_jac_g(Index, const Number*, bool, Index, Index, Index* iRow, Index* jCol,
                  Number* values) override {
    for (size_t k = 0; k < nz_.size(); ++k) {
      if (values) values[k] = p_.A(rows_[nz_[k].first], nz_[k].second);
      else iRow[k] = nz_[k].first, jCol[k] = nz_[k].second;
    }
    return true;
  }
  bool eval_h(Index n, const Number* xs, bool, Number obj_factor, Index, const Number*, bool, Index,
              Index* iRow, Index* jCol, Number* values) override {
    const double e = p_.exponent;
    for (Index i = 0; i < n; ++i) {
      if (values) values[i] = obj_factor * e * (e - 1.0) * std::pow(std::abs(xs[i]), e - 2.0);
      else iRow[i] = jCol[i] = i;
    }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn st, Index n, const Number* xs, const Number*, const Number*,
                         Index m, const Number*, const Number* lam, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    status = st;
    x = Eigen::Map<const VecX>(xs, n);
    lambda = VecX::Zero(p_.b.size());
    for (Index r = 0; r < m; ++r) lambda[rows_[r]] = lam[r];
  }

 private:
  const StaticOptimizationProblem& p_;
  std::vector<int> rows_;
  VecX x0_;
  std::vector<std::pair<int, int>> nz_;
};

const char* statusText(Ipopt::SolverReturn s) {
  switch (s) {
    case Ipopt::SUCCESS: return "solved";
    case Ipopt::STOP_AT_ACCEPTABLE_POINT: return "solved to the acceptable tolerance";
    case Ipopt::MAXITER_EXCEEDED: return "maximum number of iterations reached";
    case Ipopt::LOCAL_INFEASIBILITY: return "infeasible (the controls' bounds cannot supply the forces)";
    case Ipopt::RESTORATION_FAILURE: return "restoration failed (probably infeasible)";
    case Ipopt::STOP_AT_TINY_STEP: return "stopped at a tiny step";
    case Ipopt::DIVERGING_ITERATES: return "diverging iterates";
    case Ipopt::ERROR_IN_STEP_COMPUTATION: return "error in step computation";
    case Ipopt::INVALID_NUMBER_DETECTED: return "invalid number detected";
    default: return "solver failure";
  }
}

void checkProblem(const StaticOptimizationProblem& p) {
  const auto n = p.A.cols();
  if (p.b.size() != p.A.rows() || p.lower.size() != n || p.upper.size() != n ||
      (p.x0.size() != 0 && p.x0.size() != n))
    throw std::invalid_argument("static optimization: A, b, bounds and start have inconsistent sizes");
  if (!(p.exponent > 1.0) || !std::isfinite(p.exponent))
    throw std::invalid_argument("static optimization: the activation exponent must be > 1");
  if (!p.A.allFinite() || !p.b.allFinite())
    throw std::invalid_argument("static optimization: non-finite entries in the forces to supply or per control");
  for (Eigen::Index i = 0; i < n; ++i)
    if (!(p.lower[i] <= p.upper[i]))
      throw std::invalid_argument("static optimization: control " + std::to_string(i) + " has lower bound " +
                                  std::to_string(p.lower[i]) + " above its upper bound " + std::to_string(p.upper[i]));
}

}  // namespace

StaticOptimizationResult solveStaticOptimization(const StaticOptimizationProblem& p,
                                                 const StaticOptimizationOptions& opt) {
  checkProblem(p);
  const int n = static_cast<int>(p.A.cols());
  StaticOptimizationResult res;
  // rows no actuator acts on: 0 = b_j is either met already or impossible
  std::vector<int> rows;
  const double scale = std::max(1.0, p.b.lpNorm<Eigen::Infinity>());
  for (int r = 0; r < p.A.rows(); ++r) {
    if (p.A.row(r).cwiseAbs().maxCoeff() > 0.0) {
      rows.push_back(r);
    } else if (std::abs(p.b[r]) > 1e-12 * scale) {
      res.x = p.x0.size() ? p.x0 : VecX(0.5 * (p.lower + p.upper));
      res.lambda = VecX::Zero(p.b.size());
      res.constraint_violation = std::abs(p.b[r]);
      res.status = "infeasible: no actuator acts on generalized coordinate " + std::to_string(r);
      return res;
    }
  }
  VecX x0 = p.x0.size() ? p.x0 : VecX(0.5 * (p.lower + p.upper));
  x0 = x0.cwiseMax(p.lower).cwiseMin(p.upper);

  Ipopt::SmartPtr<FrameProgram> program = new FrameProgram(p, rows, x0);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", 0);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", opt.convergence_tolerance);
  // the equalities to the tolerance in the forces' own units, and bounds exactly as given
  app->Options()->SetNumericValue("constr_viol_tol", opt.convergence_tolerance * scale);
  app->Options()->SetNumericValue("bound_relax_factor", 0.0);
  app->Options()->SetIntegerValue("max_iter", opt.max_iterations);
  app->Options()->SetStringValue("jac_c_constant", "yes");
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  if (p.exponent == 2.0) app->Options()->SetStringValue("hessian_constant", "yes");
  if (app->Initialize() != Ipopt::Solve_Succeeded) throw std::runtime_error("static optimization: IPOPT did not start");
  const Ipopt::ApplicationReturnStatus st = app->OptimizeTNLP(program);
  if (Ipopt::IsValid(app->Statistics())) res.iterations = app->Statistics()->IterationCount();
  res.x = program->x.size() == n ? program->x : x0;
  res.lambda = program->lambda.size() ? program->lambda : VecX::Zero(p.b.size());
  res.constraint_violation = (p.A * res.x - p.b).lpNorm<Eigen::Infinity>();
  res.converged = st == Ipopt::Solve_Succeeded || st == Ipopt::Solved_To_Acceptable_Level;
  res.status = statusText(program->status);
  return res;
}

OptimalityReport checkOptimality(const StaticOptimizationProblem& p, const VecX& x, double active_tol) {
  checkProblem(p);
  const int n = static_cast<int>(p.A.cols());
  OptimalityReport rep;
  VecX grad(n);
  for (int i = 0; i < n; ++i) grad[i] = objectiveSlope(x[i], p.exponent);
  std::vector<int> inner, low, up;
  for (int i = 0; i < n; ++i) {
    const double w = std::max(1.0, std::abs(p.upper[i] - p.lower[i]));
    if (x[i] - p.lower[i] <= active_tol * w) low.push_back(i);
    else if (p.upper[i] - x[i] <= active_tol * w) up.push_back(i);
    else inner.push_back(i);
    rep.bound_violation = std::max({rep.bound_violation, p.lower[i] - x[i], x[i] - p.upper[i]});
  }
  rep.at_bounds = static_cast<int>(low.size() + up.size());
  rep.equality = (p.A * x - p.b).lpNorm<Eigen::Infinity>();
  // grad + A^T lambda = 0 on the inner controls (least squares for lambda)
  VecX lambda = VecX::Zero(p.A.rows());
  if (!inner.empty()) {
    MatX At(inner.size(), p.A.rows());
    VecX g(inner.size());
    for (size_t k = 0; k < inner.size(); ++k) At.row(k) = p.A.col(inner[k]).transpose(), g[k] = grad[inner[k]];
    lambda = At.completeOrthogonalDecomposition().solve(-g);
    rep.stationarity = (At * lambda + g).lpNorm<Eigen::Infinity>();
  }
  // a control at its lower bound needs grad + A^T lambda >= 0 there, at its upper bound <= 0
  const VecX r = grad + p.A.transpose() * lambda;
  for (int i : low) rep.bound_sign = std::max(rep.bound_sign, -r[i]);
  for (int i : up) rep.bound_sign = std::max(rep.bound_sign, r[i]);
  return rep;
}

}  // namespace redmax::osim
