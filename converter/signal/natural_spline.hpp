#pragma once
// Natural interpolating splines of odd degree 2m-1 (m = 1..4: linear, cubic, quintic, septic).
//
// This is what OpenSim's GCVSpline with error variance 0 evaluates (docs/opensim_compatibility.md §4): GCVSPL
// in mode 3 stops at a smoothing parameter so small that the fit interpolates to ~1e-13, and a
// natural smoothing spline tends to the natural interpolating spline as p -> 0. We compute the
// p = 0 limit directly:
//   - s is a polynomial of degree 2m-1 on each [x_i, x_{i+1}], with s^(j) continuous for
//     j = 0..2m-2 at the interior knots, and s(x_i) = y_i;
//   - natural end conditions s^(j)(x_1) = s^(j)(x_n) = 0 for j = m..2m-2;
//   - outside [x_1, x_n] s is the polynomial of degree m-1 that continues it (its Taylor
//     polynomial at the end knot): linear for cubics, quadratic for quintics.
// The unknowns are the derivatives 1..m-1 at the knots (Hermite form); continuity of derivatives
// m..2m-2 and the end conditions give a banded linear system, solved by banded LU with partial
// pivoting in O(n m^2) and one refinement step (residual in long double). Agreement with Simbody's
// SplineFitter (GCVSPL, error variance 0) is measured in tests/validation/signal_simbody_test.cpp.
#include <span>
#include <vector>

#include "converter/signal/signal_error.hpp"

namespace redmax::signal {

/// A natural interpolating spline of odd degree 2m-1 through (x_i, y_i), x strictly increasing.
/// Value semantics (copyable); evaluation is const and thread-safe.
class NaturalSpline {
 public:
  NaturalSpline() = default;
  /// Fit through (x_i, y_i). degree must be 1, 3, 5 or 7 (m = (degree+1)/2); at least 2m points
  /// (as GCVSPL requires), x strictly increasing, all values finite. Throws SignalError otherwise.
  NaturalSpline(int degree, std::span<const double> x, std::span<const double> y);

  int degree() const { return 2 * m_ - 1; }
  /// m: half order; outside the data the spline is a polynomial of degree m-1
  int halfOrder() const { return m_; }
  int size() const { return static_cast<int>(x_.size()); }
  bool empty() const { return x_.empty(); }
  const std::vector<double>& x() const { return x_; }
  const std::vector<double>& y() const { return y_; }
  double minX() const { return x_.front(); }
  double maxX() const { return x_.back(); }

  /// s(t), anywhere (extrapolated outside [minX, maxX])
  double calcValue(double t) const;
  /// d^order s / dt^order at t; order 0 is the value; orders above the degree give 0.
  /// At a knot, order 2m-1 (discontinuous) is taken from the interval to the right of it
  /// (the last interval at maxX).
  double calcDerivative(int order, double t) const;
  /// out[k] = d^k s / dt^k at t for k = 0..out.size()-1 (one interval search)
  void calcDerivatives(double t, std::span<double> out) const;

 private:
  int m_ = 0;
  std::vector<double> x_, y_;
  std::vector<double> h_;     // interval lengths (n-1)
  std::vector<double> coef_;  // per interval, 2m coefficients of p(u) = sum c_k u^k, u = (t-x_i)/h_i
  std::vector<double> d_lo_, d_hi_;  // derivatives 0..m-1 at x_1 and x_n (extrapolation)
};

}  // namespace redmax::signal
