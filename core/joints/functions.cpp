#include "core/joints/functions.hpp"

#include <algorithm>
#include <cmath>

namespace redmax {

namespace {

void checkData(const char* type, const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size())
    throw JointError(std::string(type) + ": " + std::to_string(x.size()) + " x values but " +
                     std::to_string(y.size()) + " y values");
  if (x.size() < 2)
    throw JointError(std::string(type) + ": needs at least 2 points, got " + std::to_string(x.size()));
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]))
      throw JointError(std::string(type) + ": point " + std::to_string(i) + " is not finite");
}

// index k of the interval [x_k, x_{k+1}] holding t, for x_0 <= t <= x_{n-1}
int findInterval(const std::vector<double>& x, double t) {
  const int n = static_cast<int>(x.size());
  const int k = static_cast<int>(std::upper_bound(x.begin(), x.end(), t) - x.begin()) - 1;
  return std::clamp(k, 0, n - 2);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
double AxisFunction::value(const VecJ& x) const {
  FunctionValue v;
  evaluate(x, 0, v);
  return v.value;
}

VecJ AxisFunction::gradient(const VecJ& x) const {
  FunctionValue v;
  evaluate(x, 1, v);
  return v.gradient;
}

MatJ AxisFunction::hessian(const VecJ& x) const {
  FunctionValue v;
  evaluate(x, 2, v);
  return v.hessian;
}

void UnivariateFunction::evaluate(const VecJ& x, int order, FunctionValue& out) const {
  double f, df, ddf;
  evaluate1(x[0], f, df, ddf);
  out.value = f;
  if (order >= 1) out.gradient.setConstant(1, df);
  if (order >= 2) out.hessian.setConstant(1, 1, ddf);
}

double UnivariateFunction::value1(double x) const {
  double f, df, ddf;
  evaluate1(x, f, df, ddf);
  return f;
}

// ---------------------------------------------------------------------------------------------
ConstantFunction::ConstantFunction(double value, int num_args) : c_(value), num_args_(num_args) {
  if (!std::isfinite(value)) throw JointError("Constant: value is not finite");
  if (num_args < 0 || num_args > 6)
    throw JointError("Constant: number of arguments must be 0..6, got " + std::to_string(num_args));
}

void ConstantFunction::evaluate(const VecJ&, int order, FunctionValue& out) const {
  out.value = c_;
  if (order >= 1) out.gradient.setZero(num_args_);
  if (order >= 2) out.hessian.setZero(num_args_, num_args_);
}

// ---------------------------------------------------------------------------------------------
LinearFunction::LinearFunction(std::vector<double> coefficients) : coef_(std::move(coefficients)) {
  if (coef_.empty()) throw JointError("LinearFunction: no coefficients (expected [slopes..., intercept])");
  if (coef_.size() > 7)
    throw JointError("LinearFunction: " + std::to_string(coef_.size() - 1) +
                     " slopes; a joint function takes at most 6 arguments");
  for (double c : coef_)
    if (!std::isfinite(c)) throw JointError("LinearFunction: coefficient is not finite");
}

void LinearFunction::evaluate(const VecJ& x, int order, FunctionValue& out) const {
  const int n = numArgs();
  double f = coef_[n];
  for (int i = 0; i < n; ++i) f += coef_[i] * x[i];
  out.value = f;
  if (order >= 1) {
    out.gradient.resize(n);
    for (int i = 0; i < n; ++i) out.gradient[i] = coef_[i];
  }
  if (order >= 2) out.hessian.setZero(n, n);
}

// ---------------------------------------------------------------------------------------------
PolynomialFunction::PolynomialFunction(std::vector<double> coefficients)
    : coef_(std::move(coefficients)) {
  if (coef_.empty()) throw JointError("PolynomialFunction: no coefficients");
  for (double c : coef_)
    if (!std::isfinite(c)) throw JointError("PolynomialFunction: coefficient is not finite");
}

void PolynomialFunction::evaluate1(double x, double& f, double& df, double& ddf) const {
  // Horner for p, p' and p'' together (coefficients in decreasing powers)
  f = df = ddf = 0.0;
  for (double c : coef_) {
    ddf = ddf * x + 2.0 * df;
    df = df * x + f;
    f = f * x + c;
  }
}

// ---------------------------------------------------------------------------------------------
NaturalCubicSpline::NaturalCubicSpline(std::vector<double> x, std::vector<double> y)
    : x_(std::move(x)), y_(std::move(y)) {
  checkData("NaturalCubicSpline", x_, y_);
  const int n = static_cast<int>(x_.size());
  for (int i = 0; i + 1 < n; ++i)
    if (!(x_[i + 1] > x_[i]))
      throw JointError("NaturalCubicSpline: x must be strictly increasing (x[" + std::to_string(i) +
                       "] >= x[" + std::to_string(i + 1) + "])");
  // second derivatives m with m_0 = m_{n-1} = 0:
  //   h_{i-1} m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_i m_{i+1} = 6 (delta_i - delta_{i-1})
  m_.assign(n, 0.0);
  if (n < 3) return;
  std::vector<double> diag(n, 0.0), rhs(n, 0.0);
  for (int i = 1; i < n - 1; ++i) {
    const double h0 = x_[i] - x_[i - 1], h1 = x_[i + 1] - x_[i];
    diag[i] = 2.0 * (h0 + h1);
    rhs[i] = 6.0 * ((y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0);
  }
  // Thomas algorithm on rows 1..n-2 (diagonally dominant, no pivoting needed)
  for (int i = 2; i < n - 1; ++i) {
    const double h0 = x_[i] - x_[i - 1];
    const double w = h0 / diag[i - 1];
    diag[i] -= w * h0;
    rhs[i] -= w * rhs[i - 1];
  }
  m_[n - 2] = rhs[n - 2] / diag[n - 2];
  for (int i = n - 3; i >= 1; --i) m_[i] = (rhs[i] - (x_[i + 1] - x_[i]) * m_[i + 1]) / diag[i];
}

void NaturalCubicSpline::evaluate1(double t, double& f, double& df, double& ddf) const {
  const int n = static_cast<int>(x_.size());
  // linear extrapolation with the end slopes
  auto piece = [&](int k, double s, double& v, double& d1, double& d2) {
    const double h = x_[k + 1] - x_[k];
    const double a = x_[k + 1] - s, b = s - x_[k];
    const double A = y_[k] / h - m_[k] * h / 6.0, B = y_[k + 1] / h - m_[k + 1] * h / 6.0;
    v = (m_[k] * a * a * a + m_[k + 1] * b * b * b) / (6.0 * h) + A * a + B * b;
    d1 = (-m_[k] * a * a + m_[k + 1] * b * b) / (2.0 * h) - A + B;
    d2 = (m_[k] * a + m_[k + 1] * b) / h;
  };
  double d2;
  if (t < x_[0]) {
    piece(0, x_[0], f, df, d2);
    f += (t - x_[0]) * df;
    ddf = 0.0;
  } else if (t > x_[n - 1]) {
    piece(n - 2, x_[n - 1], f, df, d2);
    f += (t - x_[n - 1]) * df;
    ddf = 0.0;
  } else {
    piece(findInterval(x_, t), t, f, df, ddf);
  }
}

// ---------------------------------------------------------------------------------------------
SimmSpline::SimmSpline(std::vector<double> x, std::vector<double> y) : x_(std::move(x)), y_(std::move(y)) {
  checkData("SimmSpline", x_, y_);
  const int n = static_cast<int>(x_.size());
  for (int i = 0; i + 1 < n; ++i)
    if (x_[i + 1] < x_[i])
      throw JointError("SimmSpline: x must be nondecreasing (x[" + std::to_string(i) + "] > x[" +
                       std::to_string(i + 1) + "])");
  constexpr double kTiny = 1e-7;  // OpenSim's floor on every abscissa difference
  auto gap = [&](int i, int j) { return std::max(kTiny, x_[j] - x_[i]); };
  b_.assign(n, 0.0);
  c_.assign(n, 0.0);
  d_.assign(n, 0.0);
  if (n == 2) {
    b_[0] = b_[1] = (y_[1] - y_[0]) / gap(0, 1);
    return;
  }
  // unknowns sigma_i = s''(x_i)/6 on a tridiagonal system: interior rows give C2 continuity,
  //   h_{i-1} sigma_{i-1} + 2 (h_{i-1} + h_i) sigma_i + h_i sigma_{i+1} = delta_i - delta_{i-1};
  // end rows fix the third derivative 6 (sigma_1 - sigma_0)/h_0 to 6 times the third divided
  // difference of the first four points (likewise at the right end); n = 3 uses 0 there.
  std::vector<double> h(n - 1), delta(n - 1), diag(n), rhs(n);
  for (int i = 0; i < n - 1; ++i) {
    h[i] = gap(i, i + 1);
    delta[i] = (y_[i + 1] - y_[i]) / h[i];
  }
  for (int i = 1; i < n - 1; ++i) {
    diag[i] = 2.0 * (h[i - 1] + h[i]);
    rhs[i] = delta[i] - delta[i - 1];
  }
  diag[0] = -h[0];
  diag[n - 1] = -h[n - 2];
  rhs[0] = rhs[n - 1] = 0.0;
  if (n > 3) {
    const double f3_left = ((delta[2] - delta[1]) / gap(1, 3) - (delta[1] - delta[0]) / gap(0, 2)) / gap(0, 3);
    const double f3_right =
        ((delta[n - 2] - delta[n - 3]) / gap(n - 3, n - 1) - (delta[n - 3] - delta[n - 4]) / gap(n - 4, n - 2)) /
        gap(n - 4, n - 1);
    rhs[0] = h[0] * h[0] * f3_left;
    rhs[n - 1] = -h[n - 2] * h[n - 2] * f3_right;
  }
  // elimination without pivoting; the off-diagonal of row i and column i+1 is h_i
  for (int i = 1; i < n; ++i) {
    const double w = h[i - 1] / diag[i - 1];
    diag[i] -= w * h[i - 1];
    rhs[i] -= w * rhs[i - 1];
  }
  std::vector<double> sigma(n);
  sigma[n - 1] = rhs[n - 1] / diag[n - 1];
  for (int i = n - 2; i >= 0; --i) sigma[i] = (rhs[i] - h[i] * sigma[i + 1]) / diag[i];
  // polynomial coefficients of each piece (and the slope at the right end)
  for (int i = 0; i < n - 1; ++i) {
    b_[i] = delta[i] - h[i] * (sigma[i + 1] + 2.0 * sigma[i]);
    c_[i] = 3.0 * sigma[i];
    d_[i] = (sigma[i + 1] - sigma[i]) / h[i];
  }
  b_[n - 1] = delta[n - 2] + h[n - 2] * (sigma[n - 2] + 2.0 * sigma[n - 1]);
  c_[n - 1] = 3.0 * sigma[n - 1];
  d_[n - 1] = d_[n - 2];
}

void SimmSpline::evaluate1(double t, double& f, double& df, double& ddf) const {
  const int n = static_cast<int>(x_.size());
  constexpr double kEndTol = 2e-13;  // OpenSim's ROUNDOFF_ERROR
  if (t < x_[0]) {
    f = y_[0] + (t - x_[0]) * b_[0];
    df = b_[0];
    ddf = 0.0;
    return;
  }
  if (t > x_[n - 1]) {
    f = y_[n - 1] + (t - x_[n - 1]) * b_[n - 1];
    df = b_[n - 1];
    ddf = 0.0;
    return;
  }
  if (std::abs(t - x_[0]) <= kEndTol) {
    f = y_[0];
    df = b_[0];
    ddf = 2.0 * c_[0];
    return;
  }
  if (std::abs(t - x_[n - 1]) <= kEndTol) {
    f = y_[n - 1];
    df = b_[n - 1];
    ddf = 2.0 * c_[n - 1];
    return;
  }
  const int k = findInterval(x_, t);
  const double dx = t - x_[k];
  f = y_[k] + dx * (b_[k] + dx * (c_[k] + dx * d_[k]));
  df = b_[k] + dx * (2.0 * c_[k] + 3.0 * dx * d_[k]);
  ddf = 2.0 * c_[k] + 6.0 * dx * d_[k];
}

// ---------------------------------------------------------------------------------------------
MultiplierFunction::MultiplierFunction(AxisFunctionPtr f, double scale) : f_(std::move(f)), scale_(scale) {
  if (!f_) throw JointError("MultiplierFunction: no function to scale");
  if (!std::isfinite(scale)) throw JointError("MultiplierFunction: scale is not finite");
}

void MultiplierFunction::evaluate(const VecJ& x, int order, FunctionValue& out) const {
  f_->evaluate(x, order, out);
  out.value *= scale_;
  if (order >= 1) out.gradient *= scale_;
  if (order >= 2) out.hessian *= scale_;
}

}  // namespace redmax
