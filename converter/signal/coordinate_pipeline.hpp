#pragma once
// The InverseDynamicsTool's processing of the coordinates file (docs/opensim_compatibility.md §7.3-7.6):
//   3. if the cutoff is >= 0: pad every column and the time column by N/2 (odd reflection);
//      if the time steps are not uniform, fit quintic natural splines to the padded data and
//      resample on the accumulated grid t_first, t_first+dt, ... (dt = the minimum step);
//      then the zero-phase Butterworth low-pass with T = dt;
//   4. per-column scale (the caller passes pi/180 for the Rotational columns of a degrees file:
//      deciding which columns those are needs the model);
//   5. fit one natural quintic spline per column (GCVSpline(5), error variance 0);
//   6. (the caller) maps columns to q slots by name; s, s', s'' give q, qdot, qddot.
// Step 7's time window is selectTimeWindow() on the returned time grid.
// Works on plain data (a time column and a rows x columns matrix), so it does not depend on
// how the storage file was read.
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "converter/signal/natural_spline.hpp"
#include "converter/signal/opensim_signal.hpp"

namespace redmax::signal {

struct CoordinateProcessingOptions {
  /// low-pass cutoff [Hz]; < 0 means no padding, resampling or filtering (OpenSim's default -1)
  double lowpass_cutoff_hz = -1.0;
  /// step 4: empty, or one factor per column multiplying it after filtering (OpenSim multiplies
  /// each Rotational column of a degrees file by (double)(pi/180) and leaves the others)
  std::vector<double> column_scale;
  /// degree of the final splines (OpenSim: 5)
  int spline_degree = 5;
};

/// What processCoordinates produced, with what OpenSim would have logged.
struct ProcessedCoordinates {
  /// processed times: padded (and resampled when steps were not uniform) if filtering was asked;
  /// otherwise the input times. Output rows are taken from this grid (selectTimeWindow).
  std::vector<double> time;
  /// (time.size() x columns) the filtered and scaled samples the splines interpolate
  Eigen::MatrixXd values;
  /// one spline per column, through (time, values.col(c)); s, s', s'' are q, qdot, qddot
  std::vector<NaturalSpline> splines;
  int pad = 0;              ///< samples added at each end (0 if not padded)
  bool resampled = false;   ///< the padded data was resampled to a uniform grid
  bool filtered = false;    ///< the low-pass filter was applied
  double sample_period = 0; ///< T given to the filter (the possibly clamped resampling step)
  double cutoff_hz = 0;     ///< cutoff used by the filter (after the 0.49/T clamp)
  std::vector<std::string> notes;  ///< conditions OpenSim only logs (no filtering done, clamped fc)

  int numColumns() const { return static_cast<int>(splines.size()); }
  /// step 7: output rows for time range [t0, t1] on the processed grid
  TimeWindow selectWindow(double t0, double t1) const { return selectTimeWindow(time, t0, t1); }
};

/// Run steps 3-5 on a coordinates table: time (n rows, non-decreasing) and columns (n x ncols).
/// Throws SignalError on mismatched sizes, non-finite data, too few rows for the splines
/// (2m = 6 for quintics, counted after padding), or times that do not increase where a spline
/// must pass through them.
ProcessedCoordinates processCoordinates(std::span<const double> time, const Eigen::MatrixXd& columns,
                                        const CoordinateProcessingOptions& options = {});

}  // namespace redmax::signal
