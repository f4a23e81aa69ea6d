#pragma once
// Time-series tables on a common grid: column matching by name, the overlapping time range, and
// interpolation of every table onto one set of times. This is the first half of a comparison
// (metrics.hpp is the second); it is pure (no I/O) and engine-agnostic.
//
// The table type is the converter's osim::Storage, the in-memory form of a .sto/.mot file, so an
// OpenSim reference read with osim::readStorage and an engine's result compare without copying.
// Columns are matched BY NAME, never by position: OpenSim 3.x and 4.x order the same inverse
// dynamics columns differently, and a result may have columns the reference lacks.
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "converter/storage.hpp"
#include "core/spatial/types.hpp"

namespace redmax::validation {

/// A table: time column (one entry per row), data column labels, data (rows x labels).
using Table = osim::Storage;

/// Bad input to a comparison: no common column, no overlapping times, times that are not finite
/// or do not increase, mismatched sizes. These are input errors (the command line exits with 2).
class CompareError : public std::invalid_argument {
 public:
  explicit CompareError(const std::string& message) : std::invalid_argument(message) {}
};

/// Build a table. data is time.size() x labels.size(); throws CompareError on a size mismatch.
Table makeTable(std::string name, std::vector<std::string> labels, std::vector<double> time, MatX data);

/// How a table is evaluated between its rows.
enum class Interpolation {
  Linear,       ///< piecewise linear between rows (exact at the rows)
  NaturalCubic  ///< natural interpolating cubic spline (converter/signal/natural_spline.hpp)
};
/// "linear" or "cubic"
std::string toString(Interpolation interp);
/// Parse "linear" or "cubic" (also "natural_cubic", "spline"); throws CompareError otherwise.
Interpolation parseInterpolation(const std::string& text);

/// Throws CompareError (naming `what` and the row) unless the table has at least one row, every
/// time is finite and times strictly increase, and data has rows x labels entries.
void checkTable(const Table& table, const std::string& what);

/// Values of one column at the times t_query.
/// time: strictly increasing sample times (n >= 1); values: n samples (non-finite values allowed:
/// with Linear they spoil only the two intervals around them). Queries outside [time.front(),
/// time.back()] take the end value (the caller keeps them within a small tolerance of the range).
/// At a sample time the sample itself is returned exactly. NaturalCubic needs n >= 4 and finite
/// values; otherwise Linear is used and *fell_back (if given) is set to true.
std::vector<double> interpolateColumn(const std::vector<double>& time, const std::vector<double>& values,
                                      const std::vector<double>& t_query, Interpolation interp,
                                      bool* fell_back = nullptr);

/// Column matching over several tables, by exact label.
struct ColumnMatch {
  std::vector<std::string> common;             ///< labels in every table, in the first table's order
  std::vector<std::vector<int>> index;         ///< [table][k]: column of common[k] in that table
  std::vector<std::vector<std::string>> missing;  ///< [table]: labels of other tables absent from it
  std::vector<std::string> warnings;           ///< duplicate labels (the first occurrence is used)
};
/// Match the columns of the given tables (at least one) by exact label.
ColumnMatch matchColumns(const std::vector<const Table*>& tables);

/// Where the common grid comes from.
struct AlignOptions {
  Interpolation interpolation = Interpolation::Linear;
  /// the table whose rows inside the overlap form the grid (0 = the first); -1: a uniform grid of
  /// uniform_samples points over the overlap (every table is then interpolated)
  int grid_table = 0;
  int uniform_samples = 0;
  /// an optional window [t0, t1] that further restricts the overlapping range
  double t0 = -std::numeric_limits<double>::infinity();
  double t1 = std::numeric_limits<double>::infinity();
  /// rows this close [s] outside the overlap still count as inside it: OpenSim files print time
  /// with 8 decimals, so the ends of two files of the same trial can differ by ~5e-9 s
  double time_tolerance = 1e-6;
};

/// Several tables evaluated at one set of times, on their common columns.
struct AlignedTables {
  std::vector<std::string> names;    ///< one per table (legend labels: "core", "simbody", "opensim")
  std::vector<std::vector<std::string>> labels;  ///< [table]: all its data labels, as read
  ColumnMatch match;                 ///< match.common are the columns of values
  double t_begin = 0, t_end = 0;     ///< the overlapping range (after the window)
  std::vector<double> time;          ///< the grid, increasing (n)
  std::vector<MatX> values;          ///< [table]: n x match.common.size()
  Interpolation interpolation = Interpolation::Linear;
  int grid_table = 0;                ///< as in AlignOptions
  std::vector<std::string> warnings; ///< e.g. a cubic fit that fell back to linear
  const std::vector<std::string>& columns() const { return match.common; }
};

/// Align tables (names.size() == tables.size() >= 1) on their common columns over the range all
/// of them cover: t_begin = max of first times, t_end = min of last times (and the window).
/// Throws CompareError when a table is malformed (checkTable), no column is common, the ranges
/// do not overlap, or the grid has no point.
AlignedTables alignTables(const std::vector<const Table*>& tables, const std::vector<std::string>& names,
                          const AlignOptions& opt = {});

}  // namespace redmax::validation
