#pragma once
// OpenSim's signal primitives as the InverseDynamicsTool uses them (docs/opensim_compatibility.md §7.3
// and 7.7, and §7.10 the low-pass filter): odd-reflection padding (Signal::Pad), the minimum time step and
// uniformity test, resampling on an accumulated time grid (Storage::resample), the zero-phase
// third-order Butterworth IIR (Signal::LowpassIIR) and Storage::findIndex. The floating-point
// operations are done in OpenSim's order, so time grids come out bit-identical.
#include <span>
#include <vector>

#include "converter/signal/signal_error.hpp"

namespace redmax::signal {

/// SimTK::Eps, the threshold OpenSim uses for "time steps are not uniform" and "dt is zero"
inline constexpr double kTimeEps = 2.220446049250313e-16;
/// Storage::MAX_RESAMPLE_SIZE: resampling never makes more than this many steps
inline constexpr int kMaxResampleSize = 100000;

/// Signal::Pad: prepend and append `pad` samples by odd reflection about the end samples,
///   front s[i] = 2 x_0 - x[pad-i]  (i = 0..pad-1),  back s[pad+n+k] = 2 x_{n-1} - x[n-2-k].
/// This keeps the value and slope at both ends. pad >= n is done in repeated steps, as OpenSim
/// does. pad <= 0 returns x unchanged. Applied to the time column too (OpenSim pads time).
std::vector<double> padOddReflection(std::span<const double> x, int pad);

/// Storage::getMinTimeStep: min_i (t_i - t_{i-1}); +infinity with fewer than 2 samples
double calcMinTimeStep(std::span<const double> time);

/// Storage::resample's grid: t = t_first; while t <= t_last { emit t; t += dt } with dt
/// accumulated in floating point. If (t_last - t_first)/dt > kMaxResampleSize, dt is first
/// raised to (t_last - t_first)/kMaxResampleSize. `dt_used` (optional) receives the step.
/// Throws SignalError if time is empty or dt is not positive and finite.
std::vector<double> makeResampleGrid(std::span<const double> time, double dt, double* dt_used = nullptr);

/// The digital filter y_i = sum a_k x_{i-k} - sum_{k>=1} b_k y_{i-k} of Signal::LowpassIIR:
/// the bilinear transform (with prewarping) of the 3rd-order Butterworth 1/((s+1)(s^2+s+1)).
struct Butterworth3 {
  double a[4] = {0, 0, 0, 0};  ///< numerator, a0..a3
  double b[4] = {1, 0, 0, 0};  ///< denominator, b0 = 1
  double cutoff_hz = 0;        ///< the cutoff used (after the clamp below)
  bool clamped = false;        ///< true if the requested cutoff was >= half the sample rate
};

/// Coefficients for sample period T [s] and cutoff fc [Hz]: fc >= 0.5/T is clamped to 0.49/T,
/// w = tan(pi fc T), D = (w+1)(w^2+w+1), a0 = a3 = w^3/D, a1 = a2 = 3w^3/D,
/// b1 = (3w^3+2w^2-2w-3)/D, b2 = (3w^3-2w^2-2w+3)/D, b3 = (w-1)(w^2-w+1)/D.
/// Throws SignalError for T <= 0 or a non-finite or negative fc.
Butterworth3 makeButterworth3(double T, double fc);

/// Signal::LowpassIIR: forward pass (first three outputs copied from the input), then the same
/// recursion over the reversed result, reversed back: zero phase, gain |H|^2 (-6 dB at fc).
/// Fewer than 4 samples are returned unfiltered (Storage::lowpassIIR skips them).
std::vector<double> lowpassIIR(double T, double fc, std::span<const double> x);

/// Storage::findIndex(t): the last row whose time is <= t, or 0 if t precedes every row
/// (times assumed non-decreasing). Throws SignalError on an empty column.
int findIndex(std::span<const double> time, double t);

/// The rows the InverseDynamicsTool solves at (step 7): start = max(t_first, t0),
/// end = min(t_last, t1), rows findIndex(start) .. findIndex(end) inclusive.
struct TimeWindow {
  int first_row = 0;
  int last_row = -1;
  double start_time = 0;  ///< max(t_first, t0)
  double end_time = 0;    ///< min(t_last, t1)
  int numRows() const { return last_row - first_row + 1; }
};

/// Throws SignalError on an empty time column, NaN limits, or t1 < t0.
TimeWindow selectTimeWindow(std::span<const double> time, double t0, double t1);

}  // namespace redmax::signal
