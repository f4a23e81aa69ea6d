#pragma once
// The differences the analytic Jacobians take (docs/gradients.md §2.1): of a part alone, never of
// the whole step, where no code computes the derivative in closed form - a joint's dSdot/dq, a
// moving point's or a coupling function's third derivative, a wrapping muscle's share, a
// constraint's rows - as a function of one scalar that is cheap to evaluate. localDerivative:
// fourth-order central difference at h = 1e-3 max(1, |x|) by default, truncation about
// h^4 |f^(5)| / 30 ~ 1e-12, round-off about eps |f| / h ~ 1e-13 of the value.
#include <algorithm>
#include <cmath>

namespace redmax {

/// d f / dx at x; f maps a double to a double or an Eigen object of fixed shape; the step is
/// `relative_step` max(1, |x|)
template <class F>
auto localDerivative(F&& f, double x, double relative_step = 1e-3) {
  const double h = relative_step * std::max(1.0, std::abs(x));
  // evaluated in one full expression: an Eigen expression kept in `auto` would refer to the
  // temporaries f returns after they are gone
  return decltype(f(x))((f(x - 2.0 * h) - 8.0 * f(x - h) + 8.0 * f(x + h) - f(x + 2.0 * h)) / (12.0 * h));
}

/// The second-order sibling for parts whose derivatives the adjoint takes at its own relative
/// step (Problem::jacobian_step: Hill-type muscles, force terms differenced alone): the central
/// difference at h = relative_step max(1, |x|).
template <class F>
auto centralDerivative(F&& f, double x, double relative_step) {
  const double h = relative_step * std::max(1.0, std::abs(x));
  return decltype(f(x))((f(x + h) - f(x - h)) / (2.0 * h));
}

}  // namespace redmax
