#include "core/dynamics/unilateral/qp_solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace redmax {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// J = L^-T Q and upper-triangular R with J^T N = [R; 0] for the active normals N (columns in
// active order): the Goldfarb-Idnani factors, updated by Givens rotations.
struct Factors {
  int n = 0, iq = 0;
  MatX J, R;
  double r_norm = 1.0;

  // rotate columns a, b of J by (c, s)
  void rotateJ(int a, int b, double c, double s) {
    for (int k = 0; k < n; ++k) {
      const double t1 = J(k, a), t2 = J(k, b);
      J(k, a) = c * t1 + s * t2;
      J(k, b) = -s * t1 + c * t2;
    }
  }
  // append the normal whose d = J^T np is given; false if it depends on the active ones
  bool add(VecX d) {
    if (iq >= n) return false;
    for (int j = n - 1; j >= iq + 1; --j) {
      const double h = std::hypot(d[j - 1], d[j]);
      if (h == 0.0) continue;
      const double c = d[j - 1] / h, s = d[j] / h;
      d[j - 1] = h;
      d[j] = 0.0;
      rotateJ(j - 1, j, c, s);
    }
    if (std::abs(d[iq]) <= 1e-13 * r_norm) return false;
    R.col(iq).head(iq + 1) = d.head(iq + 1);
    r_norm = std::max(r_norm, std::abs(d[iq]));
    ++iq;
    return true;
  }
  // remove the active normal at position l and re-triangularise R
  void drop(int l) {
    for (int j = l; j < iq - 1; ++j) R.col(j).head(iq) = R.col(j + 1).head(iq);
    R.col(iq - 1).setZero();
    --iq;
    for (int j = l; j < iq; ++j) {
      const double h = std::hypot(R(j, j), R(j + 1, j));
      if (h == 0.0) continue;
      const double c = R(j, j) / h, s = R(j + 1, j) / h;
      for (int k = j; k < iq; ++k) {
        const double t1 = R(j, k), t2 = R(j + 1, k);
        R(j, k) = c * t1 + s * t2;
        R(j + 1, k) = -s * t1 + c * t2;
      }
      R(j + 1, j) = 0.0;
      rotateJ(j, j + 1, c, s);
    }
  }
  // the primal step direction z and the multipliers' rate r for the normal np
  void directions(const VecX& np, VecX& d, VecX& z, VecX& r) const {
    d.noalias() = J.transpose() * np;
    z.noalias() = J.rightCols(n - iq) * d.tail(n - iq);
    r = R.topLeftCorner(iq, iq).triangularView<Eigen::Upper>().solve(d.head(iq));
  }
};

bool allFinite(const MatX& m) { return m.allFinite(); }

}  // namespace

QpResult solveQp(const QpProblem& p, const QpOptions& opt) {
  const int n = static_cast<int>(p.H.rows());
  const int me = static_cast<int>(p.E.rows()), mi = static_cast<int>(p.C.rows());
  if (n == 0 || p.H.cols() != n || p.g.size() != n || (me > 0 && p.E.cols() != n) || p.e.size() != me ||
      (mi > 0 && p.C.cols() != n) || p.d.size() != mi)
    throw QpError("QP: sizes do not match (H " + std::to_string(p.H.rows()) + "x" + std::to_string(p.H.cols()) +
                  ", g " + std::to_string(p.g.size()) + ", E " + std::to_string(me) + " rows, e " +
                  std::to_string(p.e.size()) + ", C " + std::to_string(mi) + " rows, d " +
                  std::to_string(p.d.size()) + ")");
  if (!allFinite(p.H) || !p.g.allFinite() || !allFinite(p.E) || !p.e.allFinite() || !allFinite(p.C) ||
      !p.d.allFinite())
    throw QpError("QP: non-finite entries");
  Eigen::LLT<MatX> llt(p.H);
  if (llt.info() != Eigen::Success) throw QpError("QP: H is not positive definite");

  Factors f;
  f.n = n;
  f.J = llt.matrixL().solve(MatX::Identity(n, n)).transpose();
  f.R = MatX::Zero(n, n);
  const int max_iter = opt.max_iterations > 0 ? opt.max_iterations : 10 * (n + me + mi) + 10;

  QpResult res;
  VecX x = -llt.solve(p.g);
  std::vector<int> act;  // active constraints: equality k as -1 - k, inequality k as k
  std::vector<double> u;  // their multipliers
  VecX d(n), z(n), r;

  // equalities: full steps, never dropped
  for (int k = 0; k < me; ++k) {
    const VecX np = p.E.row(k).transpose();
    f.directions(np, d, z, r);
    const double s = np.dot(x) - p.e[k];
    if (d.tail(n - f.iq).norm() <= 1e-12 * std::max(1.0, d.norm())) {
      if (std::abs(s) <= opt.tolerance * (1.0 + std::abs(p.e[k]))) continue;  // redundant, consistent
      throw QpError("QP infeasible: equality row " + std::to_string(k) +
                    " depends on the earlier ones and contradicts them (residual " + std::to_string(s) + ")");
    }
    const double t = -s / z.dot(np);
    x += t * z;
    for (int j = 0; j < f.iq; ++j) u[j] -= t * r[j];
    if (!f.add(d)) throw QpError("QP: equality row " + std::to_string(k) + " could not be added (dependent)");
    act.push_back(-1 - k);
    u.push_back(t);
    ++res.iterations;
  }

  std::vector<char> is_active(mi, 0);
  std::vector<char> warm(mi, 0);
  if (opt.warm_active)
    for (int k : *opt.warm_active)
      if (k >= 0 && k < mi) warm[k] = 1;
  auto slack = [&](int k) { return p.C.row(k).dot(x) - p.d[k]; };
  auto violated = [&](int k, double s) { return s < -opt.tolerance * (1.0 + std::abs(p.d[k])); };

  for (;;) {
    // the constraint to add: the most violated, previously active ones first
    int pick = -1;
    double worst = 0.0;
    for (int pass = 0; pass < 2 && pick < 0; ++pass)
      for (int k = 0; k < mi; ++k) {
        if (is_active[k] || (pass == 0 && !warm[k])) continue;
        const double s = slack(k);
        if (violated(k, s) && s < worst) {
          worst = s;
          pick = k;
        }
      }
    if (pick < 0) break;
    const VecX np = p.C.row(pick).transpose();
    double u_new = 0.0;
    for (;;) {
      if (++res.iterations > max_iter)
        throw QpError("QP: no convergence in " + std::to_string(max_iter) + " active-set changes");
      f.directions(np, d, z, r);
      // partial step: the first active inequality whose multiplier reaches zero
      double t1 = kInf;
      int l = -1;
      for (int j = 0; j < f.iq; ++j)
        if (act[j] >= 0 && r[j] > 0.0 && u[j] / r[j] < t1) {
          t1 = u[j] / r[j];
          l = j;
        }
      // full step: the picked constraint becomes satisfied
      const bool free_dir = d.tail(n - f.iq).norm() > 1e-12 * std::max(1.0, d.norm());
      const double t2 = free_dir ? -slack(pick) / z.dot(np) : kInf;
      const double t = std::min(t1, t2);
      if (t == kInf)
        throw QpError("QP infeasible: inequality row " + std::to_string(pick) +
                      " cannot hold together with the active constraints");
      if (free_dir) x += t * z;
      for (int j = 0; j < f.iq; ++j) u[j] -= t * r[j];
      u_new += t;
      if (free_dir && t2 <= t1) {
        if (!f.add(d)) throw QpError("QP: inequality row " + std::to_string(pick) + " could not be added");
        act.push_back(pick);
        u.push_back(u_new);
        is_active[pick] = 1;
        break;
      }
      // drop constraint l (its multiplier is zero now) and try the picked one again
      is_active[act[l]] = 0;
      f.drop(l);
      act.erase(act.begin() + l);
      u.erase(u.begin() + l);
    }
  }

  res.x = x;
  res.lambda_eq = VecX::Zero(me);
  res.lambda_in = VecX::Zero(mi);
  for (size_t j = 0; j < act.size(); ++j) {
    if (act[j] < 0) res.lambda_eq[-1 - act[j]] = u[j];
    else {
      res.lambda_in[act[j]] = std::max(0.0, u[j]);
      res.active.push_back(act[j]);
    }
  }
  res.objective = 0.5 * x.dot(p.H * x) + p.g.dot(x);
  return res;
}

}  // namespace redmax
