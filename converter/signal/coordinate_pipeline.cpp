#include "converter/signal/coordinate_pipeline.hpp"

#include <cmath>
#include <sstream>

namespace redmax::signal {
namespace {

std::span<const double> columnSpan(const Eigen::MatrixXd& m, int c) {
  return {m.col(c).data(), static_cast<size_t>(m.rows())};
}

// fit one spline per column, naming the column in any error
std::vector<NaturalSpline> fitColumns(int degree, std::span<const double> time, const Eigen::MatrixXd& values,
                                      const char* stage) {
  std::vector<NaturalSpline> splines;
  splines.reserve(values.cols());
  for (int c = 0; c < values.cols(); ++c) {
    try {
      splines.emplace_back(degree, time, columnSpan(values, c));
    } catch (const SignalError& e) {
      std::ostringstream os;
      os << stage << ", column " << c << ": " << e.what();
      throw SignalError(os.str());
    }
  }
  return splines;
}

}  // namespace

ProcessedCoordinates processCoordinates(std::span<const double> time, const Eigen::MatrixXd& columns,
                                        const CoordinateProcessingOptions& options) {
  // input checks
  const int n = static_cast<int>(time.size());
  const int ncols = static_cast<int>(columns.cols());
  if (n == 0) throw SignalError("coordinates: no rows");
  if (columns.rows() != n) {
    std::ostringstream os;
    os << "coordinates: " << n << " times but " << columns.rows() << " rows of data";
    throw SignalError(os.str());
  }
  if (!options.column_scale.empty() && static_cast<int>(options.column_scale.size()) != ncols) {
    std::ostringstream os;
    os << "coordinates: " << options.column_scale.size() << " column scale factors for " << ncols << " columns";
    throw SignalError(os.str());
  }
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(time[i])) throw SignalError("coordinates: non-finite time at row " + std::to_string(i));
  if (!columns.allFinite()) throw SignalError("coordinates: non-finite value in the data");
  if (std::isnan(options.lowpass_cutoff_hz)) throw SignalError("coordinates: low-pass cutoff is NaN");

  ProcessedCoordinates out;
  out.time.assign(time.begin(), time.end());
  out.values = columns;

  // step 3: pad, resample if the steps are not uniform, filter (a cutoff of 0 counts too)
  if (options.lowpass_cutoff_hz >= 0) {
    // 3a: odd reflection by N/2 (integer division), time column included
    out.pad = n / 2;
    if (out.pad > 0) {
      std::vector<double> t_pad = padOddReflection(time, out.pad);
      Eigen::MatrixXd v_pad(static_cast<Eigen::Index>(t_pad.size()), ncols);
      for (int c = 0; c < ncols; ++c) {
        const std::vector<double> p = padOddReflection(columnSpan(columns, c), out.pad);
        v_pad.col(c) = Eigen::Map<const Eigen::VectorXd>(p.data(), static_cast<Eigen::Index>(p.size()));
      }
      out.time = std::move(t_pad);
      out.values = std::move(v_pad);
    }

    // 3b: uniformity check on the padded times
    const int np = static_cast<int>(out.time.size());
    double dtmin = calcMinTimeStep(out.time);
    const double avg = (out.time[np - 1] - out.time[0]) / (np - 1);
    if (dtmin < kTimeEps) {
      out.notes.push_back("minimum time step is below 2.2e-16: the data cannot be resampled, so it is not filtered");
    } else {
      if ((avg - dtmin) > kTimeEps) {
        // quintic natural splines through the padded data, evaluated on the accumulated grid
        const std::vector<NaturalSpline> fit = fitColumns(5, out.time, out.values, "resampling");
        std::vector<double> grid = makeResampleGrid(out.time, dtmin, &dtmin);
        Eigen::MatrixXd resampled(static_cast<Eigen::Index>(grid.size()), ncols);
        for (int c = 0; c < ncols; ++c)
          for (size_t i = 0; i < grid.size(); ++i) resampled(static_cast<Eigen::Index>(i), c) = fit[c].calcValue(grid[i]);
        out.time = std::move(grid);
        out.values = std::move(resampled);
        out.resampled = true;
      }
      // 3c: zero-phase Butterworth with T = the (possibly clamped) step
      if (out.time.size() < 4) {
        out.notes.push_back("fewer than 4 samples: not filtered");
      } else {
        const Butterworth3 f = makeButterworth3(dtmin, options.lowpass_cutoff_hz);
        if (f.clamped) {
          std::ostringstream os;
          os << "cutoff " << options.lowpass_cutoff_hz << " Hz is not below half the sample rate; using " << f.cutoff_hz
             << " Hz";
          out.notes.push_back(os.str());
        }
        for (int c = 0; c < ncols; ++c) {
          const std::vector<double> y = lowpassIIR(dtmin, options.lowpass_cutoff_hz, columnSpan(out.values, c));
          out.values.col(c) = Eigen::Map<const Eigen::VectorXd>(y.data(), static_cast<Eigen::Index>(y.size()));
        }
        out.filtered = true;
        out.sample_period = dtmin;
        out.cutoff_hz = f.cutoff_hz;
      }
    }
  }

  // step 4: per-column scale (deg -> rad for Rotational columns, decided by the caller)
  if (!options.column_scale.empty())
    for (int c = 0; c < ncols; ++c) out.values.col(c) *= options.column_scale[c];

  // step 5: one natural spline per column through the processed samples
  out.splines = fitColumns(options.spline_degree, out.time, out.values, "coordinate splines");
  return out;
}

}  // namespace redmax::signal
