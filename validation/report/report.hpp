#pragma once
// The validation report (`redmax validate ... --report DIR`, docs/commands.md §1): a builder that
// collects comparisons, overlays, tables, plots, wall times, checks and free-form sections, and
// writes them into DIR:
//   summary.json            machine-readable: inputs, per-comparison per-column metrics,
//                           pass/fail against the stated tolerances, wall times, plot status, and
//                           any nested section later work adds ("sweeps", "work_precision")
//   <cmp>_metrics.csv       one row per column: the metrics of compare/metrics.hpp and PASS/FAIL
//   <cmp>_series.csv        the aligned series: time, then <col>:<a>, <col>:<b>, <col>:diff
//   <cmp>_overlay*.png|svg  per-column overlays of a and b; <cmp>_difference*.png|svg: a - b
//   <name>.csv / .png|svg   tables and plots added with addTable / addPlot / addOverlay
//   report.md               a short human-readable summary linking the plots
// Every file is written atomically (temporary file + rename). summary.json is written last, so
// its presence means the whole report was written. Plots need gnuplot; without it the report
// still completes and says the plots were skipped.
//
// Building is cheap and does no I/O; write() does all of it.
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "validation/compare/metrics.hpp"
#include "validation/report/csv.hpp"
#include "validation/report/json_value.hpp"
#include "validation/report/plot.hpp"

namespace redmax::validation {

/// A report could not be written (a directory or file that cannot be created). what() is
/// "PATH: message"; the command line exits with 1.
class ReportError : public std::runtime_error {
 public:
  ReportError(std::string path, const std::string& message)
      : std::runtime_error(path + ": " + message), path_(std::move(path)) {}
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

struct ReportOptions {
  std::string title = "redmax validation report";
  std::string gnuplot;                      ///< findGnuplot hint: "" auto, "none" no plots, or a path
  PlotFormat plot_format = PlotFormat::Auto;
  int panels_per_figure = 16;               ///< per-column grids are split into pages of this many
  int worst_rows = 12;                      ///< columns listed per comparison in report.md
  bool series_csv = true;                   ///< write <cmp>_series.csv
  double plot_timeout_s = 120;              ///< per figure
};

/// What write() produced.
struct ReportFiles {
  std::vector<std::string> written;      ///< every file written, in order (absolute or DIR-based paths)
  std::vector<std::string> plots;        ///< the images among them
  bool plots_skipped = false;            ///< no plot was attempted (gnuplot missing or disabled)
  std::string plots_note;                ///< why plots were skipped, or "" 
  std::vector<std::string> plot_errors;  ///< figures gnuplot failed on (the report still completed)
};

class Report {
 public:
  /// dir is created (with parents) by write() if missing.
  explicit Report(std::string dir, ReportOptions opt = {});

  const std::string& dir() const { return dir_; }
  const ReportOptions& options() const { return opt_; }

  /// summary.inputs[key] = value (model, trial and reference files, engine settings...)
  void setInput(const std::string& key, JsonValue value);
  /// summary.wall_times_s[what] += seconds
  void addWallTime(const std::string& what, double seconds);

  /// Add a comparison (compare/metrics.hpp). Files use c.name as their stem (characters other than
  /// letters, digits, '.', '-' and '_' become '_'). ylabel labels the plots' y axes.
  /// Throws std::invalid_argument if the stem is already used.
  void addComparison(const Comparison& c, const std::string& ylabel = "");
  /// A per-column overlay of several aligned tables (e.g. core, simbody and the OpenSim reference):
  /// DIR/<name>.png (pages _1, _2... when there are more columns than panels_per_figure).
  void addOverlay(const std::string& name, const AlignedTables& aligned, const std::string& title,
                  const std::string& ylabel = "");
  /// A figure built by the caller (x-y lines for mass sweeps, log-log for speed against error),
  /// DIR/<name>.png or .svg; caption is shown in report.md.
  void addPlot(const std::string& name, const PlotFigure& fig, const std::string& caption = "");
  /// A CSV table DIR/<name>.csv; caption is shown in report.md.
  void addTable(const std::string& name, const CsvTable& table, const std::string& caption = "");
  /// A top-level section of summary.json, an object created on first use, for later work
  /// ("sweeps", "work_precision"...). Reserved keys (those the report writes itself) throw
  /// std::invalid_argument.
  JsonValue& section(const std::string& key);
  /// A markdown paragraph under its own heading in report.md (after the comparisons).
  void addMarkdown(const std::string& heading, const std::string& markdown);
  /// A named check that counts toward the overall verdict (summary.checks).
  void addCheck(const std::string& name, bool passed, const std::string& detail = "");

  /// Every comparison and check passed (true when there is none).
  bool passed() const;

  /// Write all files into dir (see the file comment for the order). Throws ReportError when dir or
  /// a file cannot be written; files already written stay complete, none is left half-written.
  ReportFiles write();

 private:
  enum class PlotKind { Comparison, Overlay, Figure };
  struct PendingPlot {
    PlotKind kind;
    std::string stem;
    std::vector<PlotFigure> figures;  // one file each (stem, or stem_1, stem_2...)
    std::string caption;
  };
  struct ComparisonEntry {
    Comparison c;
    std::string stem, ylabel;
  };
  struct OverlayEntry {
    std::string stem, title;
    std::vector<std::string> tables, columns;
    double t_begin, t_end;
  };
  struct TableEntry {
    std::string stem, caption;
    CsvTable table;
  };
  struct Check {
    std::string name, detail;
    bool passed;
  };

  std::string claimStem(const std::string& name, const std::string& kind);
  JsonValue comparisonJson(const ComparisonEntry& e, const std::vector<std::string>& plots) const;
  std::string formatMarkdown(const ReportFiles& files, const std::map<std::string, std::vector<std::string>>& plots_of,
                             const GnuplotInfo& gp, const std::string& created) const;

  std::string dir_;
  ReportOptions opt_;
  JsonValue inputs_ = JsonValue::object();
  std::vector<std::pair<std::string, double>> wall_times_;
  std::vector<ComparisonEntry> comparisons_;
  std::vector<OverlayEntry> overlays_;
  std::vector<TableEntry> tables_;
  std::vector<PendingPlot> plots_;  // comparison plots first, in order, then overlays and others
  std::vector<std::pair<std::string, std::string>> markdown_;
  std::vector<Check> checks_;
  JsonValue sections_ = JsonValue::object();
  std::set<std::string> stems_;  // claimed output names, stem + kind
};

/// The file stem used for a name: characters other than [A-Za-z0-9._-] become '_' ("" -> "_").
std::string sanitizeFileStem(const std::string& name);

}  // namespace redmax::validation
