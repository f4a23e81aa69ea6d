#include "converter/signal/natural_spline.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace redmax::signal {
namespace {

// falling factorial k!/(k-d)!: the factor d^d/du^d puts on u^k
double fallingFactorial(int k, int d) {
  double f = 1.0;
  for (int i = 0; i < d; ++i) f *= k - i;
  return f;
}

// Hermite data of one interval in the normalized variable u = (t - x_l)/h on [0, 1]:
// p(u) = sum_k c_k u^k (degree 2m-1) is fixed by a_j = p^(j)(0) and b_j = p^(j)(1), j < m.
struct HermiteBasis {
  int m = 0;
  Eigen::MatrixXd C;   // (2m x 2m): c = C [a; b]
  Eigen::MatrixXd D0;  // (m-1 x 2m): row j-m gives p^(j)(0) for j = m..2m-2
  Eigen::MatrixXd D1;  // (m-1 x 2m): row j-m gives p^(j)(1)

  explicit HermiteBasis(int m_in) : m(m_in) {
    const int nc = 2 * m;
    // the first m coefficients follow from the left end alone: c_k = a_k / k!
    C = Eigen::MatrixXd::Zero(nc, nc);
    for (int k = 0; k < m; ++k) C(k, k) = 1.0 / fallingFactorial(k, k);
    // the upper m coefficients solve p^(j)(1) = b_j, i.e. B c_hi = b - E c_lo
    Eigen::MatrixXd B(m, m), E = Eigen::MatrixXd::Zero(m, m);
    for (int j = 0; j < m; ++j) {
      for (int k = m; k < nc; ++k) B(j, k - m) = fallingFactorial(k, j);
      for (int k = j; k < m; ++k) E(j, k) = fallingFactorial(k, j);
    }
    const Eigen::MatrixXd Binv = B.fullPivLu().inverse();
    C.block(m, 0, m, m) = -Binv * E * C.topLeftCorner(m, m);
    C.block(m, m, m, m) = Binv;
    // derivative rows at both ends, for the orders that continuity/natural ends constrain
    D0 = Eigen::MatrixXd::Zero(std::max(m - 1, 0), nc);
    D1 = Eigen::MatrixXd::Zero(std::max(m - 1, 0), nc);
    for (int j = m; j <= 2 * m - 2; ++j) {
      D0.row(j - m) = fallingFactorial(j, j) * C.row(j);
      for (int k = j; k < nc; ++k) D1.row(j - m) += fallingFactorial(k, j) * C.row(k);
    }
  }
};

// Square banded matrix with kl sub- and ku super-diagonals, stored by rows with room for the
// kl extra super-diagonals that partial pivoting fills in (as LAPACK's dgbtrf does).
class BandMatrix {
 public:
  BandMatrix(int n, int kl, int ku)
      : n_(n), kl_(kl), ku_(ku), w_(2 * kl + ku + 1), a_(static_cast<size_t>(n) * w_, 0.0), piv_(n) {}
  // requires r - kl <= c <= r + kl + ku
  double& at(int r, int c) { return a_[static_cast<size_t>(r) * w_ + (c - r + kl_)]; }
  double at(int r, int c) const { return a_[static_cast<size_t>(r) * w_ + (c - r + kl_)]; }

  // A x, summed in long double (for the refinement residual); before factorize() only
  void multiply(const std::vector<double>& x, std::vector<long double>& y) const {
    for (int r = 0; r < n_; ++r) {
      long double s = 0;
      for (int c = std::max(r - kl_, 0); c <= std::min(r + ku_, n_ - 1); ++c) s += static_cast<long double>(at(r, c)) * x[c];
      y[r] = s;
    }
  }

  // in-place LU by Gaussian elimination with partial pivoting; multipliers kept below the diagonal
  void factorize() {
    for (int k = 0; k < n_; ++k) {
      const int last_row = std::min(k + kl_, n_ - 1);
      const int last_col = std::min(k + kl_ + ku_, n_ - 1);
      int p = k;
      for (int r = k + 1; r <= last_row; ++r)
        if (std::abs(at(r, k)) > std::abs(at(p, k))) p = r;
      if (!(std::abs(at(p, k)) > 0.0)) throw SignalError("natural spline: singular system (knots too close?)");
      piv_[k] = p;
      if (p != k)
        for (int c = k; c <= last_col; ++c) std::swap(at(k, c), at(p, c));
      for (int r = k + 1; r <= last_row; ++r) {
        const double f = at(r, k) / at(k, k);
        at(r, k) = f;
        if (f == 0.0) continue;
        for (int c = k + 1; c <= last_col; ++c) at(r, c) -= f * at(k, c);
      }
    }
  }

  // solve with the factors, in place
  void solve(std::vector<double>& b) const {
    for (int k = 0; k < n_; ++k) {
      if (piv_[k] != k) std::swap(b[k], b[piv_[k]]);
      const int last_row = std::min(k + kl_, n_ - 1);
      for (int r = k + 1; r <= last_row; ++r) b[r] -= at(r, k) * b[k];
    }
    for (int k = n_ - 1; k >= 0; --k) {
      double s = b[k];
      const int last_col = std::min(k + kl_ + ku_, n_ - 1);
      for (int c = k + 1; c <= last_col; ++c) s -= at(k, c) * b[c];
      b[k] = s / at(k, k);
    }
  }

 private:
  int n_, kl_, ku_, w_;
  std::vector<double> a_;
  std::vector<int> piv_;
};

}  // namespace

NaturalSpline::NaturalSpline(int degree, std::span<const double> x, std::span<const double> y) {
  // input checks, with the messages GCVSPL's callers would want
  if (degree != 1 && degree != 3 && degree != 5 && degree != 7) {
    std::ostringstream os;
    os << "natural spline: degree must be 1, 3, 5 or 7 (got " << degree << ")";
    throw SignalError(os.str());
  }
  const int m = (degree + 1) / 2;
  const int n = static_cast<int>(x.size());
  if (x.size() != y.size()) {
    std::ostringstream os;
    os << "natural spline: " << x.size() << " abscissae but " << y.size() << " values";
    throw SignalError(os.str());
  }
  if (n < 2 * m) {
    std::ostringstream os;
    os << "natural spline of degree " << degree << ": needs at least " << 2 * m << " points (got " << n << ")";
    throw SignalError(os.str());
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
      std::ostringstream os;
      os << "natural spline: non-finite data at point " << i << " (x = " << x[i] << ", y = " << y[i] << ")";
      throw SignalError(os.str());
    }
    if (i > 0 && !(x[i] > x[i - 1])) {
      std::ostringstream os;
      os.precision(17);
      os << "natural spline: abscissae must be strictly increasing (x[" << i - 1 << "] = " << x[i - 1] << ", x["
         << i << "] = " << x[i] << ")";
      throw SignalError(os.str());
    }
  }

  m_ = m;
  x_.assign(x.begin(), x.end());
  y_.assign(y.begin(), y.end());
  h_.resize(n - 1);
  for (int i = 0; i + 1 < n; ++i) h_[i] = x_[i + 1] - x_[i];
  const HermiteBasis basis(m);
  const int nu = m - 1;  // unknown derivatives 1..m-1 per knot

  // local length scale per knot: unknowns z_{i,k} = g_i^k s^(k)(x_i) and equations scaled by g_i^j
  // keep the system O(1) when the spacing is smooth
  std::vector<double> g(n);
  for (int i = 0; i < n; ++i) {
    if (i == 0) g[i] = h_[0];
    else if (i == n - 1) g[i] = h_[n - 2];
    else g[i] = 0.5 * (h_[i - 1] + h_[i]);
  }

  // assemble: at each knot, continuity of s^(j) for j = m..2m-2 (interior knots) or s^(j) = 0
  // (natural ends); the same loop gives both because an end knot has only one neighbour interval
  const int N = n * nu;
  const int band = std::max(2 * m - 3, 0);
  BandMatrix A(N, band, band);
  std::vector<double> rhs(N, 0.0);
  for (int i = 0; i < n; ++i) {
    for (int j = m; j <= 2 * m - 2; ++j) {
      const int r = i * nu + (j - m);
      // add w . v_l for interval l, where v_l = [a; b] in u-units
      auto add_interval = [&](int l, const Eigen::RowVectorXd& w) {
        // a derivative of order >= 1 ignores the level, so w[0] = -w[m]: use the difference of
        // the values, not the values (a column at 5.04 varying in its 8th digit loses nothing)
        rhs[r] -= w[m] * (y_[l + 1] - y_[l]);
        for (int k = 1; k < m; ++k) {
          A.at(r, l * nu + k - 1) += w[k] * std::pow(h_[l] / g[l], k);
          A.at(r, (l + 1) * nu + k - 1) += w[m + k] * std::pow(h_[l] / g[l + 1], k);
        }
      };
      if (i >= 1) add_interval(i - 1, std::pow(g[i] / h_[i - 1], j) * basis.D1.row(j - m));
      if (i <= n - 2) add_interval(i, -std::pow(g[i] / h_[i], j) * basis.D0.row(j - m));
    }
  }
  // solve, then one step of iterative refinement with the residual summed in long double: it
  // recovers the digits the elimination loses for the higher degrees (septic mostly)
  const BandMatrix A0 = A;
  const std::vector<double> b0 = rhs;
  A.factorize();
  A.solve(rhs);
  if (N > 0) {
    std::vector<long double> Ax(N);
    A0.multiply(rhs, Ax);
    std::vector<double> r(N);
    for (int i = 0; i < N; ++i) r[i] = static_cast<double>(static_cast<long double>(b0[i]) - Ax[i]);
    A.solve(r);
    for (int i = 0; i < N; ++i) rhs[i] += r[i];
  }

  // knot derivatives s^(k)(x_i) = z_{i,k} / g_i^k
  auto knot_derivative = [&](int i, int k) { return k == 0 ? y_[i] : rhs[i * nu + k - 1] / std::pow(g[i], k); };

  // per-interval monomial coefficients c = C [a; b], a_k = h^k s^(k)(x_l), b_k = h^k s^(k)(x_{l+1});
  // the level y_l is taken out first (C maps a constant to itself), so c_1.. carry no cancellation
  const int nc = 2 * m;
  coef_.resize(static_cast<size_t>(n - 1) * nc);
  Eigen::VectorXd v(nc);
  for (int l = 0; l + 1 < n; ++l) {
    for (int k = 0; k < m; ++k) {
      v[k] = k == 0 ? 0.0 : rhs[l * nu + k - 1] * std::pow(h_[l] / g[l], k);
      v[m + k] = k == 0 ? y_[l + 1] - y_[l] : rhs[(l + 1) * nu + k - 1] * std::pow(h_[l] / g[l + 1], k);
    }
    Eigen::VectorXd c = basis.C * v;
    c[0] = y_[l];
    std::copy(c.data(), c.data() + nc, coef_.begin() + static_cast<ptrdiff_t>(l) * nc);
  }

  // end derivatives 0..m-1 continue the spline outside the data as a degree m-1 polynomial
  d_lo_.resize(m);
  d_hi_.resize(m);
  for (int k = 0; k < m; ++k) {
    d_lo_[k] = knot_derivative(0, k);
    d_hi_[k] = knot_derivative(n - 1, k);
  }
}

double NaturalSpline::calcValue(double t) const { return calcDerivative(0, t); }

double NaturalSpline::calcDerivative(int order, double t) const {
  if (x_.empty()) throw SignalError("natural spline: evaluated before it was fitted");
  if (order < 0) throw SignalError("natural spline: negative derivative order");
  if (order > degree()) return 0.0;
  double out[8];
  calcDerivatives(t, std::span<double>(out, order + 1));
  return out[order];
}

void NaturalSpline::calcDerivatives(double t, std::span<double> out) const {
  if (x_.empty()) throw SignalError("natural spline: evaluated before it was fitted");
  const int n = size();
  const int nc = 2 * m_;
  const int max_order = static_cast<int>(out.size()) - 1;

  // outside the data: Taylor polynomial of degree m-1 at the end knot
  if (t < x_.front() || t > x_.back()) {
    const bool lo = t < x_.front();
    const std::vector<double>& d = lo ? d_lo_ : d_hi_;
    const double tau = t - (lo ? x_.front() : x_.back());
    for (int order = 0; order <= max_order; ++order) {
      double s = 0.0;
      // Horner in tau over sum_{j>=order} d_j tau^(j-order)/(j-order)!
      for (int j = m_ - 1; j >= order; --j) s = s * tau / (j - order + 1) + d[j];
      out[order] = order < m_ ? s : 0.0;
    }
    return;
  }

  // inside: interval l with x_l <= t < x_{l+1} (the last one includes x_n)
  int l = static_cast<int>(std::upper_bound(x_.begin(), x_.end(), t) - x_.begin()) - 1;
  l = std::clamp(l, 0, n - 2);
  const double h = h_[l];
  const double u = (t - x_[l]) / h;
  const double* c = coef_.data() + static_cast<ptrdiff_t>(l) * nc;
  double hpow = 1.0;
  for (int order = 0; order <= max_order; ++order) {
    double s = 0.0;
    for (int k = nc - 1; k >= order; --k) s = s * u + c[k] * fallingFactorial(k, order);
    out[order] = order < nc ? s / hpow : 0.0;
    hpow *= h;
  }
}

}  // namespace redmax::signal
