#pragma once
// Plots through gnuplot, run as an external process on a generated script (Debian's gnuplot-nox,
// installed by scripts/setup). Data travel inside the script as datablocks, so one temporary file
// is written and nothing else. PNG through the pngcairo terminal when the installed gnuplot has
// it, SVG otherwise; the image is written beside its target and renamed into place, so a plot is
// either complete or absent. A missing gnuplot is not an error: callers get a reason to report.
//
// Figures are grids of panels; each panel holds lines (x-y series). The helpers at the end build
// the figures the harness needs: per-column overlays and differences, x-y multi-line plots (mass
// sweeps) and log-log plots (speed against error).
#include <string>
#include <vector>

namespace redmax::validation {

/// One series of a panel. Non-finite points (and non-positive ones on a log axis) break the line.
struct PlotLine {
  std::string label;            ///< legend text ("" = no legend entry)
  std::vector<double> x, y;     ///< same length
  std::string style = "lines";  ///< gnuplot style: lines, linespoints, points
  int dash_type = 1;            ///< gnuplot dash type (1 solid, 2 dashed, 3 dotted...)
  double width = 1.5;           ///< line width
};

/// A line (avoids aggregate initialisation with missing fields).
PlotLine makePlotLine(std::string label, std::vector<double> x, std::vector<double> y, std::string style = "lines");

/// One set of axes.
struct PlotPanel {
  std::string title, xlabel, ylabel;
  bool log_x = false, log_y = false;
  std::string key = "top right";  ///< legend position in gnuplot words ("bottom left", "off"...)
  std::vector<PlotLine> lines;
};

/// A figure: panels in a grid, row by row.
struct PlotFigure {
  std::string title;
  std::vector<PlotPanel> panels;
  int columns = 0;           ///< panels per row (0: chosen from the panel count, at most 4)
  int panel_width = 480;     ///< pixels per panel
  int panel_height = 320;
};

/// Image format. Auto: PNG (pngcairo) when available, else SVG.
enum class PlotFormat { Auto, Png, Svg };

/// What was found of gnuplot.
struct GnuplotInfo {
  bool available = false;
  std::string path;      ///< the executable
  std::string version;   ///< e.g. "5.4.4"
  bool pngcairo = false; ///< terminals it has
  bool svg = false;
  std::string why_not;   ///< when not available: why (not found, disabled, too old, no terminal)
};

/// Find gnuplot and probe its version and terminals (results cached per executable).
/// hint: "" = $REDMAX_GNUPLOT if set, else "gnuplot" on PATH; "none" = plots disabled; anything
/// else = the executable to use. Never throws; needs gnuplot >= 5.0 (datablocks).
GnuplotInfo findGnuplot(const std::string& hint = "");

/// The file extension (without dot) that format resolves to with this gnuplot ("png" or "svg";
/// "" if it cannot plot at all).
std::string resolvePlotExtension(const GnuplotInfo& gp, PlotFormat format);

/// The gnuplot script that draws fig to output_path with the given extension's terminal ("png"
/// -> pngcairo, "svg" -> svg). Pure; strings are quoted so that no text can inject commands.
std::string makeGnuplotScript(const PlotFigure& fig, const std::string& extension, const std::string& output_path);

/// Result of rendering one figure.
struct PlotOutcome {
  bool ok = false;
  std::string file;   ///< the image written (path_stem + "." + extension) when ok
  std::string error;  ///< otherwise why (gnuplot's first error line, a timeout, an I/O error)
};

/// Render fig to path_stem.png or path_stem.svg. Never throws for plotting failures (they are
/// reported in the outcome; a report still completes without its plots).
/// timeout_s bounds gnuplot's run time (it is killed after that).
PlotOutcome renderPlot(const GnuplotInfo& gp, PlotFormat format, const PlotFigure& fig, const std::string& path_stem,
                       double timeout_s = 120);

// ---------------------------------------------------------------------------------------------
// figure builders

/// An x-y panel with several lines (e.g. error against muscle mass fraction).
PlotPanel makeXYPanel(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                      std::vector<PlotLine> lines);
/// A log-log panel (e.g. wall time against error, one line per integrator), drawn with points.
PlotPanel makeLogLogPanel(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                          std::vector<PlotLine> lines);

/// Per-column overlay panels: for each column k, one panel titled columns[k] holding
/// series[s][k] against time for every series s (legend labels[s]). Split into figures of at
/// most panels_per_figure panels. values[s] is time.size() x columns.size().
struct SeriesSet {
  std::vector<double> time;
  std::vector<std::string> columns;
  std::vector<std::string> labels;      ///< one per series
  std::vector<std::vector<std::vector<double>>> values;  ///< [series][column][row]
};
std::vector<PlotFigure> makeColumnGridFigures(const SeriesSet& set, const std::string& title, const std::string& ylabel,
                                              int panels_per_figure = 16);

}  // namespace redmax::validation
