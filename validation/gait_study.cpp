#include "validation/gait_study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "converter/analyze/setup_writer.hpp"
#include "converter/atomic_file.hpp"
#include "converter/osim_reader.hpp"
#include "validation/report/trial_view.hpp"

namespace redmax::validation {
namespace fs = std::filesystem;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string number(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}

}  // namespace

double relativeChange(double x, double x0) { return x0 != 0.0 ? (x - x0) / std::abs(x0) : kNaN; }

GaitStudyResult runGaitStudy(const GaitStudyOptions& opt, const std::string& setup_dir) {
  if (!opt.transfer_body.empty() && opt.transfer_values.empty())
    throw std::invalid_argument("a transfer sweep needs its fractions");
  for (double v : opt.transfer_values)
    if (!(v >= 0.0 && v < 1.0)) throw std::invalid_argument("transfer fraction " + number(v) + " is not in [0, 1)");
  const osim::IdToolConfig& t = opt.trial;
  GaitStudyResult res;

  // the setup and its reserves (one CoordinateActuator per coordinate static optimization drives)
  osim::StaticOptimizationSetupOptions so;
  so.reserve_optimal_force = opt.reserve_optimal_force;
  so.residual_optimal_force = opt.residual_optimal_force;
  so.step_interval = opt.step_interval;
  const osim::StaticOptimizationSetupFiles files = osim::writeStaticOptimizationSetup(t, so, setup_dir);
  res.setup_file = files.setup_file;
  res.reserves_file = files.reserves_file;
  res.reserves = files.reserves;

  // the runs: zero mass, physiological, the transfer sweep (0 included: it must equal zero)
  struct Value {
    std::string label;
    osim::MuscleMassOptions mass;
  };
  std::vector<Value> values{{"zero", {}}};
  if (opt.physiological) {
    osim::MuscleMassOptions m = opt.base;
    m.source = osim::MuscleMassOptions::Source::Physiological;
    values.push_back({"physiological", m});
  }
  if (!opt.transfer_body.empty()) {
    std::vector<double> fr = opt.transfer_values;
    if (std::find(fr.begin(), fr.end(), 0.0) == fr.end()) fr.push_back(0.0);
    std::sort(fr.begin(), fr.end());
    for (double f : fr) {
      osim::MuscleMassOptions m = opt.base;
      m.source = osim::MuscleMassOptions::Source::Transfer;
      m.transfer_body = opt.transfer_body;
      m.transfer_fraction = f;
      std::ostringstream label;
      label << "transfer " << f;
      values.push_back({label.str(), m});
    }
  }
  for (const Value& v : values) {
    osim::AnalyzeToolSettings s;
    s.setup_file = res.setup_file;
    s.out_dir = setup_dir;
    if (!opt.muscle_class.empty()) s.muscle_class = opt.muscle_class;
    s.muscle_mass = v.mass;
    const auto start = std::chrono::steady_clock::now();
    const osim::AnalyzeTool tool(s);
    if (res.runs.empty()) res.warnings = tool.warnings();
    GaitStudyRun run;
    run.label = v.label;
    run.muscle_mass = tool.muscleMass();
    run.so = tool.runStaticOptimization();
    run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (opt.progress)
      std::fprintf(stderr, "gait-study: %s: muscle mass %.4g kg, %zu frames (%d failed), %.2f s\n", v.label.c_str(),
                   run.muscle_mass, run.so.frames.size(), run.so.failed, run.wall_s);
    res.runs.push_back(std::move(run));
  }

  // per muscle over the frames that converged in every run
  const auto& z = res.runs.front().so;
  res.frames = static_cast<int>(z.frames.size());
  std::vector<char> use(z.frames.size(), 1);
  for (const GaitStudyRun& r : res.runs)
    for (size_t k = 0; k < r.so.frames.size() && k < use.size(); ++k) use[k] &= r.so.frames[k].converged ? 1 : 0;
  res.frames_used = static_cast<int>(std::count(use.begin(), use.end(), 1));
  for (size_t j = 0; j < z.actuators.size(); ++j) {
    if (!z.is_muscle[j]) continue;
    GaitStudyMuscle m;
    m.name = z.actuators[j];
    for (const GaitStudyRun& r : res.runs) {
      double pf = 0.0, pa = 0.0, integral = 0.0, prev_t = kNaN, prev_f = kNaN;
      for (size_t k = 0; k < r.so.frames.size(); ++k) {
        if (!use[k]) {
          prev_t = kNaN;  // a failed frame breaks the integral's trapezoids
          continue;
        }
        const auto& f = r.so.frames[k];
        const double F = f.force[static_cast<Eigen::Index>(j)], a = f.activation[static_cast<Eigen::Index>(j)];
        pf = std::max(pf, std::abs(F));
        pa = std::max(pa, a);
        if (!std::isnan(prev_t)) integral += 0.5 * (F + prev_f) * (f.time - prev_t);
        prev_t = f.time;
        prev_f = F;
      }
      m.peak_force.push_back(pf);
      m.peak_activation.push_back(pa);
      m.force_integral.push_back(integral);
    }
    res.muscles.push_back(std::move(m));
  }
  return res;
}

void addGaitStudy(const GaitStudyResult& res, const GaitStudyOptions& opt, Report& report) {
  const size_t nr = res.runs.size();
  report.setInput("model", opt.trial.model_file);
  report.setInput("coordinates", opt.trial.coordinates_file);
  report.setInput("external_loads", opt.trial.external_loads_file);
  report.setInput("setup", res.setup_file);
  report.setInput("reserves", res.reserves_file);
  for (const GaitStudyRun& r : res.runs) report.addWallTime("static optimization " + r.label, r.wall_s);

  // runs
  CsvTable runs;
  runs.header = {"run", "muscle_mass_kg", "frames", "failed", "mean_iterations", "max_violation", "wall_s"};
  for (const GaitStudyRun& r : res.runs) {
    double it = 0, viol = 0;
    int ok = 0;
    for (const auto& f : r.so.frames)
      if (f.converged) {
        it += f.iterations;
        viol = std::max(viol, f.constraint_violation);
        ++ok;
      }
    runs.addRow(r.label, {r.muscle_mass, static_cast<double>(r.so.frames.size()), static_cast<double>(r.so.failed),
                          ok ? it / ok : kNaN, viol, r.wall_s});
    report.addCheck("no failed frame: " + r.label, r.so.failed == 0,
                    std::to_string(r.so.failed) + " of " + std::to_string(r.so.frames.size()) + " frames failed");
  }
  report.addTable("runs", runs, "Each static-optimization run: muscle mass on mass points, frames, iterations, "
                                "max |A x - b| (N or N m), wall time.");

  // a transfer of fraction 0 moves no mass: it must be the zero run exactly
  for (size_t r = 1; r < nr; ++r) {
    if (res.runs[r].label != "transfer 0") continue;
    double diff = 0.0;
    const auto& a = res.runs[0].so.frames;
    const auto& b = res.runs[r].so.frames;
    bool same = a.size() == b.size();
    for (size_t k = 0; same && k < a.size(); ++k)
      if (a[k].converged && b[k].converged)
        diff = std::max(diff, (a[k].force - b[k].force).cwiseAbs().maxCoeff());
    report.addCheck("transfer 0 equals zero mass", same && diff == 0.0, "max |force difference| " + number(diff) + " N");
  }

  // per muscle: zero, each run, the change
  CsvTable mt;
  mt.header = {"muscle"};
  for (const GaitStudyRun& r : res.runs) {
    mt.header.push_back("peak_force_N " + r.label);
    mt.header.push_back("peak_activation " + r.label);
    mt.header.push_back("force_integral_Ns " + r.label);
  }
  for (size_t r = 1; r < nr; ++r) {
    mt.header.push_back("peak_force_change_% " + res.runs[r].label);
    mt.header.push_back("peak_activation_change_% " + res.runs[r].label);
    mt.header.push_back("force_integral_change_% " + res.runs[r].label);
  }
  for (const GaitStudyMuscle& m : res.muscles) {
    std::vector<double> row;
    for (size_t r = 0; r < nr; ++r) {
      row.push_back(m.peak_force[r]);
      row.push_back(m.peak_activation[r]);
      row.push_back(m.force_integral[r]);
    }
    for (size_t r = 1; r < nr; ++r) {
      row.push_back(100 * relativeChange(m.peak_force[r], m.peak_force[0]));
      row.push_back(100 * relativeChange(m.peak_activation[r], m.peak_activation[0]));
      row.push_back(100 * relativeChange(m.force_integral[r], m.force_integral[0]));
    }
    mt.addRow(m.name, row);
  }
  report.addTable("muscles", mt, "Per muscle: peak |force|, peak activation and force-time integral of each run, "
                                 "and their change from the zero-mass run (%).");

  // which muscles change most: by the force-time integral's change in N s (a relative change
  // would rank near-silent muscles first)
  const size_t last = nr - 1;
  std::vector<size_t> order(res.muscles.size());
  std::iota(order.begin(), order.end(), 0);
  auto change = [&](size_t i, size_t r) { return res.muscles[i].force_integral[r] - res.muscles[i].force_integral[0]; };
  size_t ref = nr > 1 ? 1 : 0;  // physiological when run, else the first sweep value
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return std::abs(change(a, ref)) > std::abs(change(b, ref)); });
  std::ostringstream md;
  md.precision(3);
  md << "Static optimization (OpenSim's StaticOptimization: activation exponent 2, muscle physiology on) of "
     << res.frames << " frames (" << res.frames_used << " converged in every run and enter the metrics). The study's "
     << "own setup (`" << res.setup_file << "`) adds " << res.reserves.size()
     << " CoordinateActuators (`" << res.reserves_file << "`): residuals on the pelvis (root) coordinates (optimal force "
     << opt.residual_optimal_force << "), reserves on every other coordinate (optimal force " << opt.reserve_optimal_force
     << "), controls unbounded.\n\n";
  if (nr > 1 && !res.muscles.empty()) {
    md << "Muscles whose force-time integral changes most from zero mass to " << res.runs[ref].label
       << " (change in N s and % of the muscle's own zero-mass integral):\n\n| muscle | integral zero [N s] | change [N s] | change [%] | peak force change [%] | peak activation change [%] |\n|---|---|---|---|---|---|\n";
    for (size_t k = 0; k < std::min<size_t>(10, order.size()); ++k) {
      const GaitStudyMuscle& m = res.muscles[order[k]];
      md << "| " << m.name << " | " << m.force_integral[0] << " | " << change(order[k], ref) << " | "
         << 100 * relativeChange(m.force_integral[ref], m.force_integral[0]) << " | "
         << 100 * relativeChange(m.peak_force[ref], m.peak_force[0]) << " | "
         << 100 * relativeChange(m.peak_activation[ref], m.peak_activation[0]) << " |\n";
    }
  }
  for (const auto& w : res.warnings) md << "\nwarning: " << w << "\n";
  report.addMarkdown("Gait study: muscle forces with muscle mass", md.str());
  JsonValue& sec = report.section("gait_study");
  sec["frames"] = res.frames;
  sec["frames_used"] = res.frames_used;
  sec["reserves"] = static_cast<int>(res.reserves.size());
  JsonValue most = JsonValue::array();
  for (size_t k = 0; k < std::min<size_t>(10, order.size()); ++k) most.push(res.muscles[order[k]].name);
  sec["changes_most"] = most;

  // plots: force over time of the six that change most (zero, reference, last run), and the
  // integral's change against the transfer fraction
  PlotFigure forces;
  forces.title = "muscle force, zero mass vs " + res.runs[ref].label + (last != ref ? " and " + res.runs[last].label : "");
  const auto& z = res.runs[0].so;
  int muscle_col = 0;
  for (size_t k = 0; k < std::min<size_t>(6, order.size()); ++k) {
    const std::string& name = res.muscles[order[k]].name;
    const auto it = std::find(z.actuators.begin(), z.actuators.end(), name);
    muscle_col = static_cast<int>(it - z.actuators.begin());
    PlotPanel p;
    p.title = name;
    p.xlabel = "t [s]";
    p.ylabel = "force [N]";
    for (size_t r : std::vector<size_t>{0, ref, last}) {
      if (r != 0 && r == ref && ref == 0) continue;
      std::vector<double> t, f;
      for (const auto& fr : res.runs[r].so.frames) {
        t.push_back(fr.time);
        f.push_back(fr.force[muscle_col]);
      }
      p.lines.push_back(makePlotLine(res.runs[r].label, t, f));
      if (last == ref) break;
    }
    forces.panels.push_back(p);
  }
  if (!forces.panels.empty()) report.addPlot("muscle_forces", forces, "Forces of the muscles that change most.");
  std::vector<size_t> sweep;
  for (size_t r = 0; r < nr; ++r)
    if (res.runs[r].label.rfind("transfer ", 0) == 0) sweep.push_back(r);
  if (sweep.size() > 1) {
    PlotPanel p = makeXYPanel("force-time integral change over the transfer sweep", "fraction of " + opt.transfer_body +
                                                                                        "'s mass moved",
                              "change of the integral [% of zero mass]", {});
    for (size_t k = 0; k < std::min<size_t>(8, order.size()); ++k) {
      std::vector<double> x, y;
      for (size_t r : sweep) {
        x.push_back(std::stod(res.runs[r].label.substr(9)));
        const auto& m = res.muscles[order[k]];
        y.push_back(100 * relativeChange(m.force_integral[r], m.force_integral[0]));
      }
      p.lines.push_back(makePlotLine(res.muscles[order[k]].name, x, y, "linespoints"));
    }
    PlotFigure fig;
    fig.title = "transfer sweep";
    fig.panels.push_back(p);
    report.addPlot("transfer_sweep", fig, "Change of the force-time integral against the transfer fraction.");
  }
}

void addGaitStudyView(const GaitStudyOptions& opt, const std::string& report_dir,
                      const view::ViewAssets& assets, Report& report) {
  TrialView tv{opt.trial.model_file, opt.trial.coordinates_file, opt.base, "no muscle mass"};
  if (opt.physiological) {
    tv.mass.source = osim::MuscleMassOptions::Source::Physiological;
    tv.mass_note = "the physiological run's";
  } else if (!opt.transfer_body.empty() && !opt.transfer_values.empty()) {
    tv.mass.source = osim::MuscleMassOptions::Source::Transfer;
    tv.mass.transfer_body = opt.transfer_body;
    tv.mass.transfer_fraction = *std::max_element(opt.transfer_values.begin(), opt.transfer_values.end());
    std::ostringstream note;
    note << "the largest transfer fraction, " << tv.mass.transfer_fraction;
    tv.mass_note = note.str();
  } else {
    tv.mass.source = osim::MuscleMassOptions::Source::None;
  }
  addTrialView(report, report_dir, tv, assets);
}

}  // namespace redmax::validation
