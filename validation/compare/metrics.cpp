#include "validation/compare/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

namespace redmax::validation {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// x / y for non-negative x, y with 0/0 = 0 and x/0 = inf: a zero reference with zero error is
// perfect agreement, with any error it is infinitely wrong in relative terms
double safeRatio(double x, double y) {
  if (y > 0) return x / y;
  return x == 0 ? 0.0 : kInf;
}

void checkTolerance(const Tolerance& tol, const std::string& name) {
  for (double v : {tol.rms_abs, tol.rms_rel, tol.max_abs, tol.max_rel}) {
    if (!(v >= 0)) throw CompareError("tolerance of column '" + name + "' must be non-negative");
  }
}

}  // namespace

std::string toString(RmsWeighting w) {
  return w == RmsWeighting::Trapezoid ? "trapezoid" : "samples";
}

ColumnMetrics calcColumnMetrics(const std::string& name, const std::vector<double>& t,
                                const std::vector<double>& a, const std::vector<double>& b,
                                const Tolerance& tol, RmsWeighting weighting) {
  const size_t n = t.size();
  if (n == 0 || a.size() != n || b.size() != n) {
    throw CompareError("column '" + name + "': " + std::to_string(t.size()) + " times, " +
                       std::to_string(a.size()) + " and " + std::to_string(b.size()) + " values");
  }
  checkTolerance(tol, name);
  ColumnMetrics m;
  m.name = name;
  m.tolerance = tol;

  // weights: trapezoid rule over the grid (the integral mean of d^2), or 1 per sample
  std::vector<double> w(n, 1.0);
  if (weighting == RmsWeighting::Trapezoid && n > 1 && t.back() > t.front()) {
    for (size_t i = 0; i < n; ++i) {
      const double left = i > 0 ? t[i] - t[i - 1] : 0.0;
      const double right = i + 1 < n ? t[i + 1] - t[i] : 0.0;
      w[i] = 0.5 * (left + right);
    }
  }
  // non-finite samples are left out of the sums and make the column fail
  double sw = 0, swd = 0, swd2 = 0;
  bool first = true;
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(a[i]) || !std::isfinite(b[i])) {
      ++m.non_finite;
      continue;
    }
    ++m.samples;
    const double d = a[i] - b[i];
    sw += w[i];
    swd += w[i] * d;
    swd2 += w[i] * d * d;
    if (first || std::abs(d) > m.max_abs) m.max_abs = std::abs(d), m.t_max_abs = t[i];
    m.peak_ref = std::max(m.peak_ref, std::abs(b[i]));
    first = false;
  }
  if (m.samples == 0) {
    m.rms = m.mean = m.max_abs = m.t_max_abs = m.peak_ref = m.rms_rel = m.max_rel = kNaN;
    m.usage = kInf;
    m.passed = false;
    return m;
  }
  if (!(sw > 0)) {
    // every finite sample has zero weight (e.g. only end points of a wider grid): plain mean
    sw = swd = swd2 = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(a[i]) || !std::isfinite(b[i])) continue;
      const double d = a[i] - b[i];
      sw += 1, swd += d, swd2 += d * d;
    }
  }
  m.mean = swd / sw;
  m.rms = std::sqrt(swd2 / sw);
  m.rms_rel = safeRatio(m.rms, m.peak_ref);
  m.max_rel = safeRatio(m.max_abs, m.peak_ref);

  // tolerance: an absolute floor plus a part proportional to the reference's peak
  const double allow_rms = tol.rms_abs + tol.rms_rel * m.peak_ref;
  const double allow_max = tol.max_abs + tol.max_rel * m.peak_ref;
  m.usage = std::max(safeRatio(m.rms, allow_rms), safeRatio(m.max_abs, allow_max));
  m.passed = m.non_finite == 0 && m.rms <= allow_rms && m.max_abs <= allow_max;
  return m;
}

std::vector<int> Comparison::rankWorstFirst() const {
  std::vector<int> idx(metrics.size());
  std::iota(idx.begin(), idx.end(), 0);
  // NaN usage (never produced, but be safe) ranks as worst
  auto key = [](double x) { return std::isnan(x) ? kInf : x; };
  std::stable_sort(idx.begin(), idx.end(), [&](int i, int j) {
    const auto& a = metrics[i];
    const auto& b = metrics[j];
    if (key(a.usage) != key(b.usage)) return key(a.usage) > key(b.usage);
    if (key(a.rms_rel) != key(b.rms_rel)) return key(a.rms_rel) > key(b.rms_rel);
    return a.name < b.name;
  });
  return idx;
}

Comparison compareAligned(const std::string& name, const AlignedTables& aligned, int ia, int ib,
                          const CompareOptions& opt) {
  const int nt = static_cast<int>(aligned.values.size());
  if (ia < 0 || ia >= nt || ib < 0 || ib >= nt || ia == ib) {
    throw CompareError("compareAligned: table indices " + std::to_string(ia) + " and " + std::to_string(ib) +
                       " are not two of the " + std::to_string(nt) + " aligned tables");
  }
  Comparison c;
  c.name = name;
  c.label_a = aligned.names.at(ia);
  c.label_b = aligned.names.at(ib);
  c.t_begin = aligned.t_begin;
  c.t_end = aligned.t_end;
  c.interpolation = aligned.interpolation;
  c.weighting = opt.weighting;
  c.grid = aligned.grid_table < 0 ? std::string("uniform") : aligned.names.at(aligned.grid_table);
  c.time = aligned.time;
  c.columns = aligned.columns();
  c.a = aligned.values[ia];
  c.b = aligned.values[ib];
  c.warnings = aligned.warnings;
  c.missing_columns_fail = opt.missing_columns_fail;
  checkTolerance(opt.tolerance, "(default)");
  c.tolerance = opt.tolerance;

  // unmatched columns of the pair, and columns the pair shares that a third table lacks
  const std::set<std::string> la(aligned.labels.at(ia).begin(), aligned.labels.at(ia).end());
  const std::set<std::string> lb(aligned.labels.at(ib).begin(), aligned.labels.at(ib).end());
  const std::set<std::string> common(c.columns.begin(), c.columns.end());
  std::set<std::string> listed;
  for (const auto& l : aligned.labels.at(ia)) {
    if (!listed.insert(l).second) continue;
    if (!lb.count(l)) {
      c.only_in_a.push_back(l);
    } else if (!common.count(l)) {
      c.warnings.push_back("column '" + l + "' is in both '" + c.label_a + "' and '" + c.label_b +
                           "' but not compared: another aligned table lacks it");
    }
  }
  listed.clear();
  for (const auto& l : aligned.labels.at(ib)) {
    if (listed.insert(l).second && !la.count(l)) c.only_in_b.push_back(l);
  }
  for (const auto& [col, tol] : opt.column_tolerance) {
    if (!common.count(col)) c.warnings.push_back("a tolerance is given for column '" + col + "', which is not compared");
  }

  // metrics per column
  const auto n = static_cast<Eigen::Index>(c.time.size());
  std::vector<double> va(n), vb(n);
  for (size_t k = 0; k < c.columns.size(); ++k) {
    for (Eigen::Index r = 0; r < n; ++r) {
      va[r] = c.a(r, static_cast<Eigen::Index>(k));
      vb[r] = c.b(r, static_cast<Eigen::Index>(k));
    }
    const auto it = opt.column_tolerance.find(c.columns[k]);
    const Tolerance& tol = it != opt.column_tolerance.end() ? it->second : opt.tolerance;
    c.metrics.push_back(calcColumnMetrics(c.columns[k], c.time, va, vb, tol, opt.weighting));
  }

  // verdict and worst column
  const auto rank = c.rankWorstFirst();
  c.worst = rank.empty() ? -1 : rank.front();
  c.passed = !c.metrics.empty() &&
             std::all_of(c.metrics.begin(), c.metrics.end(), [](const ColumnMetrics& m) { return m.passed; });
  if (opt.missing_columns_fail && (!c.only_in_a.empty() || !c.only_in_b.empty())) c.passed = false;
  return c;
}

Comparison compareTables(const std::string& name, const Table& a, const std::string& label_a, const Table& b,
                         const std::string& label_b, const CompareOptions& opt) {
  const auto aligned = alignTables({&a, &b}, {label_a, label_b}, opt.align);
  return compareAligned(name, aligned, 0, 1, opt);
}

}  // namespace redmax::validation
