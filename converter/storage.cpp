// Storage (.sto/.mot) reading and writing, restating OpenSim's Storage(file) and printResult
// behaviour (docs/opensim_compatibility.md §1.5).
#include "converter/storage.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "converter/atomic_file.hpp"

namespace redmax::osim {
namespace {

std::string trimWs(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> splitAny(const std::string& s, const char* seps) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (std::strchr(seps, c)) {
      if (!cur.empty()) out.push_back(cur), cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

bool parseDouble(const std::string& w, double& x) {
  const std::string l = lower(w);
  if (l == "nan" || l == "-nan") return x = std::numeric_limits<double>::quiet_NaN(), true;
  if (l == "inf" || l == "infinity") return x = std::numeric_limits<double>::infinity(), true;
  if (l == "-inf" || l == "-infinity") return x = -std::numeric_limits<double>::infinity(), true;
  char* end = nullptr;
  errno = 0;
  x = std::strtod(w.c_str(), &end);
  return end != w.c_str() && *end == '\0' && errno != ERANGE;
}

}  // namespace

int Storage::findColumn(const std::string& label) const {
  for (size_t i = 0; i < labels.size(); ++i)
    if (labels[i] == label) return static_cast<int>(i);
  return -1;
}

std::vector<int> Storage::findColumnsWithPrefix(const std::string& prefix) const {
  std::vector<int> out;
  if (prefix.empty()) return out;
  for (size_t i = 0; i < labels.size(); ++i)
    if (labels[i].compare(0, prefix.size(), prefix) == 0) out.push_back(static_cast<int>(i));
  return out;
}

Storage readStorage(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConvertError(path, 0, "cannot open file");
  const std::string lpath = lower(path);
  const bool is_mot = lpath.rfind(".mot") != std::string::npos;
  const bool is_sto = lpath.rfind(".sto") != std::string::npos;
  if (!is_mot && !is_sto)
    throw ConvertError(path, 0, "not a .sto or .mot file (OpenSim reads others with file adapters)");

  // all lines, so that errors can name them
  std::vector<std::string> lines;
  {
    std::string l;
    while (std::getline(in, l)) {
      if (!l.empty() && l.back() == '\r') l.pop_back();
      lines.push_back(l);
    }
  }

  // ---- header (Storage::parseHeaders) ----
  Storage s;
  int nr = 0, nc = 0;
  bool first = true, end_found = false;
  size_t li = 0;
  for (; li < lines.size(); ++li) {
    const std::string line = trimWs(lines[li]);
    if (line.empty()) continue;
    const size_t delim = line.find_first_of(" \t=");
    const std::string key = line.substr(0, delim);
    const size_t restidx = delim == std::string::npos ? delim : line.find_first_not_of(" \t=", delim);
    const std::string rest = restidx == std::string::npos ? "" : line.substr(restidx);
    auto count = [&](int& v) {
      char* end = nullptr;
      const long x = std::strtol(rest.c_str(), &end, 10);
      if (end == rest.c_str() || x < 0 || x > 100000000)
        throw ConvertError(path, static_cast<int>(li + 1),
                           "header '" + key + "' needs a non-negative count, found '" + rest + "'");
      v = static_cast<int>(x);
    };
    if (key == "endheader") {
      end_found = true;
      break;
    } else if (key == "name") {
      s.name = rest;
    } else if (key == "nr" || key == "nRows" || key == "datarows") {
      count(nr);
    } else if (key == "nc" || key == "nColumns" || key == "datacolumns") {
      count(nc);
    } else if (key == "version") {
      s.version = std::atoi(rest.c_str());
    } else if (key == "inDegrees") {
      const std::string v = lower(rest);
      s.in_degrees = v == "yes" || v == "y";
    } else if (key == "Angles" && s.version == 0) {
      if (line == "Angles are in degrees.") s.in_degrees = true;
      else if (line == "Angles are in radians.") s.in_degrees = false;
    } else {
      if (first) s.name = line;  // an unrecognized first line is the storage's name
      s.header.emplace_back(key, rest);
    }
    first = false;
  }
  if (!end_found)
    throw ConvertError(path, static_cast<int>(lines.size()),
                       "no 'endheader' line: not an OpenSim storage file");
  ++li;  // past endheader

  // ---- data ----
  if (s.version <= 1) {
    if (nr < 1 && nc < 1)
      throw ConvertError(path, static_cast<int>(li),
                         "header gives neither nRows nor nColumns (needed for version<=1 files)");
    // blank lines after the header are skipped, then one line of labels
    while (li < lines.size() && trimWs(lines[li]).empty()) ++li;
    if (li >= lines.size())
      throw ConvertError(path, static_cast<int>(li), "no column labels after endheader");
    const int label_line = static_cast<int>(li + 1);
    s.label_line = label_line;
    std::vector<std::string> labels = splitAny(lines[li], " \t\r\n");
    ++li;
    if (nc >= 1 && static_cast<int>(labels.size()) != nc)
      throw ConvertError(path, label_line,
                         "nColumns=" + std::to_string(nc) + " but the label line has " +
                             std::to_string(labels.size()) + " labels");
    const int ncol = static_cast<int>(labels.size());
    if (ncol < 1) throw ConvertError(path, label_line, "empty column-label line");
    bool has_time = false;
    for (const auto& l : labels) has_time = has_time || l == "time" || l == "range";
    // numbers flow across lines: read nRows rows of nColumns values
    std::vector<double> values;
    int last_line = label_line;
    for (; li < lines.size(); ++li) {
      for (const auto& w : splitAny(lines[li], " \t\r\n")) {
        double x;
        if (!parseDouble(w, x))
          throw ConvertError(path, static_cast<int>(li + 1), "'" + w + "' is not a number");
        if (nr >= 1 && static_cast<long long>(values.size()) == static_cast<long long>(nr) * ncol) {
          s.warnings.push_back("data after the " + std::to_string(nr) +
                               " rows announced by nRows are ignored (line " +
                               std::to_string(li + 1) + ")");
          li = lines.size();
          break;
        }
        values.push_back(x);
        last_line = static_cast<int>(li + 1);
      }
    }
    if (nr >= 1 && static_cast<long long>(values.size()) < static_cast<long long>(nr) * ncol)
      throw ConvertError(path, last_line,
                         "nRows=" + std::to_string(nr) + " rows of " + std::to_string(ncol) +
                             " values announced but the data ends after " +
                             std::to_string(values.size()) + " values");
    if (nr < 1) {
      if (values.size() % ncol != 0)
        throw ConvertError(path, last_line,
                           "the data is not a whole number of rows of " + std::to_string(ncol) +
                               " values");
      s.warnings.push_back("no nRows in the header: all rows until the end of file are read");
    }
    const int rows = static_cast<int>(values.size()) / ncol;
    if (has_time) {
      // the first column is the time, whatever its label (Storage's legacy reader)
      s.labels.assign(labels.begin() + 1, labels.end());
      s.data.resize(rows, ncol - 1);
      // a row whose time equals the previous row's replaces it (Storage::append's duplicate-time
      // check, on by default, which Storage(file) reads through)
      int kept = 0, replaced = 0;
      for (int r = 0; r < rows; ++r) {
        const double t = values[static_cast<size_t>(r) * ncol];
        int at = kept;
        if (kept > 0 && s.time.back() == t) {
          at = kept - 1;
          ++replaced;
        } else {
          s.time.push_back(t);
          ++kept;
        }
        for (int c = 1; c < ncol; ++c) s.data(at, c - 1) = values[static_cast<size_t>(r) * ncol + c];
      }
      if (replaced > 0) {
        s.data.conservativeResize(kept, ncol - 1);
        s.warnings.push_back(std::to_string(replaced) + " row(s) repeat the previous row's time; each replaces that "
                             "row, as OpenSim's Storage reads them");
      }
    } else {
      // SIMM motion without a time column: uniform times from "range t0 t1", else row numbers
      s.labels = labels;
      s.data.resize(rows, ncol);
      double t0 = 0.0, t1 = rows > 1 ? rows - 1.0 : 0.0;
      bool have_range = false;
      for (const auto& [k, v] : s.header)
        if (k == "range") {
          const auto w = splitAny(v, " \t");
          if (w.size() >= 2 && parseDouble(w[0], t0) && parseDouble(w[1], t1)) have_range = true;
        }
      for (int r = 0; r < rows; ++r) {
        s.time.push_back(have_range ? (rows > 1 ? t0 + (t1 - t0) * r / (rows - 1) : t0) : r);
        for (int c = 0; c < ncol; ++c) s.data(r, c) = values[static_cast<size_t>(r) * ncol + c];
      }
      s.warnings.push_back(std::string("no time column: times ") +
                           (have_range ? "spread uniformly over the header's range"
                                       : "are the row numbers"));
    }
    // SIMM .mot files (no version line) are in degrees (Storage(file))
    if (s.version < 1 && is_mot) s.in_degrees = true;
  } else {
    // version 2+: tab-delimited table (STOFileAdapter); the first column is time
    for (const auto& [k, v] : s.header)
      if (k == "DataType" && v != "double")
        throw ConvertError(path, 0, "DataType=" + v + " tables are not supported (only double)");
    while (li < lines.size() && trimWs(lines[li]).empty()) ++li;
    if (li >= lines.size())
      throw ConvertError(path, static_cast<int>(li), "no column labels after endheader");
    const int label_line = static_cast<int>(li + 1);
    s.label_line = label_line;
    std::vector<std::string> labels = splitAny(lines[li], "\t");
    for (auto& l : labels) l = trimWs(l);
    if (labels.size() == 1) labels = splitAny(lines[li], " \t");
    ++li;
    const int ncol = static_cast<int>(labels.size());
    if (ncol < 1) throw ConvertError(path, label_line, "empty column-label line");
    s.labels.assign(labels.begin() + 1, labels.end());
    std::vector<std::vector<double>> rows;
    for (; li < lines.size(); ++li) {
      if (trimWs(lines[li]).empty()) continue;
      const auto words = splitAny(lines[li], " \t");
      if (static_cast<int>(words.size()) != ncol)
        throw ConvertError(path, static_cast<int>(li + 1),
                           "row has " + std::to_string(words.size()) + " values but there are " +
                               std::to_string(ncol) + " column labels");
      std::vector<double> row(ncol);
      for (int c = 0; c < ncol; ++c)
        if (!parseDouble(words[c], row[c]))
          throw ConvertError(path, static_cast<int>(li + 1), "'" + words[c] + "' is not a number");
      rows.push_back(std::move(row));
    }
    if (nr >= 1 && static_cast<int>(rows.size()) != nr)
      s.warnings.push_back("nRows=" + std::to_string(nr) + " but " + std::to_string(rows.size()) +
                           " rows were read");
    s.data.resize(static_cast<Eigen::Index>(rows.size()), ncol - 1);
    for (size_t r = 0; r < rows.size(); ++r) {
      s.time.push_back(rows[r][0]);
      for (int c = 1; c < ncol; ++c) s.data(static_cast<Eigen::Index>(r), c - 1) = rows[r][c];
    }
  }
  return s;
}

std::string formatStorage(const Storage& s, const StorageWriteOptions& opt) {
  if (static_cast<Eigen::Index>(s.time.size()) != s.data.rows() ||
      static_cast<Eigen::Index>(s.labels.size()) != s.data.cols())
    throw ConvertError(s.name.empty() ? "(storage)" : s.name, 0,
                       "inconsistent storage: " + std::to_string(s.time.size()) + " times, " +
                           std::to_string(s.labels.size()) + " labels, data " +
                           std::to_string(s.data.rows()) + "x" + std::to_string(s.data.cols()));
  std::string out;
  out += (s.name.empty() ? std::string("redmax") : s.name) + "\n";
  out += "version=1\n";
  out += "nRows=" + std::to_string(s.time.size()) + "\n";
  out += "nColumns=" + std::to_string(s.labels.size() + 1) + "\n";
  out += std::string("inDegrees=") + (s.in_degrees ? "yes" : "no") + "\n";
  if (!opt.description.empty()) {
    out += opt.description;
    if (out.back() != '\n') out += "\n";
  }
  out += "endheader\ntime";
  for (const auto& l : s.labels) out += "\t" + l;
  out += "\n";
  char fmt[32];
  std::snprintf(fmt, sizeof fmt, opt.scientific ? "%%16.%de" : "%%16.%dlf", opt.decimals);
  char buf[128];
  for (size_t r = 0; r < s.time.size(); ++r) {
    std::snprintf(buf, sizeof buf, fmt, s.time[r]);
    out += buf;
    for (Eigen::Index c = 0; c < s.data.cols(); ++c) {
      std::snprintf(buf, sizeof buf, fmt, s.data(static_cast<Eigen::Index>(r), c));
      out += "\t";
      out += buf;
    }
    out += "\n";
  }
  return out;
}

void writeStorage(const std::string& path, const Storage& s, const StorageWriteOptions& opt) {
  writeFileAtomic(path, formatStorage(s, opt));
}

void writeResultStorage(const std::string& path, const Storage& s, bool full_precision,
                        const std::string& description) {
  // a folder that cannot be made shows up as the write's error, with the file named
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  StorageWriteOptions wo;
  if (full_precision) {
    wo.scientific = true;
    wo.decimals = 16;
  }
  wo.description = description;
  writeStorage(path, s, wo);
}

}  // namespace redmax::osim
