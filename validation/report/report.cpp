#include "validation/report/report.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>

#include "converter/atomic_file.hpp"
#include "converter/error.hpp"

#ifndef REDMAX_VERSION
#define REDMAX_VERSION "unknown"
#endif

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;

// keys of summary.json the report writes itself; section() refuses them
const std::set<std::string> kReservedKeys = {"format", "format_version", "generator", "title", "created_utc",
                                             "passed", "inputs", "wall_times_s", "comparisons", "overlays",
                                             "tables", "figures", "plots", "checks"};

std::string nowUtc() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// a short number for report.md
std::string fmt3(double x) {
  if (std::isnan(x)) return "n/a";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// a code span for a markdown table cell (names may hold '_' or '|')
std::string mdCode(const std::string& s) {
  std::string o = "`";
  for (char c : s) {
    if (c == '|') o += "\\|";
    else if (c == '`') o += '\'';
    else if (c == '\n' || c == '\r') o += ' ';
    else o += c;
  }
  return o + "`";
}

std::string mdText(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '|') o += "\\|";
    else if (c == '\n' || c == '\r') o += ' ';
    else o += c;
  }
  return o;
}

std::string passText(bool ok) { return ok ? "PASS" : "FAIL"; }

std::string joinNames(const std::vector<std::string>& v, size_t max_items = 12) {
  std::string o;
  for (size_t i = 0; i < v.size() && i < max_items; ++i) o += (i ? ", " : "") + mdCode(v[i]);
  if (v.size() > max_items) o += " and " + std::to_string(v.size() - max_items) + " more";
  return o;
}

JsonValue toleranceJson(const Tolerance& t) {
  JsonValue j = JsonValue::object();
  j["rms_abs"] = t.rms_abs;
  j["rms_rel"] = t.rms_rel;
  j["max_abs"] = t.max_abs;
  j["max_rel"] = t.max_rel;
  return j;
}

bool sameTolerance(const Tolerance& a, const Tolerance& b) {
  return a.rms_abs == b.rms_abs && a.rms_rel == b.rms_rel && a.max_abs == b.max_abs && a.max_rel == b.max_rel;
}

std::string toleranceText(const Tolerance& t) {
  return "RMS <= " + fmt3(t.rms_abs) + " + " + fmt3(t.rms_rel) + " * peak, max <= " + fmt3(t.max_abs) + " + " +
         fmt3(t.max_rel) + " * peak";
}

CsvTable metricsTable(const Comparison& c) {
  CsvTable t;
  t.header = {"column",  "samples", "non_finite",  "rms",         "mean",        "max_abs",     "t_max_abs", "peak_ref",
              "rms_rel", "max_rel", "tol_rms_abs", "tol_rms_rel", "tol_max_abs", "tol_max_rel", "usage",     "result"};
  for (const auto& m : c.metrics) {
    std::vector<std::string> row{m.name, std::to_string(m.samples), std::to_string(m.non_finite)};
    for (double v : {m.rms, m.mean, m.max_abs, m.t_max_abs, m.peak_ref, m.rms_rel, m.max_rel, m.tolerance.rms_abs,
                     m.tolerance.rms_rel, m.tolerance.max_abs, m.tolerance.max_rel, m.usage}) {
      row.push_back(formatNumber(v));
    }
    row.push_back(passText(m.passed));
    t.addRow(std::move(row));
  }
  return t;
}

CsvTable seriesTable(const Comparison& c) {
  CsvTable t;
  t.header.push_back("time");
  for (const auto& col : c.columns) {
    t.header.push_back(col + ":" + c.label_a);
    t.header.push_back(col + ":" + c.label_b);
    t.header.push_back(col + ":diff");
  }
  const auto k = static_cast<Eigen::Index>(c.columns.size());
  for (size_t r = 0; r < c.time.size(); ++r) {
    const auto i = static_cast<Eigen::Index>(r);
    std::vector<double> row{c.time[r]};
    for (Eigen::Index j = 0; j < k; ++j) {
      row.push_back(c.a(i, j));
      row.push_back(c.b(i, j));
      row.push_back(c.a(i, j) - c.b(i, j));
    }
    t.addRow(row);
  }
  return t;
}

std::vector<double> matrixColumn(const MatX& m, Eigen::Index j) {
  std::vector<double> v(static_cast<size_t>(m.rows()));
  for (Eigen::Index i = 0; i < m.rows(); ++i) v[static_cast<size_t>(i)] = m(i, j);
  return v;
}

void writeAtomic(const std::string& path, const std::string& content) {
  try {
    osim::writeFileAtomic(path, content);
  } catch (const osim::ConvertError& e) {
    throw ReportError(path, e.message());
  }
}

}  // namespace

std::string sanitizeFileStem(const std::string& name) {
  std::string o;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '-' || c == '_';
    o += ok ? c : '_';
  }
  // no hidden files and no "." / ".." as names
  if (o.empty() || o[0] == '.') o.insert(o.begin(), '_');
  return o;
}

Report::Report(std::string dir, ReportOptions opt) : dir_(std::move(dir)), opt_(std::move(opt)) {
  if (dir_.empty()) throw std::invalid_argument("Report: empty directory name");
  stems_ = {"summary.json", "report.md"};
}

std::string Report::claimStem(const std::string& name, const std::string& kind) {
  // names are claimed per kind of output (".csv", ".img" for png/svg, ".cmp" for comparisons),
  // so a table and a plot of the same data may share a name but two files never collide
  const std::string stem = sanitizeFileStem(name);
  if (!stems_.insert(stem + kind).second) {
    throw std::invalid_argument("Report: the name '" + name + "' (file '" + stem + kind + "') is already used");
  }
  return stem;
}

void Report::setInput(const std::string& key, JsonValue value) { inputs_[key] = std::move(value); }

void Report::addWallTime(const std::string& what, double seconds) {
  for (auto& [k, v] : wall_times_) {
    if (k == what) {
      v += seconds;
      return;
    }
  }
  wall_times_.emplace_back(what, seconds);
}

void Report::addComparison(const Comparison& c, const std::string& ylabel) {
  const std::string stem = sanitizeFileStem(c.name);
  // claim every file stem the comparison will use, so that nothing else overwrites them
  claimStem(stem, ".cmp");
  claimStem(stem + "_metrics", ".csv");
  claimStem(stem + "_series", ".csv");
  claimStem(stem + "_overlay", ".img");
  claimStem(stem + "_difference", ".img");
  comparisons_.push_back({c, stem, ylabel});

  // overlays of a and b, and the difference a - b, one panel per column
  SeriesSet both, diff;
  both.time = diff.time = c.time;
  both.columns = diff.columns = c.columns;
  both.labels = {c.label_a, c.label_b};
  diff.labels = {c.label_a + " - " + c.label_b};
  both.values.resize(2);
  diff.values.resize(1);
  for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(c.columns.size()); ++j) {
    both.values[0].push_back(matrixColumn(c.a, j));
    both.values[1].push_back(matrixColumn(c.b, j));
    diff.values[0].push_back(matrixColumn(c.a - c.b, j));
  }
  const std::string title = c.name + ": " + c.label_a + " vs " + c.label_b;
  auto overlay = makeColumnGridFigures(both, title, ylabel, opt_.panels_per_figure);
  auto difference = makeColumnGridFigures(diff, c.name + ": difference " + c.label_a + " - " + c.label_b, ylabel,
                                          opt_.panels_per_figure);
  if (overlay.size() > 1) {
    for (size_t p = 1; p <= overlay.size(); ++p) {
      claimStem(stem + "_overlay_" + std::to_string(p), ".img");
      claimStem(stem + "_difference_" + std::to_string(p), ".img");
    }
  }
  if (!overlay.empty()) {
    plots_.push_back({PlotKind::Comparison, stem + "_overlay", std::move(overlay), "overlay"});
    plots_.push_back({PlotKind::Comparison, stem + "_difference", std::move(difference), "difference"});
  }
}

void Report::addOverlay(const std::string& name, const AlignedTables& aligned, const std::string& title,
                        const std::string& ylabel) {
  const std::string stem = claimStem(name, ".img");
  SeriesSet set;
  set.time = aligned.time;
  set.columns = aligned.columns();
  set.labels = aligned.names;
  for (const auto& m : aligned.values) {
    std::vector<std::vector<double>> cols;
    for (Eigen::Index j = 0; j < m.cols(); ++j) cols.push_back(matrixColumn(m, j));
    set.values.push_back(std::move(cols));
  }
  auto figs = makeColumnGridFigures(set, title, ylabel, opt_.panels_per_figure);
  if (figs.size() > 1) {
    for (size_t p = 1; p <= figs.size(); ++p) claimStem(stem + "_" + std::to_string(p), ".img");
  }
  overlays_.push_back({stem, title, aligned.names, aligned.columns(), aligned.t_begin, aligned.t_end});
  if (!figs.empty()) plots_.push_back({PlotKind::Overlay, stem, std::move(figs), title});
}

void Report::addPlot(const std::string& name, const PlotFigure& fig, const std::string& caption) {
  plots_.push_back({PlotKind::Figure, claimStem(name, ".img"), {fig}, caption.empty() ? fig.title : caption});
}

void Report::addTable(const std::string& name, const CsvTable& table, const std::string& caption) {
  // format now, so that a malformed table is reported where it is added
  formatCsv(table);
  tables_.push_back({claimStem(name, ".csv"), caption, table});
}

JsonValue& Report::section(const std::string& key) {
  if (key.empty() || kReservedKeys.count(key)) {
    throw std::invalid_argument("Report::section: '" + key + "' is reserved for the report itself");
  }
  JsonValue& s = sections_[key];
  if (s.isNull()) s = JsonValue::object();
  return s;
}

void Report::addMarkdown(const std::string& heading, const std::string& markdown) {
  markdown_.emplace_back(heading, markdown);
}

void Report::addCheck(const std::string& name, bool passed, const std::string& detail) {
  checks_.push_back({name, detail, passed});
}

bool Report::passed() const {
  for (const auto& e : comparisons_) {
    if (!e.c.passed) return false;
  }
  for (const auto& c : checks_) {
    if (!c.passed) return false;
  }
  return true;
}

JsonValue Report::comparisonJson(const ComparisonEntry& e, const std::vector<std::string>& plots) const {
  const Comparison& c = e.c;
  JsonValue j = JsonValue::object();
  j["name"] = c.name;
  j["a"] = c.label_a;
  j["b"] = c.label_b;
  j["reference"] = c.label_b;
  j["passed"] = c.passed;
  j["time_range"] = std::vector<double>{c.t_begin, c.t_end};
  j["samples"] = static_cast<long>(c.time.size());
  j["grid"] = c.grid;
  j["interpolation"] = toString(c.interpolation);
  j["rms_weighting"] = toString(c.weighting);
  j["tolerance"] = toleranceJson(c.tolerance);
  int failed = 0;
  for (const auto& m : c.metrics) failed += m.passed ? 0 : 1;
  j["columns_compared"] = static_cast<long>(c.metrics.size());
  j["columns_failed"] = failed;
  if (c.worst >= 0) {
    const auto& w = c.metrics[static_cast<size_t>(c.worst)];
    JsonValue& jw = j["worst_column"];
    jw["name"] = w.name;
    jw["rms"] = w.rms;
    jw["rms_rel"] = w.rms_rel;
    jw["max_abs"] = w.max_abs;
    jw["t_max_abs"] = w.t_max_abs;
    jw["max_rel"] = w.max_rel;
    jw["peak_ref"] = w.peak_ref;
    jw["usage"] = w.usage;
    jw["passed"] = w.passed;
  } else {
    j["worst_column"] = nullptr;
  }
  JsonValue& miss = j["missing"];
  miss["only_in_a"] = c.only_in_a;
  miss["only_in_b"] = c.only_in_b;
  miss["fails"] = c.missing_columns_fail;
  j["warnings"] = c.warnings;
  JsonValue& cols = j["columns"];
  cols = JsonValue::array();
  for (const auto& m : c.metrics) {
    JsonValue& jc = cols.push(JsonValue::object());
    jc["name"] = m.name;
    jc["passed"] = m.passed;
    jc["samples"] = m.samples;
    jc["non_finite"] = m.non_finite;
    jc["rms"] = m.rms;
    jc["mean"] = m.mean;
    jc["max_abs"] = m.max_abs;
    jc["t_max_abs"] = m.t_max_abs;
    jc["peak_ref"] = m.peak_ref;
    jc["rms_rel"] = m.rms_rel;
    jc["max_rel"] = m.max_rel;
    jc["usage"] = m.usage;
    // a column's tolerance only where it differs from the comparison's
    if (!sameTolerance(m.tolerance, c.tolerance)) jc["tolerance"] = toleranceJson(m.tolerance);
  }
  JsonValue& files = j["files"];
  files["metrics_csv"] = e.stem + "_metrics.csv";
  files["series_csv"] = opt_.series_csv ? JsonValue(e.stem + "_series.csv") : JsonValue();
  files["plots"] = plots;
  return j;
}

std::string Report::formatMarkdown(const ReportFiles& files,
                                   const std::map<std::string, std::vector<std::string>>& plots_of,
                                   const GnuplotInfo& gp, const std::string& created) const {
  std::ostringstream md;
  auto images = [&](const std::string& stem, const std::string& what) {
    const auto it = plots_of.find(stem);
    if (it == plots_of.end() || it->second.empty()) return;
    for (const auto& f : it->second) md << "![" << mdText(what) << "](" << f << ")\n";
    md << "\n";
  };
  const bool ok = passed();
  md << "# " << mdText(opt_.title) << "\n\n";
  md << "Overall: **" << passText(ok) << "** (" << comparisons_.size() << " comparison"
     << (comparisons_.size() == 1 ? "" : "s") << ", " << checks_.size() << " check" << (checks_.size() == 1 ? "" : "s")
     << "). Generated " << created << " by redmax " << REDMAX_VERSION << "; machine-readable results in "
     << "[summary.json](summary.json).\n\n";

  // inputs and wall times
  if (inputs_.size() > 0) {
    md << "## Inputs\n\n| input | value |\n|---|---|\n";
    for (const auto& k : inputs_.keys()) {
      const JsonValue& v = inputs_.at(k);
      std::string text = v.isString() ? v.asString() : v.dump();
      while (!text.empty() && text.back() == '\n') text.pop_back();
      md << "| " << mdText(k) << " | " << mdText(text) << " |\n";
    }
    md << "\n";
  }
  if (!wall_times_.empty()) {
    md << "## Wall times\n\n| what | seconds |\n|---|---|\n";
    for (const auto& [k, v] : wall_times_) md << "| " << mdText(k) << " | " << fmt3(v) << " |\n";
    md << "\n";
  }

  // comparisons: verdict, conditions, the worst columns, plots
  if (!comparisons_.empty()) {
    md << "## Comparisons\n\n| comparison | result | worst column | RMS/peak | max/peak | failed columns |\n"
       << "|---|---|---|---|---|---|\n";
    for (const auto& e : comparisons_) {
      const Comparison& c = e.c;
      int failed = 0;
      for (const auto& m : c.metrics) failed += m.passed ? 0 : 1;
      md << "| " << mdText(c.name) << " | **" << passText(c.passed) << "** | ";
      if (c.worst >= 0) {
        const auto& w = c.metrics[static_cast<size_t>(c.worst)];
        md << mdCode(w.name) << " | " << fmt3(w.rms_rel) << " | " << fmt3(w.max_rel);
      } else {
        md << "- | - | -";
      }
      md << " | " << failed << " of " << c.metrics.size() << " |\n";
    }
    md << "\n";
  }
  for (const auto& e : comparisons_) {
    const Comparison& c = e.c;
    md << "### " << mdText(c.name) << ": " << passText(c.passed) << "\n\n";
    const std::string grid = c.grid == "uniform" ? std::string("a uniform grid") : mdText(c.grid) + "'s rows";
    md << "a = " << mdText(c.label_a) << " against the reference b = " << mdText(c.label_b) << " over t = "
       << fmt3(c.t_begin) << " .. " << fmt3(c.t_end) << " s (" << c.time.size() << " samples on " << grid << ", "
       << toString(c.interpolation) << " interpolation, " << toString(c.weighting) << "-weighted RMS).\n";
    md << "Tolerance per column: " << toleranceText(c.tolerance) << " (peak = max |" << mdText(c.label_b)
       << "|); a column passes when both hold.\n\n";
    if (!c.only_in_a.empty()) md << "Only in " << mdText(c.label_a) << ": " << joinNames(c.only_in_a) << ".\n";
    if (!c.only_in_b.empty()) md << "Only in " << mdText(c.label_b) << ": " << joinNames(c.only_in_b) << ".\n";
    if (!c.only_in_a.empty() || !c.only_in_b.empty()) {
      md << (c.missing_columns_fail ? "Missing columns make this comparison fail.\n\n"
                                    : "Missing columns are reported, not failed.\n\n");
    }
    for (const auto& w : c.warnings) md << "- warning: " << mdText(w) << "\n";
    if (!c.warnings.empty()) md << "\n";
    const auto rank = c.rankWorstFirst();
    const size_t shown = std::min(rank.size(), static_cast<size_t>(std::max(opt_.worst_rows, 0)));
    if (shown > 0) {
      md << "| column | RMS | RMS/peak | max abs | at t [s] | max/peak | peak | tolerance used | result |\n"
         << "|---|---|---|---|---|---|---|---|---|\n";
      for (size_t i = 0; i < shown; ++i) {
        const auto& m = c.metrics[static_cast<size_t>(rank[i])];
        md << "| " << mdCode(m.name) << " | " << fmt3(m.rms) << " | " << fmt3(m.rms_rel) << " | " << fmt3(m.max_abs)
           << " | " << fmt3(m.t_max_abs) << " | " << fmt3(m.max_rel) << " | " << fmt3(m.peak_ref) << " | "
           << fmt3(m.usage) << " | " << passText(m.passed) << (m.non_finite ? " (non-finite values)" : "")
           << " |\n";
      }
      md << "\n";
    }
    md << "Worst " << shown << " of " << c.metrics.size() << " columns (ordered by tolerance used); all in ["
       << e.stem << "_metrics.csv](" << e.stem << "_metrics.csv)";
    if (opt_.series_csv) md << ", aligned series in [" << e.stem << "_series.csv](" << e.stem << "_series.csv)";
    md << ".\n\n";
    images(e.stem + "_overlay", c.name + " overlay");
    images(e.stem + "_difference", c.name + " difference");
  }

  // overlays, tables and figures others added
  for (const auto& o : overlays_) {
    md << "## " << mdText(o.title) << "\n\n" << o.tables.size() << " series (";
    for (size_t i = 0; i < o.tables.size(); ++i) md << (i ? ", " : "") << mdText(o.tables[i]);
    md << ") on " << o.columns.size() << " common columns, t = " << fmt3(o.t_begin) << " .. " << fmt3(o.t_end)
       << " s.\n\n";
    images(o.stem, o.title);
  }
  if (!tables_.empty()) {
    md << "## Tables\n\n";
    for (const auto& t : tables_) {
      md << "- [" << t.stem << ".csv](" << t.stem << ".csv)" << (t.caption.empty() ? "" : ": " + mdText(t.caption))
         << "\n";
    }
    md << "\n";
  }
  bool any_figure = false;
  for (const auto& p : plots_) {
    if (p.kind != PlotKind::Figure) continue;
    if (!any_figure) md << "## Figures\n\n";
    any_figure = true;
    if (!p.caption.empty()) md << mdText(p.caption) << "\n\n";
    images(p.stem, p.caption.empty() ? p.stem : p.caption);
  }

  if (!checks_.empty()) {
    md << "## Checks\n\n| check | result | detail |\n|---|---|---|\n";
    for (const auto& c : checks_) {
      md << "| " << mdText(c.name) << " | **" << passText(c.passed) << "** | " << mdText(c.detail) << " |\n";
    }
    md << "\n";
  }
  for (const auto& [heading, text] : markdown_) md << "## " << mdText(heading) << "\n\n" << text << "\n\n";

  // how the plots were made, or why there are none
  md << "## Plots\n\n";
  if (files.plots_skipped) {
    md << "Plots were skipped: " << mdText(files.plots_note) << ".\n";
  } else {
    md << files.plots.size() << " image(s) drawn with gnuplot " << mdText(gp.version) << ".\n";
    for (const auto& e : files.plot_errors) md << "- not drawn: " << mdText(e) << "\n";
  }
  return md.str();
}

ReportFiles Report::write() {
  ReportFiles files;
  const std::string created = nowUtc();

  // the directory (with parents); an existing non-directory is an error
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (!fs::is_directory(dir_)) {
    throw ReportError(dir_, "cannot create the report directory" + (ec ? ": " + ec.message() : std::string()));
  }
  const fs::path dir(dir_);
  auto put = [&](const std::string& name, const std::string& content) {
    const std::string path = (dir / name).string();
    writeAtomic(path, content);
    files.written.push_back(path);
  };

  // tables first
  for (const auto& e : comparisons_) {
    put(e.stem + "_metrics.csv", formatCsv(metricsTable(e.c)));
    if (opt_.series_csv) put(e.stem + "_series.csv", formatCsv(seriesTable(e.c)));
  }
  for (const auto& t : tables_) put(t.stem + ".csv", formatCsv(t.table));

  // plots: a failed figure is noted, never fatal
  const GnuplotInfo gp = plots_.empty() ? GnuplotInfo{} : findGnuplot(opt_.gnuplot);
  std::map<std::string, std::vector<std::string>> plots_of;  // stem -> image file names
  if (!plots_.empty() && !gp.available) {
    files.plots_skipped = true;
    files.plots_note = gp.why_not.empty() ? "gnuplot is not available" : gp.why_not;
  }
  for (const auto& p : plots_) {
    if (!gp.available) break;
    for (size_t f = 0; f < p.figures.size(); ++f) {
      const std::string stem = p.figures.size() > 1 ? p.stem + "_" + std::to_string(f + 1) : p.stem;
      const auto out = renderPlot(gp, opt_.plot_format, p.figures[f], (dir / stem).string(), opt_.plot_timeout_s);
      if (out.ok) {
        files.written.push_back(out.file);
        files.plots.push_back(out.file);
        plots_of[p.stem].push_back(fs::path(out.file).filename().string());
      } else {
        files.plot_errors.push_back(stem + ": " + out.error);
      }
    }
  }
  if (plots_.empty()) files.plots_note = "no figure was requested";

  // report.md, then summary.json last (its presence marks a complete report)
  put("report.md", formatMarkdown(files, plots_of, gp, created));

  JsonValue s = JsonValue::object();
  s["format"] = "redmax-validation-report";
  s["format_version"] = 1;
  s["generator"] = std::string("redmax ") + REDMAX_VERSION;
  s["title"] = opt_.title;
  s["created_utc"] = created;
  s["passed"] = passed();
  s["inputs"] = inputs_;
  JsonValue& wt = s["wall_times_s"];
  wt = JsonValue::object();
  for (const auto& [k, v] : wall_times_) wt[k] = v;
  JsonValue& cmp = s["comparisons"];
  cmp = JsonValue::array();
  for (const auto& e : comparisons_) {
    std::vector<std::string> pl;
    for (const char* suffix : {"_overlay", "_difference"}) {
      const auto it = plots_of.find(e.stem + suffix);
      if (it != plots_of.end()) pl.insert(pl.end(), it->second.begin(), it->second.end());
    }
    cmp.push(comparisonJson(e, pl));
  }
  JsonValue& ov = s["overlays"];
  ov = JsonValue::array();
  for (const auto& o : overlays_) {
    JsonValue& j = ov.push(JsonValue::object());
    j["name"] = o.stem;
    j["title"] = o.title;
    j["series"] = o.tables;
    j["columns"] = o.columns;
    j["time_range"] = std::vector<double>{o.t_begin, o.t_end};
    j["plots"] = plots_of.count(o.stem) ? JsonValue(plots_of.at(o.stem)) : JsonValue::array();
  }
  JsonValue& tb = s["tables"];
  tb = JsonValue::array();
  for (const auto& t : tables_) {
    JsonValue& j = tb.push(JsonValue::object());
    j["name"] = t.stem;
    j["file"] = t.stem + ".csv";
    j["caption"] = t.caption;
    j["rows"] = static_cast<long>(t.table.rows.size());
  }
  JsonValue& fg = s["figures"];
  fg = JsonValue::array();
  for (const auto& p : plots_) {
    JsonValue& j = fg.push(JsonValue::object());
    j["name"] = p.stem;
    j["caption"] = p.caption;
    j["files"] = plots_of.count(p.stem) ? JsonValue(plots_of.at(p.stem)) : JsonValue::array();
  }
  JsonValue& pl = s["plots"];
  pl["drawn"] = static_cast<long>(files.plots.size());
  pl["skipped"] = files.plots_skipped;
  pl["note"] = files.plots_note;
  pl["gnuplot"] = gp.available ? JsonValue(gp.path) : JsonValue();
  pl["gnuplot_version"] = gp.available ? JsonValue(gp.version) : JsonValue();
  pl["format"] = gp.available ? JsonValue(resolvePlotExtension(gp, opt_.plot_format)) : JsonValue();
  pl["errors"] = files.plot_errors;
  JsonValue& ch = s["checks"];
  ch = JsonValue::array();
  for (const auto& c : checks_) {
    JsonValue& j = ch.push(JsonValue::object());
    j["name"] = c.name;
    j["passed"] = c.passed;
    j["detail"] = c.detail;
  }
  // sections added by later work, in the order they were created
  for (const auto& k : sections_.keys()) s[k] = sections_.at(k);
  put("summary.json", s.dump());
  return files;
}

}  // namespace redmax::validation
