#pragma once
// Least-squares exponent of y ~ x^p on log-log data, for the scaling tables the benchmarks print.
#include <cmath>
#include <vector>

namespace redmax::bench {

inline double fittedExponent(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double a = std::log(x[i]), b = std::log(y[i]);
    sx += a, sy += b, sxx += a * a, sxy += a * b;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace redmax::bench
