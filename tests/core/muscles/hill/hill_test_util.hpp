#pragma once
// Helpers for the Hill-model suites: central differences and relative comparisons.
#include <cmath>
#include <functional>

namespace redmax::hill::test {

/// (f(x + h) - f(x - h)) / 2h
inline double centralDifference(const std::function<double(double)>& f, double x, double h = 1e-6) {
  return (f(x + h) - f(x - h)) / (2 * h);
}

/// |a - b| <= tol (1 + |b|)   (STYLE.md: safe against a zero reference)
inline bool nearRel(double a, double b, double tol) { return std::abs(a - b) <= tol * (1 + std::abs(b)); }

}  // namespace redmax::hill::test
