#pragma once
// Coordinates read from a motion or states file (.mot/.sto): which column holds each coordinate's
// value (and speed), and the factor that takes it to SI. One label rule and one degree constant for
// every reader (`redmax id`, `redmax lengths`, `redmax simulate --initial`).
//
// Labels (docs/opensim_compatibility.md §1.5, §7): a column names coordinate C of joint J when its label is
//   C                          (OpenSim 3 motions, the ID tool's q splines),
//   /jointset/J/C/value        (OpenSim 4 state names), or
//   any path whose last element is C or whose last two are C/value ("C/value", "/x/C").
// OpenSim's InverseDynamicsTool builds its q splines by exact name only (§7 step 6): the ExactName
// rule keeps that, and the path labels it passes over are reported so the tool can warn.
// Degrees: in a table flagged inDegrees=yes, Rotational coordinates are multiplied by OpenSim's
// (double)(pi/180); Translational, Coupled and unknown ones are left alone (§7 step 4).
#include <string>
#include <vector>

#include "converter/model_description.hpp"
#include "converter/storage.hpp"

namespace redmax::osim {

/// OpenSim's (double)(pi/180), the factor Rotational columns of a degrees file are multiplied by
double degreesToRadians();

enum class CoordinateLabels {
  NameOrPath,  ///< the name, /jointset/J/C/value, or a path ending in C or C/value (header)
  ExactName,   ///< the name only, as OpenSim's InverseDynamicsTool matches q
};

/// OpenSim 4's absolute path of coordinate c: /jointset/<joint>/<name>
std::string coordinatePath(const CoordinateDesc& c);

/// true when `label` names coordinate c by a path (not by its bare name) under NameOrPath
bool labelIsCoordinatePath(const std::string& label, const CoordinateDesc& c);

/// The column holding c's value, -1 when none. NameOrPath prefers the exact name, then
/// /jointset/J/C/value, then the first path label that names c.
int findCoordinateColumn(const Storage& table, const CoordinateDesc& c,
                         CoordinateLabels rule = CoordinateLabels::NameOrPath);

/// The column holding c's speed: /jointset/J/C/speed, a path ending in C/speed, or C_u (OpenSim 3
/// states); -1 when none.
int findSpeedColumn(const Storage& table, const CoordinateDesc& c);

/// The factor from the table's units to SI for c's value and speed columns: degreesToRadians() for
/// a Rotational coordinate of a degrees table, else 1.
double coordinateScale(const Storage& table, const CoordinateDesc& c);

/// Every coordinate of `coordinates` matched against `table`.
struct CoordinateColumns {
  std::vector<int> value_column;  ///< per coordinate; -1 = not in the table
  std::vector<double> scale;      ///< per coordinate (coordinateScale)
  int matched = 0;                ///< coordinates with a value column
  /// labels that name a coordinate by path only, when the rule is ExactName (unused columns)
  std::vector<std::string> unused_path_labels;
};
CoordinateColumns matchCoordinateColumns(const Storage& table, const std::vector<CoordinateDesc>& coordinates,
                                         CoordinateLabels rule = CoordinateLabels::NameOrPath);

/// The coordinate vectors (core q order, SI) of every row of `table`: each coordinate's default
/// value, overwritten by its column where the table has one (NameOrPath labels, degrees converted).
/// `coordinate_index` maps description coordinates to core ones (BuildResult::coordinate_index; -1
/// = none), `nr` is the core's size. Throws ConvertError(table_file, 0, ...) when no column names a
/// coordinate.
struct CoordinateRows {
  std::vector<VecX> q;  ///< one per row
  int missing = 0;      ///< coordinates of the model without a column (held at their defaults)
};
CoordinateRows coordinateRows(const Storage& table, const std::vector<CoordinateDesc>& coordinates,
                              const std::vector<int>& coordinate_index, int nr, const std::string& table_file);

}  // namespace redmax::osim
