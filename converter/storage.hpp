#pragma once
// OpenSim Storage files (.sto, .mot): reading every header variant OpenSim reads, deciding
// degrees vs radians as OpenSim's Storage(file) does (docs/opensim_compatibility.md §1.5), and writing
// OpenSim-readable version-1 files atomically.
#include <string>
#include <utility>
#include <vector>

#include "converter/error.hpp"
#include "core/spatial/types.hpp"

namespace redmax::osim {

/// a table with a time column and named data columns
struct Storage {
  std::string name;                 ///< the header's name (first line or name=)
  int version = 0;                  ///< header version= (0 when absent)
  bool in_degrees = false;          ///< angles in degrees (see readStorage)
  std::vector<std::string> labels;  ///< data column labels; the time column is not included
  std::vector<double> time;         ///< one per row
  MatX data;                        ///< rows x labels.size()
  /// header lines other than name, version, nRows, nColumns, inDegrees and endheader,
  /// as (key, value) pairs in file order (e.g. SIMM "range", "DataType", description lines)
  std::vector<std::pair<std::string, std::string>> header;
  std::vector<std::string> warnings;  ///< tolerated oddities (OpenSim only warns on these)
  int label_line = 0;                 ///< the file's line of column labels (0: not read from a file)

  int numRows() const { return static_cast<int>(time.size()); }
  int numColumns() const { return static_cast<int>(labels.size()); }
  /// index of a data column with exactly this label, or -1
  int findColumn(const std::string& label) const;
  /// indices of the columns whose label starts with prefix, in file order
  /// (OpenSim's getColumnIndicesForIdentifier: a case-sensitive prefix match)
  std::vector<int> findColumnsWithPrefix(const std::string& prefix) const;
};

/// Read a .sto or .mot file.
/// - Header keys as OpenSim parses them: name, nr/nRows/datarows, nc/nColumns/datacolumns
///   (counting time), version, inDegrees (yes/y = degrees), "Angles are in degrees/radians."
///   (only before any version line), endheader; an unrecognized first line is the name.
/// - version <= 1 with a row or column count: the legacy reader (nRows rows of nColumns numbers,
///   white space and line breaks irrelevant); otherwise the version-2+ tab-delimited reader.
/// - Degrees: a .mot whose version is below 1 is forced to degrees; otherwise the header decides;
///   the default is radians.
/// Throws ConvertError with the file and line on malformed input.
Storage readStorage(const std::string& path);

struct StorageWriteOptions {
  int decimals = 8;         ///< OpenSim writes %16.8lf
  bool scientific = false;  ///< %.{decimals}e instead (keeps tiny values)
  std::string description;  ///< optional lines between inDegrees and endheader
};

/// Format a storage as an OpenSim version-1 file: name, version=1, nRows, nColumns (data + 1),
/// inDegrees=yes|no, description, endheader, tab-separated labels ("time" first), rows.
std::string formatStorage(const Storage& s, const StorageWriteOptions& opt = {});
/// formatStorage written atomically (temporary file, then rename)
void writeStorage(const std::string& path, const Storage& s, const StorageWriteOptions& opt = {});
/// A command's result table (`redmax id`, `lengths`, `simulate`): its folder created first, as
/// OpenSim's tools create their results directory, then writeStorage with %.16e when
/// full_precision (else OpenSim's %16.8lf) and the description lines.
void writeResultStorage(const std::string& path, const Storage& s, bool full_precision,
                        const std::string& description = "");

}  // namespace redmax::osim
