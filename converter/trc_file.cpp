// TRC marker files, restating OpenSim's TRCFileAdapter::extendRead (header checks, tab-separated
// rows of exactly 2 + 3 NumMarkers fields, an empty field a gap, a blank line ends the data) with
// errors that name the line.
#include "converter/trc_file.hpp"

#include <algorithm>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>

#include "converter/atomic_file.hpp"

namespace redmax::osim {
namespace {

const std::vector<std::string> kKeys = {"DataRate", "CameraRate", "NumFrames", "NumMarkers",
                                        "Units", "OrigDataRate", "OrigDataStartFrame", "OrigNumFrames"};
// a NumMarkers above this is not a marker count (nothing is allocated from it before the labels agree)
constexpr long kMaxMarkers = 100000;

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
  while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r')) --b;
  return s.substr(a, b - a);
}

// fields between single tabs, empty ones kept, each trimmed of spaces
std::vector<std::string> splitTabs(const std::string& s) {
  std::vector<std::string> out(1);
  for (char c : s) {
    if (c == '\t') out.emplace_back();
    else out.back() += c;
  }
  for (auto& f : out) f = trim(f);
  return out;
}

// words between runs of white space
std::vector<std::string> splitWords(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == ' ' || c == '\t' || c == '\r') {
      if (!cur.empty()) out.push_back(cur), cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

std::vector<std::string> nonEmpty(const std::vector<std::string>& v) {
  std::vector<std::string> out;
  for (const auto& s : v)
    if (!s.empty()) out.push_back(s);
  return out;
}

bool parseNumber(const std::string& w, double& x) {
  if (w == "nan" || w == "NaN" || w == "-nan" || w == "NAN") return x = std::numeric_limits<double>::quiet_NaN(), true;
  char* end = nullptr;
  errno = 0;
  x = std::strtod(w.c_str(), &end);
  return !w.empty() && end != w.c_str() && *end == '\0' && errno != ERANGE;
}

}  // namespace

int MarkerTable::findMarker(const std::string& name) const {
  for (size_t i = 0; i < markers.size(); ++i)
    if (markers[i] == name) return static_cast<int>(i);
  return -1;
}

bool MarkerTable::present(int row, int marker) const {
  return std::isfinite(data(row, 3 * marker)) && std::isfinite(data(row, 3 * marker + 1)) &&
         std::isfinite(data(row, 3 * marker + 2));
}

void MarkerTable::bracketRows(double t0, double t1, int& lo, int& hi) const {
  const int n = numRows();
  lo = 0;
  hi = n - 1;
  while (lo + 1 < n && time[lo + 1] <= t0 + 1e-12) ++lo;
  while (hi - 1 >= 0 && time[hi - 1] >= t1 - 1e-12) --hi;
  hi = std::max(hi, lo);
}

MarkerTable readTrc(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConvertError(path, 0, "cannot open file");
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    lines.push_back(l);
  }
  auto fail = [&](int line, const std::string& what) { throw ConvertError(path, line, what); };
  if (lines.empty() || trim(lines[0]).empty()) fail(1, "empty file: not a TRC marker file");
  if (splitWords(lines[0]).front() != "PathFileType")
    fail(1, "the first line does not start with PathFileType: not a TRC marker file");
  if (lines.size() < 5) fail(static_cast<int>(lines.size()), "the file ends inside the TRC header (5 lines)");

  // line 2: the eight keys; line 3: their values
  const std::vector<std::string> keys = splitWords(lines[1]);
  if (keys != kKeys) {
    std::string want;
    for (const auto& k : kKeys) want += (want.empty() ? "" : " ") + k;
    fail(2, "header keys must be '" + want + "', found '" + trim(lines[1]) + "'");
  }
  const std::vector<std::string> values = splitWords(lines[2]);
  if (values.size() != kKeys.size())
    fail(3, "the header values line has " + std::to_string(values.size()) + " values for the " +
                std::to_string(kKeys.size()) + " keys of line 2");
  MarkerTable t;
  auto count = [&](const std::string& key, const std::string& v) {
    char* end = nullptr;
    errno = 0;
    const long x = std::strtol(v.c_str(), &end, 10);
    if (end == v.c_str() || *end != '\0' || errno == ERANGE || x < 0 || x > kMaxMarkers * 1000)
      fail(3, key + " must be a non-negative count, found '" + v + "'");
    return x;
  };
  auto rate = [&](const std::string& key, const std::string& v) {
    double x = 0.0;
    if (!parseNumber(v, x) || !std::isfinite(x)) fail(3, key + " must be a number, found '" + v + "'");
    return x;
  };
  t.data_rate = rate("DataRate", values[0]);
  t.camera_rate = rate("CameraRate", values[1]);
  const long num_frames = count("NumFrames", values[2]);
  const long num_markers = count("NumMarkers", values[3]);
  if (num_markers > kMaxMarkers)
    fail(3, "NumMarkers=" + values[3] + " is more than " + std::to_string(kMaxMarkers) + " markers");
  t.units = values[4];
  double scale = 1.0;
  if (t.units == "mm") scale = 1e-3;
  else if (t.units == "cm") scale = 1e-2;
  else if (t.units != "m") fail(3, "Units must be mm, cm or m, found '" + t.units + "'");

  // line 4: Frame# Time and the marker names (the blank fields of the uniform tabbing dropped)
  t.label_line = 4;
  const std::vector<std::string> labels = nonEmpty(splitTabs(lines[3]));
  if (labels.size() < 2 || labels[0] != "Frame#" || labels[1] != "Time")
    fail(4, "the column labels must start with Frame# and Time, found '" + trim(lines[3]) + "'");
  if (static_cast<long>(labels.size()) - 2 != num_markers)
    fail(4, "NumMarkers=" + std::to_string(num_markers) + " but the label line names " +
                std::to_string(labels.size() - 2) + " markers");
  t.markers.assign(labels.begin() + 2, labels.end());
  for (size_t i = 0; i < t.markers.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (t.markers[i] == t.markers[j]) fail(4, "marker '" + t.markers[i] + "' is named twice");
  // line 5: X1 Y1 Z1 X2 ...
  const std::vector<std::string> xyz = nonEmpty(splitTabs(lines[4]));
  if (static_cast<long>(xyz.size()) < 3 * num_markers)
    fail(5, "the component labels line has " + std::to_string(xyz.size()) + " labels, expected X1 Y1 Z1 ... for " +
                std::to_string(num_markers) + " markers");
  for (long i = 0; i < num_markers; ++i)
    for (int k = 0; k < 3; ++k) {
      const std::string want = std::string(1, "XYZ"[k]) + std::to_string(i + 1);
      if (xyz[static_cast<size_t>(3 * i + k)] != want)
        fail(5, "component label " + std::to_string(3 * i + k + 1) + " must be '" + want + "', found '" +
                    xyz[static_cast<size_t>(3 * i + k)] + "'");
    }

  // rows: blank lines before the data are skipped, a blank line after it ends it
  size_t li = 5;
  while (li < lines.size() && trim(lines[li]).empty()) ++li;
  t.first_data_line = static_cast<int>(li + 1);
  const size_t expected = static_cast<size_t>(2 + 3 * num_markers);
  std::vector<double> values_read;  // row-major, expected per row
  for (; li < lines.size(); ++li) {
    const int line = static_cast<int>(li + 1);
    if (trim(lines[li]).empty()) {
      for (size_t rest = li + 1; rest < lines.size(); ++rest)
        if (!trim(lines[rest]).empty()) {
          t.warnings.push_back(path + ": the data ends at the blank line " + std::to_string(line) +
                               "; the lines after it are ignored (as OpenSim reads TRC files)");
          break;
        }
      break;
    }
    std::vector<std::string> f = splitTabs(lines[li]);
    if (f.size() == 1) f = splitWords(lines[li]);  // a space-separated file
    // the trailing tab OpenSim writes after the last Z
    while (f.size() > expected && f.back().empty()) f.pop_back();
    if (f.size() != expected)
      fail(line, "row has " + std::to_string(f.size()) + " fields, expected " + std::to_string(expected) +
                     " (Frame#, Time and X Y Z of " + std::to_string(num_markers) + " markers)");
    double frame = 0.0, time = 0.0;
    if (!parseNumber(f[0], frame) || !std::isfinite(frame)) fail(line, "Frame# '" + f[0] + "' is not a number");
    if (!parseNumber(f[1], time) || !std::isfinite(time)) fail(line, "time '" + f[1] + "' is not a finite number");
    if (!t.time.empty() && !(time > t.time.back()))
      fail(line, "time " + f[1] + " does not increase (the previous row is at " + std::to_string(t.time.back()) + ")");
    for (size_t c = 2; c < expected; ++c) {
      double x = std::numeric_limits<double>::quiet_NaN();
      if (!f[c].empty() && !parseNumber(f[c], x))
        fail(line, "'" + f[c] + "' (marker '" + t.markers[(c - 2) / 3] + "') is not a number");
      if (std::isinf(x)) fail(line, "marker '" + t.markers[(c - 2) / 3] + "' has an infinite value");
      values_read.push_back(x * scale);
    }
    t.time.push_back(time);
    t.frame.push_back(static_cast<int>(std::lround(frame)));
  }
  if (t.time.empty()) fail(static_cast<int>(li), "no data rows after the header");
  if (num_frames != t.numRows())
    t.warnings.push_back(path + ": NumFrames=" + std::to_string(num_frames) + " but " +
                         std::to_string(t.numRows()) + " rows were read");
  const Eigen::Index rows = t.numRows(), cols = 3 * num_markers;
  t.data.resize(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r)
    for (Eigen::Index c = 0; c < cols; ++c) t.data(r, c) = values_read[static_cast<size_t>(r * cols + c)];
  return t;
}

std::string formatTrc(const MarkerTable& t, const std::string& units) {
  double scale = 1.0;
  if (units == "mm") scale = 1e3;
  else if (units != "m") throw ConvertError("(trc)", 0, "formatTrc: units must be mm or m, not '" + units + "'");
  const int rows = t.numRows(), n = t.numMarkers();
  if (t.data.rows() != rows || t.data.cols() != 3 * n)
    throw ConvertError("(trc)", 0, "inconsistent marker table: " + std::to_string(rows) + " times, " +
                                       std::to_string(n) + " markers, data " + std::to_string(t.data.rows()) +
                                       "x" + std::to_string(t.data.cols()));
  char buf[64];
  auto num = [&](double x) {
    std::snprintf(buf, sizeof buf, "%.17g", x);
    return std::string(buf);
  };
  double rate = t.data_rate;
  if (!(rate > 0.0) && rows > 1) rate = (rows - 1) / (t.time.back() - t.time.front());
  const double camera = t.camera_rate > 0.0 ? t.camera_rate : rate;
  std::string out = "PathFileType\t4\t(X/Y/Z)\tredmax.trc\n";
  for (size_t k = 0; k < kKeys.size(); ++k) out += (k ? "\t" : "") + kKeys[k];
  out += "\n" + num(rate) + "\t" + num(camera) + "\t" + std::to_string(rows) + "\t" + std::to_string(n) + "\t" +
         units + "\t" + num(rate) + "\t" + std::to_string(t.frame.empty() ? 1 : t.frame.front()) + "\t" +
         std::to_string(rows) + "\n";
  out += "Frame#\tTime";
  for (const auto& m : t.markers) out += "\t" + m + "\t\t";
  out += "\n\t";
  for (int i = 1; i <= n; ++i) out += "\tX" + std::to_string(i) + "\tY" + std::to_string(i) + "\tZ" + std::to_string(i);
  out += "\n\n";
  for (int r = 0; r < rows; ++r) {
    out += std::to_string(static_cast<int>(t.frame.size()) == rows ? t.frame[r] : r + 1) + "\t" + num(t.time[r]);
    for (int c = 0; c < 3 * n; ++c) {
      out += "\t";
      if (std::isfinite(t.data(r, c))) out += num(t.data(r, c) * scale);
    }
    out += "\n";
  }
  return out;
}

void writeTrc(const std::string& path, const MarkerTable& t, const std::string& units) {
  writeFileAtomic(path, formatTrc(t, units));
}

}  // namespace redmax::osim
