#pragma once
// OpenSim marker files (.trc): reading them as OpenSim's TRCFileAdapter does, in metres, with
// missing samples kept as gaps, and writing them back atomically.
//
// The format (tab-separated):
//   PathFileType  4  (X/Y/Z)  name.trc
//   DataRate CameraRate NumFrames NumMarkers Units OrigDataRate OrigDataStartFrame OrigNumFrames
//   <the eight values>
//   Frame#  Time  M1 <tab><tab>  M2 ...
//   <tab><tab>  X1  Y1  Z1  X2  Y2  Z2 ...
//   (blank lines)
//   frame  time  x y z  x y z ...
// A marker whose x, y or z field is empty (or nan) in a row has a gap there (TRCFileAdapter leaves
// it NaN); a blank line after the data ends it, as OpenSim reads it.
#include <string>
#include <vector>

#include "converter/error.hpp"
#include "core/spatial/types.hpp"

namespace redmax::osim {

struct MarkerTable {
  std::vector<std::string> markers;  ///< marker names, file order
  std::vector<double> time;          ///< one per row, strictly increasing
  std::vector<int> frame;            ///< the Frame# column
  MatX data;                         ///< rows x 3 markers: x, y, z of each (m); NaN marks a gap
  std::string units;                 ///< the header's Units ("mm", "cm" or "m"); data is in m
  double data_rate = 0.0, camera_rate = 0.0;
  int label_line = 0;                ///< the line of the marker names (0: not read from a file)
  int first_data_line = 0;           ///< the file's line of row 0
  std::vector<std::string> warnings; ///< tolerated oddities (NumFrames not the rows read)

  int numRows() const { return static_cast<int>(time.size()); }
  int numMarkers() const { return static_cast<int>(markers.size()); }
  /// index of the marker with exactly this name, or -1
  int findMarker(const std::string& name) const;
  /// false where any of the marker's three values is missing in that row
  bool present(int row, int marker) const;
  Vec3 position(int row, int marker) const { return data.block<1, 3>(row, 3 * marker).transpose(); }
  /// the rows a run over [t0, t1] needs: from the last at or before t0 to the first at or after t1
  /// (clamped to the table; 1e-12 s of slack)
  void bracketRows(double t0, double t1, int& lo, int& hi) const;
};

/// Read a .trc file. Units mm, cm and m are converted to m; any other unit is an error. Throws
/// ConvertError naming the file and line for: a first line not starting PathFileType, header keys
/// other than OpenSim's eight, a values line without eight values, a NumMarkers that is not a count
/// or disagrees with the marker names, column labels other than Frame#, Time and X1 Y1 Z1 ..., a row
/// without 2 + 3 NumMarkers fields, a field that is not a number, a time that does not increase.
MarkerTable readTrc(const std::string& path);

/// The table as a TRC file in `units` (mm or m; values converted from m): OpenSim's header lines,
/// full-precision values, an empty field for every gap.
std::string formatTrc(const MarkerTable& t, const std::string& units = "m");
/// formatTrc written atomically (temporary file, then rename)
void writeTrc(const std::string& path, const MarkerTable& t, const std::string& units = "m");

}  // namespace redmax::osim
