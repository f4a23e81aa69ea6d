#include "converter/signal/opensim_signal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace redmax::signal {
namespace {

// SimTK_PI is a long double literal; OpenSim's wc = 2*SimTK_PI*fc is therefore evaluated in
// long double and rounded once to double. Keeping that makes our coefficients OpenSim's bits.
constexpr long double kPiLong = 3.141592653589793238462643383279502884197169399375105820974944592L;

// one padding step with pad < size (Signal::Pad's main branch)
std::vector<double> padOnce(const std::vector<double>& x, int pad) {
  const int n = static_cast<int>(x.size());
  std::vector<double> s(static_cast<size_t>(n + 2 * pad));
  // front: reflect x[pad..1] about x[0]
  for (int i = 0; i < pad; ++i) s[i] = 2.0 * x[0] - x[pad - i];
  for (int i = 0; i < n; ++i) s[pad + i] = x[i];
  // back: reflect x[n-2..] about x[n-1]
  for (int k = 0; k < pad; ++k) s[pad + n + k] = 2.0 * x[n - 1] - x[n - 2 - k];
  return s;
}

}  // namespace

std::vector<double> padOddReflection(std::span<const double> x, int pad) {
  std::vector<double> s(x.begin(), x.end());
  if (pad <= 0 || s.empty()) return s;
  const int size = static_cast<int>(s.size());
  if (size < 2) throw SignalError("padding: a single sample cannot be reflected");
  if (pad < size) return padOnce(s, pad);
  // pad >= size: OpenSim pads in steps of at most size-1 until the target length is reached
  const int target = size + 2 * pad;
  int step = size - 1;
  while (static_cast<int>(s.size()) < target) {
    s = padOnce(s, step);
    const int now = static_cast<int>(s.size());
    step = (target - now) / 2;
    if (step >= now) step = now - 1;
  }
  return s;
}

double calcMinTimeStep(std::span<const double> time) {
  double dtmin = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < time.size(); ++i) dtmin = std::min(dtmin, time[i] - time[i - 1]);
  return dtmin;
}

std::vector<double> makeResampleGrid(std::span<const double> time, double dt, double* dt_used) {
  if (time.empty()) throw SignalError("resampling: no samples");
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    std::ostringstream os;
    os << "resampling: time step must be positive and finite (got " << dt << ")";
    throw SignalError(os.str());
  }
  const double first = time.front(), last = time.back();
  // at most kMaxResampleSize steps over the span
  if ((last - first) / dt > kMaxResampleSize) dt = (last - first) / kMaxResampleSize;
  if (dt_used) *dt_used = dt;
  // accumulated addition, exactly as GCVSplineSet::constructStorage walks x
  std::vector<double> grid;
  grid.reserve(static_cast<size_t>(10 + (last - first) / dt));
  for (double t = first; t <= last; t += dt) grid.push_back(t);
  return grid;
}

Butterworth3 makeButterworth3(double T, double fc) {
  if (!(T > 0.0) || !std::isfinite(T)) {
    std::ostringstream os;
    os << "low-pass filter: sample period must be positive (got " << T << ")";
    throw SignalError(os.str());
  }
  if (!(fc >= 0.0) || !std::isfinite(fc)) {
    std::ostringstream os;
    os << "low-pass filter: cutoff frequency must be finite and >= 0 (got " << fc << ")";
    throw SignalError(os.str());
  }
  Butterworth3 f;
  // keep the cutoff below Nyquist as OpenSim does
  const double fs = 1 / T;
  if (fc >= 0.5 * fs) {
    fc = 0.49 * fs;
    f.clamped = true;
  }
  f.cutoff_hz = fc;
  // prewarped bilinear transform, in OpenSim's operation order
  const double wc = 2 * kPiLong * fc;
  const double wa = std::tan(wc * T / 2.0);
  const double wa2 = wa * wa;
  const double wa3 = wa * wa * wa;
  const double denom = (wa + 1) * (wa * wa + wa + 1.0);
  f.a[0] = wa3 / denom;
  f.a[1] = 3 * wa3 / denom;
  f.a[2] = 3 * wa3 / denom;
  f.a[3] = wa3 / denom;
  f.b[0] = 1;
  f.b[1] = (3 * wa3 + 2 * wa2 - 2 * wa - 3) / denom;
  f.b[2] = (3 * wa3 - 2 * wa2 - 2 * wa + 3) / denom;
  f.b[3] = (wa - 1) * (wa2 - wa + 1) / denom;
  return f;
}

std::vector<double> lowpassIIR(double T, double fc, std::span<const double> x) {
  const Butterworth3 f = makeButterworth3(T, fc);
  const int n = static_cast<int>(x.size());
  std::vector<double> out(x.begin(), x.end());
  if (n < 4) return out;
  const double* a = f.a;
  const double* b = f.b;
  // one causal pass; the first three outputs are the inputs (no history before them)
  auto pass = [&](const std::vector<double>& in, std::vector<double>& y) {
    for (int i = 0; i < 3; ++i) y[i] = in[i];
    for (int i = 3; i < n; ++i)
      y[i] = a[0] * in[i] + a[1] * in[i - 1] + a[2] * in[i - 2] + a[3] * in[i - 3] - b[1] * y[i - 1] -
             b[2] * y[i - 2] - b[3] * y[i - 3];
  };
  std::vector<double> y(n), r(n);
  pass(out, y);
  // backward pass over the reversed output cancels the phase
  std::reverse_copy(y.begin(), y.end(), r.begin());
  pass(r, y);
  std::reverse_copy(y.begin(), y.end(), out.begin());
  return out;
}

int findIndex(std::span<const double> time, double t) {
  if (time.empty()) throw SignalError("findIndex: no samples");
  int i = 0;
  const int n = static_cast<int>(time.size());
  while (i < n && !(t < time[i])) ++i;
  return std::max(i - 1, 0);
}

TimeWindow selectTimeWindow(std::span<const double> time, double t0, double t1) {
  if (time.empty()) throw SignalError("time window: no samples");
  if (std::isnan(t0) || std::isnan(t1)) throw SignalError("time window: time range is NaN");
  if (t1 < t0) {
    std::ostringstream os;
    os << "time window: time range end " << t1 << " is before its start " << t0;
    throw SignalError(os.str());
  }
  TimeWindow w;
  w.start_time = time.front() > t0 ? time.front() : t0;
  w.end_time = time.back() < t1 ? time.back() : t1;
  w.first_row = findIndex(time, w.start_time);
  w.last_row = findIndex(time, w.end_time);
  return w;
}

}  // namespace redmax::signal
