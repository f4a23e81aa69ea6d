#include "converter/signal/load_interpolant.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace redmax::signal {
namespace {

// OpenSim's SimmMacros: minimum segment width for slopes, and the end-point tolerance
constexpr double kTinyNumber = 1e-7;
constexpr double kRoundoffError = 2e-13;

void checkSeries(std::span<const double> x, std::span<const double> y, const char* what) {
  if (x.size() != y.size()) {
    std::ostringstream os;
    os << what << ": " << x.size() << " times but " << y.size() << " values";
    throw SignalError(os.str());
  }
  if (x.empty()) throw SignalError(std::string(what) + ": no samples");
  for (size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
      std::ostringstream os;
      os << what << ": non-finite sample at row " << i;
      throw SignalError(os.str());
    }
    if (i > 0 && x[i] < x[i - 1]) {
      std::ostringstream os;
      os.precision(17);
      os << what << ": times decrease at row " << i << " (" << x[i - 1] << " then " << x[i] << ")";
      throw SignalError(os.str());
    }
  }
}

}  // namespace

PiecewiseLinear::PiecewiseLinear(std::span<const double> x, std::span<const double> y) {
  checkSeries(x, y, "piecewise linear function");
  if (x.size() < 2) throw SignalError("piecewise linear function: needs at least 2 points");
  x_.assign(x.begin(), x.end());
  y_.assign(y.begin(), y.end());
  const int n = static_cast<int>(x_.size());
  b_.resize(n);
  for (int i = 0; i + 1 < n; ++i) b_[i] = (y_[i + 1] - y_[i]) / std::max(kTinyNumber, x_[i + 1] - x_[i]);
  b_[n - 1] = b_[n - 2];
}

int PiecewiseLinear::findSegment(double t) const {
  // OpenSim's bisection: stops on k with x_k <= t <= x_{k+1}
  const int n = static_cast<int>(x_.size());
  int i = 0, j = n, k = 0;
  while (true) {
    k = (i + j) / 2;
    if (t < x_[k]) j = k;
    else if (t > x_[k + 1]) i = k;
    else break;
  }
  return k;
}

double PiecewiseLinear::calcValue(double t) const { return calcDerivative(0, t); }

double PiecewiseLinear::calcDerivative(int order, double t) const {
  if (x_.empty()) throw SignalError("piecewise linear function: evaluated before it was built");
  if (order < 0) throw SignalError("piecewise linear function: negative derivative order");
  if (order >= 2) return 0.0;
  const int n = static_cast<int>(x_.size());
  // linear extrapolation with the end slopes
  if (t < x_[0]) return order == 0 ? y_[0] + (t - x_[0]) * b_[0] : b_[0];
  if (t > x_[n - 1]) return order == 0 ? y_[n - 1] + (t - x_[n - 1]) * b_[n - 1] : b_[n - 1];
  // at the ends (bisection does not handle them): end value, end slope
  if (std::abs(t - x_[0]) <= kRoundoffError) return order == 0 ? y_[0] : b_[0];
  if (std::abs(t - x_[n - 1]) <= kRoundoffError) return order == 0 ? y_[n - 1] : b_[n - 1];
  const int k = findSegment(t);
  return order == 0 ? y_[k] + (t - x_[k]) * b_[k] : b_[k];
}

LoadInterpolant::LoadInterpolant(std::span<const double> time, std::span<const double> values) {
  checkSeries(time, values, "external load data");
  const size_t n = time.size();
  if (n == 1) {
    kind_ = Kind::Constant;
    constant_ = values[0];
  } else if (n <= 3) {
    kind_ = Kind::PiecewiseLinear;
    linear_ = PiecewiseLinear(time, values);
  } else {
    kind_ = Kind::NaturalCubic;
    cubic_ = NaturalSpline(3, time, values);
  }
}

double LoadInterpolant::calcDerivative(int order, double t) const {
  if (order < 0) throw SignalError("external load data: negative derivative order");
  switch (kind_) {
    case Kind::Constant: return order == 0 ? constant_ : 0.0;
    case Kind::PiecewiseLinear: return linear_.calcDerivative(order, t);
    case Kind::NaturalCubic: return cubic_.calcDerivative(order, t);
  }
  return 0.0;
}

}  // namespace redmax::signal
