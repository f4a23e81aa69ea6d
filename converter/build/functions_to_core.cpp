#include "converter/build/functions_to_core.hpp"

#include <cmath>
#include <stdexcept>

#include "converter/signal/natural_spline.hpp"

namespace redmax::osim {

namespace {

// OpenSim's EQUAL_WITHIN_ERROR tolerance (SimmMacros.h ROUNDOFF_ERROR) and interval floor
constexpr double kRoundoff = 2e-13;
constexpr double kTinyInterval = 1e-7;

bool equalWithinError(double a, double b) { return std::abs(a - b) <= kRoundoff; }

// OpenSim's bisection for x[0] < t < x[n-1]: some k with x[k] <= t <= x[k+1]; at an interior knot
// it returns whichever side the search reaches first, so derivatives there follow OpenSim's
int opensimBisection(const std::vector<double>& x, double t) {
  int i = 0, j = static_cast<int>(x.size()), k = 0;
  while (true) {
    k = (i + j) / 2;
    if (t < x[k]) j = k;
    else if (t > x[k + 1]) i = k;
    else break;
  }
  return k;
}

void checkTable(const char* type, const std::vector<double>& x, const std::vector<double>& y,
                size_t min_points) {
  if (x.size() != y.size())
    throw std::invalid_argument(std::string(type) + ": " + std::to_string(x.size()) +
                                " x values but " + std::to_string(y.size()) + " y values");
  if (x.size() < min_points)
    throw std::invalid_argument(std::string(type) + ": needs at least " +
                                std::to_string(min_points) + " points, has " +
                                std::to_string(x.size()));
  for (size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]))
      throw std::invalid_argument(std::string(type) + ": point " + std::to_string(i) +
                                  " is not finite");
    if (i > 0 && x[i] < x[i - 1])
      throw std::invalid_argument(std::string(type) + ": x decreases at point " +
                                  std::to_string(i));
  }
}

/// OpenSim PiecewiseLinearFunction (calcCoefficients / calcValue / calcDerivative)
class PiecewiseLinear final : public UnivariateFunction {
 public:
  PiecewiseLinear(std::vector<double> x, std::vector<double> y) : x_(std::move(x)), y_(std::move(y)) {
    checkTable("PiecewiseLinearFunction", x_, y_, 2);
    const size_t n = x_.size();
    b_.resize(n);
    for (size_t i = 0; i + 1 < n; ++i)
      b_[i] = (y_[i + 1] - y_[i]) / std::max(kTinyInterval, x_[i + 1] - x_[i]);
    b_[n - 1] = b_[n - 2];
  }
  void evaluate1(double t, double& f, double& df, double& ddf) const override {
    const int n = static_cast<int>(x_.size());
    ddf = 0.0;
    if (t < x_[0]) {
      f = y_[0] + (t - x_[0]) * b_[0];
      df = b_[0];
    } else if (t > x_[n - 1]) {
      f = y_[n - 1] + (t - x_[n - 1]) * b_[n - 1];
      df = b_[n - 1];
    } else if (equalWithinError(t, x_[0])) {
      f = y_[0];
      df = b_[0];
    } else if (equalWithinError(t, x_[n - 1])) {
      f = y_[n - 1];
      df = b_[n - 1];
    } else {
      const int k = opensimBisection(x_, t);
      f = y_[k] + (t - x_[k]) * b_[k];
      df = b_[k];
    }
  }
  std::string typeName() const override { return "PiecewiseLinearFunction"; }

 private:
  std::vector<double> x_, y_, b_;
};

/// OpenSim PiecewiseConstantFunction
class PiecewiseConstant final : public UnivariateFunction {
 public:
  PiecewiseConstant(std::vector<double> x, std::vector<double> y) : x_(std::move(x)), y_(std::move(y)) {
    checkTable("PiecewiseConstantFunction", x_, y_, 1);
  }
  void evaluate1(double t, double& f, double& df, double& ddf) const override {
    const int n = static_cast<int>(x_.size());
    df = ddf = 0.0;
    if (t < x_[0] || equalWithinError(t, x_[0])) f = y_[0];
    else if (t > x_[n - 1] || equalWithinError(t, x_[n - 1])) f = y_[n - 1];
    else f = y_[opensimBisection(x_, t)];
  }
  std::string typeName() const override { return "PiecewiseConstantFunction"; }

 private:
  std::vector<double> x_, y_;
};

/// OpenSim Sine: A sin(w x + phase) + offset
class Sine final : public UnivariateFunction {
 public:
  Sine(double A, double w, double phase, double offset) : A_(A), w_(w), ph_(phase), off_(offset) {
    if (!std::isfinite(A) || !std::isfinite(w) || !std::isfinite(phase) || !std::isfinite(offset))
      throw std::invalid_argument("Sine: a parameter is not finite");
  }
  void evaluate1(double t, double& f, double& df, double& ddf) const override {
    const double s = std::sin(w_ * t + ph_), c = std::cos(w_ * t + ph_);
    f = A_ * s + off_;
    df = A_ * w_ * c;
    ddf = -A_ * w_ * w_ * s;
  }
  std::string typeName() const override { return "Sine"; }

 private:
  double A_, w_, ph_, off_;
};

/// OpenSim StepFunction = SimTK::Function::Step: y0 + (y1 - y0) s(u), u = (x - x0) / (x1 - x0)
/// clamped to [0, 1], s(u) = 10u^3 - 15u^4 + 6u^5 (C2, so the Hessian is continuous)
class Step final : public UnivariateFunction {
 public:
  Step(double x0, double x1, double y0, double y1) : x0_(x0), y0_(y0), dy_(y1 - y0) {
    if (!std::isfinite(x0) || !std::isfinite(x1) || !std::isfinite(y0) || !std::isfinite(y1))
      throw std::invalid_argument("StepFunction: a parameter is not finite");
    if (x0 == x1)
      throw std::invalid_argument("StepFunction: transition_start_time equals transition_end_time");
    oox_ = 1.0 / (x1 - x0);
  }
  void evaluate1(double t, double& f, double& df, double& ddf) const override {
    const double u = (t - x0_) * oox_;
    if (u <= 0.0) {
      f = y0_, df = ddf = 0.0;
    } else if (u >= 1.0) {
      f = y0_ + dy_, df = ddf = 0.0;
    } else {
      const double u2 = u * u, u3 = u2 * u;
      f = y0_ + dy_ * u3 * (10.0 - 15.0 * u + 6.0 * u2);
      df = dy_ * oox_ * 30.0 * u2 * (1.0 - 2.0 * u + u2);
      ddf = dy_ * oox_ * oox_ * 60.0 * u * (1.0 - 3.0 * u + 2.0 * u2);
    }
  }
  std::string typeName() const override { return "StepFunction"; }

 private:
  double x0_, y0_, dy_, oox_ = 1.0;
};

/// OpenSim GCVSpline with error variance 0: the natural interpolating spline of its degree
class GcvSpline final : public UnivariateFunction {
 public:
  GcvSpline(int half_order, const std::vector<double>& x, const std::vector<double>& y)
      : s_(2 * half_order - 1, x, y) {}
  void evaluate1(double t, double& f, double& df, double& ddf) const override {
    double d[3];
    s_.calcDerivatives(t, d);
    f = d[0], df = d[1], ddf = d[2];
  }
  std::string typeName() const override { return "GCVSpline"; }

 private:
  signal::NaturalSpline s_;
};

/// OpenSim MultivariatePolynomialFunction (4.5+): sum_i c_i prod_j x_j^e_ij over the monomials of
/// total degree <= order, ordered as OpenSim generates them (argument 0's power outermost)
class MultivariatePolynomial final : public AxisFunction {
 public:
  MultivariatePolynomial(int dimension, int order, std::vector<double> coefficients)
      : dim_(dimension), coef_(std::move(coefficients)) {
    if (dimension < 1 || dimension > 6)
      throw std::invalid_argument("MultivariatePolynomialFunction: dimension must be 1..6");
    if (order < 0) throw std::invalid_argument("MultivariatePolynomialFunction: order must be >= 0");
    std::vector<int> e;
    generate(e, 0, order);
    if (coef_.size() != powers_.size())
      throw std::invalid_argument("MultivariatePolynomialFunction: dimension " +
                                  std::to_string(dimension) + " and order " +
                                  std::to_string(order) + " need " +
                                  std::to_string(powers_.size()) + " coefficients, found " +
                                  std::to_string(coef_.size()));
    for (double c : coef_)
      if (!std::isfinite(c))
        throw std::invalid_argument("MultivariatePolynomialFunction: coefficient is not finite");
  }
  int numArgs() const override { return dim_; }
  std::string typeName() const override { return "MultivariatePolynomialFunction"; }
  void evaluate(const VecJ& x, int order, FunctionValue& out) const override {
    out.value = 0.0;
    if (order >= 1) out.gradient.setZero(dim_);
    if (order >= 2) out.hessian.setZero(dim_, dim_);
    for (size_t m = 0; m < powers_.size(); ++m) {
      const std::vector<int>& e = powers_[m];
      const double c = coef_[m];
      out.value += c * monomial(x, e, -1, -1);
      if (order < 1) continue;
      for (int a = 0; a < dim_; ++a) {
        if (e[a] == 0) continue;
        out.gradient[a] += c * e[a] * monomial(x, e, a, -1);
        if (order < 2) continue;
        for (int b = 0; b < dim_; ++b) {
          const int eb = b == a ? e[b] - 1 : e[b];
          if (eb <= 0) continue;
          out.hessian(a, b) += c * e[a] * eb * monomial(x, e, a, b);
        }
      }
    }
  }

 private:
  // all exponent vectors with sum <= order, in OpenSim's generateCombinations order
  void generate(std::vector<int>& e, int sum, int order) {
    if (static_cast<int>(e.size()) == dim_) {
      powers_.push_back(e);
      return;
    }
    for (int i = 0; i <= order - sum; ++i) {
      e.push_back(i);
      generate(e, sum + i, order);
      e.pop_back();
    }
  }
  // prod_j x_j^(e_j - [j == a] - [j == b])
  double monomial(const VecJ& x, const std::vector<int>& e, int a, int b) const {
    double v = 1.0;
    for (int j = 0; j < dim_; ++j) {
      const int p = e[j] - (j == a) - (j == b);
      for (int k = 0; k < p; ++k) v *= x[j];
    }
    return v;
  }
  int dim_;
  std::vector<double> coef_;
  std::vector<std::vector<int>> powers_;
};

AxisFunctionPtr build(const FunctionDesc& f, int num_args, const std::string& file,
                      const std::string& owner) {
  auto fail = [&](const std::string& what) -> ConvertError {
    return ConvertError(file, f.line, owner + ": " + what);
  };
  // every type but Constant (and a Multiplier of one) has a fixed argument count
  auto requireArgs = [&](int n) {
    if (n != num_args)
      throw fail("the " + f.type + " takes " + std::to_string(n) + " argument" +
                 (n == 1 ? "" : "s") + " but " + std::to_string(num_args) + " are given");
  };
  try {
    switch (f.kind) {
      case FunctionKind::Constant:
        return std::make_shared<const ConstantFunction>(f.value, num_args);
      case FunctionKind::Linear:
        requireArgs(static_cast<int>(f.coefficients.size()) - 1);
        return std::make_shared<const LinearFunction>(f.coefficients);
      case FunctionKind::Polynomial:
        requireArgs(1);
        return std::make_shared<const PolynomialFunction>(f.coefficients);
      case FunctionKind::SimmSpline:
        requireArgs(1);
        return std::make_shared<const SimmSpline>(f.x, f.y);
      case FunctionKind::GCVSpline:
        requireArgs(1);
        if (f.error_variance != 0.0)
          throw fail("GCVSpline with error_variance " + std::to_string(f.error_variance) +
                     " is a smoothing spline; only error_variance 0 (interpolation) is supported");
        if (f.half_order < 1 || f.half_order > 4)
          throw fail("GCVSpline half_order must be 1..4, found " + std::to_string(f.half_order));
        return std::make_shared<const GcvSpline>(f.half_order, f.x, f.y);
      case FunctionKind::Multiplier:
        if (f.inner.size() != 1) throw fail("MultiplierFunction needs exactly one function to scale");
        if (!std::isfinite(f.scale)) throw fail("MultiplierFunction scale is not finite");
        return std::make_shared<const MultiplierFunction>(build(f.inner.front(), num_args, file, owner),
                                                          f.scale);
      case FunctionKind::PiecewiseLinear:
        requireArgs(1);
        return std::make_shared<const PiecewiseLinear>(f.x, f.y);
      case FunctionKind::PiecewiseConstant:
        requireArgs(1);
        return std::make_shared<const PiecewiseConstant>(f.x, f.y);
      case FunctionKind::Sine:
        requireArgs(1);
        return std::make_shared<const Sine>(f.amplitude, f.omega, f.phase, f.offset);
      case FunctionKind::Step:
        requireArgs(1);
        return std::make_shared<const Step>(f.start_time, f.end_time, f.start_value, f.end_value);
      case FunctionKind::MultivariatePolynomial:
        requireArgs(f.dimension);
        return std::make_shared<const MultivariatePolynomial>(f.dimension, f.order, f.coefficients);
      case FunctionKind::ExpressionBased:
        throw fail("ExpressionBasedFunction ('" + f.expression +
                   "') is not supported: expressions are not evaluated");
    }
  } catch (const ConvertError&) {
    throw;
  } catch (const std::exception& e) {
    // JointError, SignalError, invalid_argument from the constructors: bad data in the file
    throw fail(e.what());
  }
  throw fail("unknown function type '" + f.written_type + "'");
}

}  // namespace

AxisFunctionPtr makeCoreFunction(const FunctionDesc& f, int num_args, const std::string& file,
                                 const std::string& owner) {
  if (num_args < 0 || num_args > 6)
    throw ConvertError(file, f.line,
                       owner + ": " + std::to_string(num_args) +
                           " arguments (a core function takes 0..6)");
  return build(f, num_args, file, owner);
}

}  // namespace redmax::osim
