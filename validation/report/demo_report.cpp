#include "validation/report/demo_report.hpp"

#include <cmath>
#include <filesystem>

#include "converter/storage.hpp"
#include "validation/report/progress.hpp"

namespace redmax::validation {
namespace {

constexpr double kPi = 3.14159265358979323846;

// the synthetic "true" torques of four coordinates [N m, N]
double hip(double t) { return 50 * std::sin(2 * kPi * t); }
double knee(double t) { return 30 * std::cos(2 * kPi * t); }
double ankle(double t) { return 80 * std::sin(4 * kPi * t) + 10; }
double lumbar(double t) { return 5 * std::sin(2 * kPi * t); }

}  // namespace

std::vector<Table> makeDemoTables(int rows) {
  if (rows < 2) throw CompareError("makeDemoTables: rows must be >= 2");
  const std::vector<std::string> labels = {"hip_flexion_r_moment", "knee_angle_r_moment", "ankle_angle_r_moment",
                                           "pelvis_tx_force"};
  std::vector<double> t(static_cast<size_t>(rows));
  MatX core(rows, 4), simbody(rows, 4);
  for (int i = 0; i < rows; ++i) {
    t[static_cast<size_t>(i)] = static_cast<double>(i) / (rows - 1);
    const double ti = t[static_cast<size_t>(i)];
    core.row(i) << hip(ti), knee(ti), ankle(ti), 0.0;
    // a second engine that differs by round-off-sized amounts
    simbody.row(i) = core.row(i).array() + 1e-12 * std::sin(6 * kPi * ti);
  }
  // the reference as an OpenSim 3.x file might have it: other column order, pelvis_tx_force
  // missing, lumbar_extension_moment extra, rows every 0.01 s over 0.01..0.99 s; knee offset by
  // +0.5 N m and ankle 2% larger, so that its errors are known
  const std::vector<std::string> ref_labels = {"ankle_angle_r_moment", "lumbar_extension_moment",
                                               "knee_angle_r_moment", "hip_flexion_r_moment"};
  const int nr = 99;
  std::vector<double> tr(nr);
  MatX ref(nr, 4);
  for (int i = 0; i < nr; ++i) {
    const double ti = 0.01 * (i + 1);
    tr[static_cast<size_t>(i)] = ti;
    ref.row(i) << 1.02 * ankle(ti), lumbar(ti), knee(ti) + 0.5, hip(ti);
  }
  return {makeTable("core", labels, t, core), makeTable("simbody", labels, t, simbody),
          makeTable("reference", ref_labels, tr, ref)};
}

DemoReportResult writeDemoReport(const std::string& dir, const DemoReportOptions& opt) {
  ReportOptions ro;
  ro.title = "redmax validation report (synthetic demonstration)";
  ro.gnuplot = opt.gnuplot;
  Report report(dir, ro);
  auto tables = makeDemoTables(opt.rows);

  // the reference goes through a .sto file, as an OpenSim result would
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::string ref_path = (std::filesystem::path(dir) / "demo_reference.sto").string();
  Table reference;
  try {
    osim::writeStorage(ref_path, tables[2]);
    reference = osim::readStorage(ref_path);
  } catch (const osim::ConvertError& e) {
    throw ReportError(ref_path, e.message());
  }

  report.setInput("model", "(synthetic: four coordinates)");
  report.setInput("reference", "demo_reference.sto");
  report.setInput("rows", opt.rows);

  // the engines against each other: round-off agreement
  Stopwatch sw;
  CompareOptions tight;
  tight.tolerance = {1e-9, 1e-9, 1e-9, 1e-9};
  DemoReportResult r;
  r.engines = compareTables("core_vs_simbody", tables[0], "core", tables[1], "simbody", tight);
  report.addComparison(r.engines, "generalized force");
  // core against the reference: modelling-level agreement, reference interpolated onto core's rows
  CompareOptions loose;
  loose.tolerance = {1e-6, 0.05, 1e-6, 0.1};
  r.reference = compareTables("core_vs_reference", tables[0], "core", reference, "reference", loose);
  report.addComparison(r.reference, "generalized force");
  report.addWallTime("comparisons", sw.seconds());

  // all three on one grid
  const auto aligned = alignTables({&tables[0], &tables[1], &reference}, {"core", "simbody", "reference"});
  report.addOverlay("overlay_all", aligned, "core, simbody and reference", "generalized force");

  // a mass-sweep-shaped section (later: the tibia mass transfer sweep)
  ProgressOptions po;
  po.stream = opt.show_progress ? stderr : nullptr;
  Progress progress("demo sweep", 9, po);
  std::vector<double> fraction, knee_change, hip_change;
  for (int k = 0; k <= 8; ++k) {
    const double f = 0.1 * k;
    fraction.push_back(f);
    knee_change.push_back(12 * std::pow(f, 1.5));
    hip_change.push_back(3 * f * f);
    progress.advance();
  }
  progress.finish();
  JsonValue& sweep = report.section("sweeps")["tibia_mass_transfer"];
  sweep["synthetic"] = true;
  sweep["fraction"] = fraction;
  sweep["knee_rms_rel_percent"] = knee_change;
  sweep["hip_rms_rel_percent"] = hip_change;
  PlotFigure sweep_fig;
  sweep_fig.title = "synthetic mass sweep";
  sweep_fig.panels.push_back(makeXYPanel("change against muscle mass fraction", "fraction of tibia mass moved",
                                         "RMS change [% of peak]",
                                         {makePlotLine("knee", fraction, knee_change), makePlotLine("hip", fraction, hip_change)}));
  report.addPlot("sweep_tibia", sweep_fig, "Synthetic mass sweep (x-y helper)");
  CsvTable sweep_table;
  sweep_table.header = {"fraction", "knee_rms_rel_percent", "hip_rms_rel_percent"};
  for (size_t i = 0; i < fraction.size(); ++i) sweep_table.addRow({fraction[i], knee_change[i], hip_change[i]});
  report.addTable("sweep_tibia", sweep_table, "synthetic mass sweep");

  // a work-precision-shaped section (later: speed against error per integrator)
  JsonValue& wp = report.section("work_precision")["integrators"];
  PlotFigure wp_fig;
  wp_fig.title = "synthetic work-precision";
  PlotPanel panel = makeLogLogPanel("wall time against error", "error", "wall time [s]", {});
  for (const std::string name : {"euler", "rk45"}) {
    PlotLine line;
    line.label = name;
    JsonValue& jn = wp.push(JsonValue::object());
    jn["name"] = name;
    JsonValue& pts = jn["points"];
    pts = JsonValue::array();
    for (int k = 0; k < 5; ++k) {
      const double h = std::pow(10.0, -2 - k * 0.5);
      const double err = name == "euler" ? 0.5 * h : std::pow(h, 4);
      const double secs = name == "euler" ? 1e-4 / h : 2e-3 * std::pow(h, -0.2);
      line.x.push_back(err);
      line.y.push_back(secs);
      JsonValue& p = pts.push(JsonValue::object());
      p["error"] = err;
      p["seconds"] = secs;
    }
    line.style = "linespoints";
    panel.lines.push_back(line);
  }
  wp_fig.panels.push_back(panel);
  report.addPlot("work_precision", wp_fig, "Synthetic work-precision (log-log helper)");

  report.addCheck("engines finite", r.engines.metrics.front().non_finite == 0, "no NaN in either engine");
  report.addMarkdown("About this report",
                     "Every number here is synthetic: the demonstration exercises the report machinery "
                     "that `redmax validate` uses.");
  r.files = report.write();
  r.passed = report.passed();
  return r;
}

}  // namespace redmax::validation
