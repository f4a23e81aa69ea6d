#pragma once
// Functions of joint coordinates for the function-based (OpenSim CustomJoint) joint, with exact
// first and second derivatives (docs/opensim_compatibility.md §4).
//
// Interface for new function types (the converter adds OpenSim's others against it):
//   - derive from AxisFunction (any number of arguments, at most 6) or, for one argument, from
//     UnivariateFunction and implement evaluate1();
//   - objects are immutable after construction and shared as
//     std::shared_ptr<const AxisFunction>, so Models that hold them stay cheap to copy;
//   - validate in the constructor and throw JointError with a clear message on bad input;
//   - evaluate() must be exact (no finite differences): S uses the gradient and Sdot the Hessian.
#include <memory>
#include <string>
#include <vector>

#include "core/joints/joint_kinematics.hpp"

namespace redmax {

/// Result of AxisFunction::evaluate: value, gradient (numArgs) and Hessian (numArgs x numArgs).
struct FunctionValue {
  double value = 0.0;
  VecJ gradient;
  MatJ hessian;
};

class AxisFunction {
 public:
  virtual ~AxisFunction() = default;
  /// number of arguments (0..6)
  virtual int numArgs() const = 0;
  /// Value at x (numArgs entries) and, for order >= 1, the gradient, for order >= 2 the
  /// Hessian. Entries not requested are left unspecified.
  virtual void evaluate(const VecJ& x, int order, FunctionValue& out) const = 0;
  /// short name for errors and summaries ("SimmSpline", "LinearFunction", ...)
  virtual std::string typeName() const = 0;

  double value(const VecJ& x) const;
  VecJ gradient(const VecJ& x) const;
  MatJ hessian(const VecJ& x) const;
};

using AxisFunctionPtr = std::shared_ptr<const AxisFunction>;

/// Base for functions of one argument: implement f, f' and f'' at a point.
class UnivariateFunction : public AxisFunction {
 public:
  int numArgs() const final { return 1; }
  void evaluate(const VecJ& x, int order, FunctionValue& out) const final;
  /// f(x), f'(x), f''(x)
  virtual void evaluate1(double x, double& f, double& df, double& ddf) const = 0;
  double value1(double x) const;
};

/// c, of any number of arguments (OpenSim's Constant takes none); all derivatives 0.
class ConstantFunction : public AxisFunction {
 public:
  explicit ConstantFunction(double value, int num_args = 0);
  int numArgs() const override { return num_args_; }
  void evaluate(const VecJ& x, int order, FunctionValue& out) const override;
  std::string typeName() const override { return "Constant"; }
  double constant() const { return c_; }

 private:
  double c_;
  int num_args_;
};

/// OpenSim LinearFunction: coefficients [slope_1..slope_n, intercept], f = sum s_i x_i + c;
/// n = coefficients - 1 arguments. Throws JointError for an empty list or more than 6 slopes.
class LinearFunction : public AxisFunction {
 public:
  explicit LinearFunction(std::vector<double> coefficients);
  LinearFunction(double slope, double intercept) : LinearFunction(std::vector<double>{slope, intercept}) {}
  int numArgs() const override { return static_cast<int>(coef_.size()) - 1; }
  void evaluate(const VecJ& x, int order, FunctionValue& out) const override;
  std::string typeName() const override { return "LinearFunction"; }
  const std::vector<double>& coefficients() const { return coef_; }

 private:
  std::vector<double> coef_;
};

/// OpenSim PolynomialFunction: coefficients in DECREASING powers, c_0 x^n + ... + c_n
/// (Horner). Throws JointError for an empty list.
class PolynomialFunction : public UnivariateFunction {
 public:
  explicit PolynomialFunction(std::vector<double> coefficients);
  void evaluate1(double x, double& f, double& df, double& ddf) const override;
  std::string typeName() const override { return "PolynomialFunction"; }

 private:
  std::vector<double> coef_;
};

/// Natural interpolating cubic spline: zero second derivative at both ends, linear
/// extrapolation outside [x_0, x_{n-1}] (second derivative 0 there). n = 2 is a straight line.
/// Throws JointError if n < 2, sizes differ, values are not finite or x is not strictly
/// increasing.
class NaturalCubicSpline : public UnivariateFunction {
 public:
  NaturalCubicSpline(std::vector<double> x, std::vector<double> y);
  void evaluate1(double x, double& f, double& df, double& ddf) const override;
  std::string typeName() const override { return "NaturalCubicSpline"; }

 private:
  std::vector<double> x_, y_, m_;  // m_: second derivatives at the knots
};

/// OpenSim SimmSpline (Forsythe-Malcolm-Moler cubic spline, docs/opensim_compatibility.md §4):
///  - intervals h_i = max(1e-7, x_{i+1} - x_i);
///  - n = 2: the straight line; n = 3: the parabola through the points (equal second derivatives
///    on both intervals); n >= 4: the third derivative on the first (last) interval equals that
///    of the cubic through the first (last) four points;
///  - piece i: y_i + b_i dx + c_i dx^2 + d_i dx^3, dx = x - x_i;
///  - outside [x_0, x_{n-1}]: y_end + (x - x_end) b_end, first derivative b_end, second 0;
///  - within 2e-13 inside an end: value y_end, first derivative b_end, second 2 c_end.
/// Throws JointError if n < 2, sizes differ, values are not finite or x decreases somewhere
/// (equal neighbours are accepted, as OpenSim does, through the 1e-7 floor).
class SimmSpline : public UnivariateFunction {
 public:
  SimmSpline(std::vector<double> x, std::vector<double> y);
  void evaluate1(double x, double& f, double& df, double& ddf) const override;
  std::string typeName() const override { return "SimmSpline"; }
  const std::vector<double>& x() const { return x_; }
  const std::vector<double>& y() const { return y_; }

 private:
  std::vector<double> x_, y_, b_, c_, d_;
};

/// OpenSim MultiplierFunction: scale * f, same arguments as f. Throws JointError if f is null.
class MultiplierFunction : public AxisFunction {
 public:
  MultiplierFunction(AxisFunctionPtr f, double scale);
  int numArgs() const override { return f_->numArgs(); }
  void evaluate(const VecJ& x, int order, FunctionValue& out) const override;
  std::string typeName() const override { return "MultiplierFunction"; }

 private:
  AxisFunctionPtr f_;
  double scale_;
};

}  // namespace redmax
