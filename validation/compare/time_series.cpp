#include "validation/compare/time_series.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "converter/signal/natural_spline.hpp"

namespace redmax::validation {

Table makeTable(std::string name, std::vector<std::string> labels, std::vector<double> time, MatX data) {
  if (data.rows() != static_cast<Eigen::Index>(time.size()) ||
      data.cols() != static_cast<Eigen::Index>(labels.size())) {
    std::ostringstream m;
    m << "table '" << name << "': data is " << data.rows() << " x " << data.cols() << " but there are "
      << time.size() << " times and " << labels.size() << " labels";
    throw CompareError(m.str());
  }
  Table t;
  t.name = std::move(name);
  t.labels = std::move(labels);
  t.time = std::move(time);
  t.data = std::move(data);
  return t;
}

std::string toString(Interpolation interp) {
  return interp == Interpolation::Linear ? "linear" : "cubic";
}

Interpolation parseInterpolation(const std::string& text) {
  if (text == "linear") return Interpolation::Linear;
  if (text == "cubic" || text == "natural_cubic" || text == "spline") return Interpolation::NaturalCubic;
  throw CompareError("unknown interpolation '" + text + "' (expected linear or cubic)");
}

void checkTable(const Table& table, const std::string& what) {
  const auto n = table.time.size();
  if (n == 0) throw CompareError(what + ": the table has no rows");
  if (table.data.rows() != static_cast<Eigen::Index>(n) ||
      table.data.cols() != static_cast<Eigen::Index>(table.labels.size())) {
    std::ostringstream m;
    m << what << ": data is " << table.data.rows() << " x " << table.data.cols() << " but there are " << n
      << " times and " << table.labels.size() << " labels";
    throw CompareError(m.str());
  }
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(table.time[i])) {
      throw CompareError(what + ": time of row " + std::to_string(i + 1) + " is not finite");
    }
    if (i > 0 && !(table.time[i] > table.time[i - 1])) {
      std::ostringstream m;
      m.precision(17);
      m << what << ": times must increase, but row " << i + 1 << " has t = " << table.time[i]
        << " after t = " << table.time[i - 1];
      throw CompareError(m.str());
    }
  }
}

namespace {

// linear interpolation, exact at the samples (no y0 + (y1 - y0) * 1 round-off at the right end)
double lerpAt(const std::vector<double>& time, const std::vector<double>& y, double t) {
  const size_t n = time.size();
  if (n == 1 || t <= time.front()) return y.front();
  if (t >= time.back()) return y.back();
  const size_t i = static_cast<size_t>(std::upper_bound(time.begin(), time.end(), t) - time.begin()) - 1;
  if (time[i] == t) return y[i];
  const double s = (t - time[i]) / (time[i + 1] - time[i]);
  return y[i] + s * (y[i + 1] - y[i]);
}

}  // namespace

std::vector<double> interpolateColumn(const std::vector<double>& time, const std::vector<double>& values,
                                      const std::vector<double>& t_query, Interpolation interp,
                                      bool* fell_back) {
  if (time.empty() || time.size() != values.size()) {
    throw CompareError("interpolateColumn: " + std::to_string(time.size()) + " times but " +
                       std::to_string(values.size()) + " values");
  }
  std::vector<double> out(t_query.size());
  if (interp == Interpolation::NaturalCubic) {
    // a natural cubic needs 4 points (as GCVSPL does) and finite data; otherwise linear
    const bool finite = std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
    if (time.size() >= 4 && finite) {
      const signal::NaturalSpline s(3, time, values);
      for (size_t k = 0; k < t_query.size(); ++k) {
        // clamp like the linear case: no extrapolation beyond the data
        const double t = std::clamp(t_query[k], time.front(), time.back());
        const auto hit = std::lower_bound(time.begin(), time.end(), t);
        out[k] = (hit != time.end() && *hit == t) ? values[hit - time.begin()] : s.calcValue(t);
      }
      return out;
    }
    if (fell_back) *fell_back = true;
  }
  for (size_t k = 0; k < t_query.size(); ++k) out[k] = lerpAt(time, values, t_query[k]);
  return out;
}

ColumnMatch matchColumns(const std::vector<const Table*>& tables) {
  if (tables.empty()) throw CompareError("matchColumns: no table");
  const size_t nt = tables.size();
  ColumnMatch m;
  m.index.resize(nt);
  m.missing.resize(nt);
  // label -> first column index, per table (duplicates warned about, first one used)
  std::vector<std::map<std::string, int>> where(nt);
  for (size_t t = 0; t < nt; ++t) {
    const auto& labels = tables[t]->labels;
    for (size_t c = 0; c < labels.size(); ++c) {
      if (!where[t].emplace(labels[c], static_cast<int>(c)).second) {
        m.warnings.push_back("table '" + tables[t]->name + "': column '" + labels[c] +
                             "' appears more than once; the first is used");
      }
    }
  }
  // common labels in the first table's order
  for (const auto& label : tables[0]->labels) {
    if (where[0].at(label) != static_cast<int>(&label - tables[0]->labels.data())) continue;  // duplicate
    bool everywhere = true;
    for (size_t t = 1; t < nt && everywhere; ++t) everywhere = where[t].count(label) > 0;
    if (!everywhere) continue;
    m.common.push_back(label);
    for (size_t t = 0; t < nt; ++t) m.index[t].push_back(where[t].at(label));
  }
  // per table, labels seen in some other table but not in this one (first-seen order)
  for (size_t t = 0; t < nt; ++t) {
    std::set<std::string> seen;
    for (size_t o = 0; o < nt; ++o) {
      if (o == t) continue;
      for (const auto& label : tables[o]->labels) {
        if (where[t].count(label) || !seen.insert(label).second) continue;
        m.missing[t].push_back(label);
      }
    }
  }
  return m;
}

AlignedTables alignTables(const std::vector<const Table*>& tables, const std::vector<std::string>& names,
                          const AlignOptions& opt) {
  if (tables.empty()) throw CompareError("alignTables: no table");
  if (names.size() != tables.size()) throw CompareError("alignTables: one name per table is needed");
  for (size_t t = 0; t < tables.size(); ++t) {
    if (!tables[t]) throw CompareError("alignTables: null table");
    checkTable(*tables[t], "table '" + names[t] + "'");
  }
  const int nt = static_cast<int>(tables.size());
  if (opt.grid_table < -1 || opt.grid_table >= nt) {
    throw CompareError("alignTables: grid_table " + std::to_string(opt.grid_table) + " is not a table index");
  }
  if (opt.grid_table == -1 && opt.uniform_samples < 1) {
    throw CompareError("alignTables: a uniform grid needs uniform_samples >= 1");
  }
  if (!(opt.time_tolerance >= 0)) throw CompareError("alignTables: time_tolerance must be >= 0");

  AlignedTables out;
  out.names = names;
  for (const auto* t : tables) out.labels.push_back(t->labels);
  out.interpolation = opt.interpolation;
  out.grid_table = opt.grid_table;
  out.match = matchColumns(tables);
  out.warnings = out.match.warnings;
  if (out.match.common.empty()) {
    std::string msg = "no column is common to";
    for (const auto& n : names) msg += " '" + n + "'";
    throw CompareError(msg + " (columns are matched by exact name)");
  }

  // overlapping range: every table covers [t_begin, t_end]
  double lo = opt.t0, hi = opt.t1;
  for (const auto* t : tables) {
    lo = std::max(lo, t->time.front());
    hi = std::min(hi, t->time.back());
  }
  const double eps = opt.time_tolerance;
  if (!(hi >= lo - eps)) {
    std::ostringstream m;
    m.precision(10);
    m << "the time ranges do not overlap:";
    for (int t = 0; t < nt; ++t) {
      m << " '" << names[t] << "' [" << tables[t]->time.front() << ", " << tables[t]->time.back() << "]";
    }
    if (std::isfinite(opt.t0) || std::isfinite(opt.t1)) m << ", window [" << opt.t0 << ", " << opt.t1 << "]";
    throw CompareError(m.str());
  }
  if (hi < lo) hi = lo;  // ends within the tolerance: one instant
  out.t_begin = lo;
  out.t_end = hi;

  // the grid: a table's rows inside the (tolerance-widened) range, or uniform
  if (opt.grid_table >= 0) {
    for (double t : tables[opt.grid_table]->time) {
      if (t >= lo - eps && t <= hi + eps) out.time.push_back(t);
    }
  } else {
    const int n = opt.uniform_samples;
    for (int k = 0; k < n; ++k) out.time.push_back(n == 1 ? lo : lo + (hi - lo) * k / (n - 1));
    if (n > 1) out.time.back() = hi;
  }
  if (out.time.empty()) {
    throw CompareError("table '" + names[opt.grid_table] + "' has no row inside the overlapping time range");
  }

  // each common column of each table on the grid (the grid table's own rows are copied exactly)
  const size_t nc = out.match.common.size(), n = out.time.size();
  out.values.resize(nt);
  for (int t = 0; t < nt; ++t) {
    const Table& tab = *tables[t];
    out.values[t].resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(nc));
    for (size_t k = 0; k < nc; ++k) {
      const int c = out.match.index[t][k];
      std::vector<double> col(tab.time.size());
      for (size_t r = 0; r < col.size(); ++r) col[r] = tab.data(static_cast<Eigen::Index>(r), c);
      bool fell_back = false;
      const auto v = interpolateColumn(tab.time, col, out.time, opt.interpolation, &fell_back);
      if (fell_back) {
        out.warnings.push_back("table '" + names[t] + "', column '" + out.match.common[k] +
                               "': cubic interpolation needs 4 rows of finite values; linear used");
      }
      for (size_t r = 0; r < n; ++r) out.values[t](static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k)) = v[r];
    }
  }
  return out;
}

}  // namespace redmax::validation
