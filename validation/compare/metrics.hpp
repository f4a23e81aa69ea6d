#pragma once
// Per-column error metrics of one table against another on a common grid, pass/fail against
// stated tolerances, and the worst column. Pure functions over time_series.hpp's aligned tables.
//
// Conventions (d = a - b, b is the reference side):
//   rms      = sqrt( sum_i w_i d_i^2 / sum_i w_i ), w_i the trapezoid weights of the grid
//              (time-weighted, so uneven grids do not bias it; exact for a sinusoid sampled
//              uniformly over whole periods), or w_i = 1 with RmsWeighting::Samples;
//   max_abs  = max_i |d_i|, at time t_max_abs (the first such time);
//   peak_ref = max_i |b_i| over the same grid;
//   rms_rel  = rms / peak_ref, max_rel = max_abs / peak_ref (0 when both are 0, +inf when only
//              the peak is 0);
//   pass     <=>  rms <= rms_abs + rms_rel_tol * peak_ref  and  max_abs <= max_abs_tol +
//              max_rel_tol * peak_ref, and every sample finite (an absolute floor keeps columns
//              whose reference is ~0, e.g. a locked coordinate's moment, from failing on round-off).
// usage = the larger of the two ratios metric / allowance (<= 1 passes); the worst column is the
// one with the largest usage.
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "validation/compare/time_series.hpp"

namespace redmax::validation {

/// Allowed error of one column: |error| <= abs + rel * peak |reference|, for RMS and for max.
struct Tolerance {
  double rms_abs = 1e-9;
  double rms_rel = 1e-3;
  double max_abs = 1e-9;
  double max_rel = 1e-2;
};

/// How the RMS averages over the grid.
enum class RmsWeighting {
  Trapezoid,  ///< time-weighted (trapezoid rule over the grid), the default
  Samples     ///< plain mean over the samples
};
/// "trapezoid" or "samples"
std::string toString(RmsWeighting w);

/// Metrics of one column (see the file comment for the definitions).
struct ColumnMetrics {
  std::string name;
  int samples = 0;           ///< grid points with finite a and b (the metrics use only these)
  int non_finite = 0;        ///< grid points where a or b is NaN or infinite (such a column fails)
  double rms = 0;
  double mean = 0;           ///< mean difference (same weights as rms): a constant offset shows here
  double max_abs = 0;
  double t_max_abs = 0;
  double peak_ref = 0;
  double rms_rel = 0;
  double max_rel = 0;
  Tolerance tolerance;
  double usage = 0;          ///< max(rms / rms allowance, max_abs / max allowance)
  bool passed = false;
};

/// Metrics of a against the reference b, sampled at the increasing times t (all three the same
/// length >= 1). Pass/fail uses tol. Throws CompareError on mismatched lengths.
ColumnMetrics calcColumnMetrics(const std::string& name, const std::vector<double>& t,
                                const std::vector<double>& a, const std::vector<double>& b,
                                const Tolerance& tol = {}, RmsWeighting weighting = RmsWeighting::Trapezoid);

struct CompareOptions {
  AlignOptions align;                                 ///< grid and interpolation
  Tolerance tolerance;                                ///< for every column...
  std::map<std::string, Tolerance> column_tolerance;  ///< ...unless named here
  RmsWeighting weighting = RmsWeighting::Trapezoid;
  /// when true, a column present on only one side makes the comparison fail (it is always reported)
  bool missing_columns_fail = false;
};

/// One comparison: a against the reference b, column by column.
struct Comparison {
  std::string name;               ///< identifier, also the file stem in reports ("core_vs_simbody")
  std::string label_a, label_b;   ///< legend labels ("core", "simbody")
  double t_begin = 0, t_end = 0;  ///< overlapping range compared
  Interpolation interpolation = Interpolation::Linear;
  RmsWeighting weighting = RmsWeighting::Trapezoid;
  std::string grid;               ///< where the grid came from: label_a, label_b or "uniform"
  std::vector<double> time;       ///< the grid (n)
  std::vector<std::string> columns;  ///< matched columns (k), in a's order
  MatX a, b;                      ///< n x k, aligned values
  Tolerance tolerance;            ///< the default tolerance (a column's own is in its metrics)
  std::vector<ColumnMetrics> metrics;  ///< k, in column order
  std::vector<std::string> only_in_a, only_in_b;  ///< unmatched columns
  std::vector<std::string> warnings;
  bool missing_columns_fail = false;
  int worst = -1;                 ///< index into metrics of the largest usage (-1 if none)
  bool passed = false;            ///< every column passed (and none missing, if that fails)

  /// metrics indices ordered from worst (largest usage; ties by rms_rel, then name) to best
  std::vector<int> rankWorstFirst() const;
};

/// Compare table a against the reference b: align (opt.align; grid_table 0 = a's rows, 1 = b's,
/// -1 = uniform), then per-column metrics. Throws CompareError (see alignTables).
Comparison compareTables(const std::string& name, const Table& a, const std::string& label_a, const Table& b,
                         const std::string& label_b, const CompareOptions& opt = {});

/// Compare two of several aligned tables: ia against the reference ib on their shared grid and
/// common columns. only_in_a / only_in_b come from the two tables' own labels; a column both have
/// but another aligned table lacks is not compared and is named in warnings. opt.align is unused.
Comparison compareAligned(const std::string& name, const AlignedTables& aligned, int ia, int ib,
                          const CompareOptions& opt = {});

}  // namespace redmax::validation
