#pragma once
// Time interpolation of external-load data (docs/opensim_compatibility.md §7.8, ExternalForce): the data
// is not filtered; one row gives a constant, two or three rows OpenSim's PiecewiseLinearFunction,
// four or more a natural cubic spline (GCVSpline degree 3, error variance 0).
#include <span>
#include <vector>

#include "converter/signal/natural_spline.hpp"

namespace redmax::signal {

/// OpenSim's PiecewiseLinearFunction (§4): segment slopes (y_{i+1}-y_i)/max(1e-7, dx), the last
/// slope repeating the previous one; linear extrapolation with the end slopes; value and slope at
/// an end when within 2e-13 of it; derivatives of order >= 2 are 0. Inside, the segment is found
/// by OpenSim's bisection (at an interior knot the slope is that of the segment it stops on).
class PiecewiseLinear {
 public:
  PiecewiseLinear() = default;
  /// x non-decreasing, at least 2 points, all finite; throws SignalError otherwise
  PiecewiseLinear(std::span<const double> x, std::span<const double> y);
  double calcValue(double t) const;
  /// order 0 is the value; order 1 the segment slope; order >= 2 is 0
  double calcDerivative(int order, double t) const;

 private:
  int findSegment(double t) const;  // valid only for x_0 < t < x_{n-1} off the end tolerances
  std::vector<double> x_, y_, b_;
};

/// One column of external-load data as a function of time, interpolated as OpenSim does.
class LoadInterpolant {
 public:
  enum class Kind { Constant, PiecewiseLinear, NaturalCubic };
  LoadInterpolant() = default;
  /// times and values of one column (same length >= 1, finite; times non-decreasing, and strictly
  /// increasing for 4+ rows). Throws SignalError otherwise.
  LoadInterpolant(std::span<const double> time, std::span<const double> values);
  Kind kind() const { return kind_; }
  double calcValue(double t) const { return calcDerivative(0, t); }
  /// d^order/dt^order; the constant has zero derivatives, the piecewise linear zero for order >= 2
  double calcDerivative(int order, double t) const;

 private:
  Kind kind_ = Kind::Constant;
  double constant_ = 0;
  PiecewiseLinear linear_;
  NaturalSpline cubic_;
};

}  // namespace redmax::signal
