// `redmax gait-study`: a trial's static optimization at zero muscle mass, physiological muscle mass
// and over a transfer sweep, per muscle the change of peak force, activation and force-time
// integral, as a report folder (docs/analyze.md, "Gait study"). validation/gait_study.hpp does the work.
// Exit codes: 0 every run converged at every frame, 1 a frame failed (named in the report) or the
// report could not be written, 2 bad input or usage.
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/id_flags.hpp"
#include "core/muscles/hill/factory.hpp"
#include "validation/gait_study.hpp"
#include "validation/mass_sweep.hpp"

namespace redmax::cli {
namespace {

struct GaitStudyFlags {
  IdInputFlags in;
  std::string report, mass_sweep, gnuplot, muscle_class;
  double reserve_force = 1.0, residual_force = 1.0;
  int step_interval = 1;
  bool no_physiological = false, no_plots = false, quiet = false, view = false;
};

int runGaitStudy(const GaitStudyFlags& f, const CLI::App& app) {
  validation::GaitStudyOptions opt;
  const osim::IdToolSettings settings = parseIdInputFlags(f.in, app, "gait-study");
  if (f.report.empty()) throw UsageError{"gait-study needs --report DIR"};
  if (given(app, "--transfer-fraction")) throw UsageError{"--mass-sweep gives the transfer fractions"};
  // the options of the mass runs (points, region, density, ...); the study sets the source per run
  opt.base = parseMuscleMassFlags(f.in.muscle_mass, true);
  if (opt.base.source == osim::MuscleMassOptions::Source::Transfer) {
    opt.transfer_body = opt.base.transfer_body;
    opt.transfer_values = validation::parseMassSweepValues(given(app, "--mass-sweep") ? f.mass_sweep : "0.2,0.4,0.6,0.8");
  } else if (given(app, "--mass-sweep")) {
    throw UsageError{"--mass-sweep needs --muscle-mass transfer --transfer-body BODY"};
  }
  opt.physiological = !f.no_physiological;
  opt.reserve_optimal_force = f.reserve_force;
  opt.residual_optimal_force = f.residual_force;
  opt.step_interval = f.step_interval;
  opt.muscle_class = f.muscle_class;
  opt.progress = !f.quiet;
  view::ViewAssets assets;  // found before the runs: a missing page file is a usage error, not a late failure
  if (f.view) {
    try {
      assets = view::findViewAssets(viewAssetFolders());
    } catch (const std::runtime_error& e) {
      throw UsageError{std::string("--view: ") + e.what()};
    }
  }

  validation::GaitStudyResult res;
  try {
    opt.trial = osim::resolveIdSettings(settings);
    res = validation::runGaitStudy(opt, f.report + "/setup");
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  validation::ReportOptions ro;
  ro.title = "redmax gait study: static optimization with muscle mass";
  ro.gnuplot = f.no_plots ? "none" : f.gnuplot;
  validation::Report report(f.report, ro);
  validation::addGaitStudy(res, opt, report);
  if (f.view) {
    try {
      validation::addGaitStudyView(opt, f.report, assets, report);
    } catch (const validation::ReportError& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 1;
    }
  }
  validation::ReportFiles files;
  try {
    files = report.write();
  } catch (const validation::ReportError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  if (!f.quiet) {
    for (const auto& w : res.warnings) std::cerr << "warning: " << w << "\n";
    std::printf("report: %s/report.md, summary.json%s\n", f.report.c_str(),
                files.plots_skipped ? (" (plots skipped: " + files.plots_note + ")").c_str() : "");
  }
  return report.passed() ? 0 : 1;
}

CommandRegistration reg(
    {"gait-study", "static optimization of a trial at zero, physiological and transferred muscle mass: a report",
     [](CLI::App& app) {
       auto f = std::make_shared<GaitStudyFlags>();
       addIdInputFlags(app, f->in);
       app.add_option("--mass-sweep", f->mass_sweep,
                      "transfer fractions in [0, 1) with --muscle-mass transfer --transfer-body BODY\n(default 0.2,0.4,0.6,0.8; 0 is added)")
           ->type_name("V1,V2,...")
           ->group("Muscle mass");
       app.add_flag("--no-physiological", f->no_physiological, "skip the physiological-mass run")->group("Muscle mass");
       app.add_option("--reserve-force", f->reserve_force, "optimal force of the generated reserves (default 1)")
           ->type_name("N_M")
           ->check(CLI::PositiveNumber);
       app.add_option("--residual-force", f->residual_force,
                      "optimal force of the generated pelvis residuals (default 1)")
           ->type_name("N")
           ->check(CLI::PositiveNumber);
       app.add_option("--step-interval", f->step_interval, "StaticOptimization's step_interval (default 1)")
           ->type_name("K")
           ->check(CLI::PositiveNumber);
       app.add_option("--muscle-class", f->muscle_class, "read every muscle as CLASS (OpenSim's Object::renameType)")
           ->type_name("CLASS")
           ->check(oneOf(hill::muscleModelClasses()));
       app.add_option("--report", f->report, "the report folder (required)")->type_name("DIR");
       app.add_flag("--no-plots", f->no_plots, "no gnuplot plots");
       app.add_flag("--view", f->view,
                    "also write the trial's `redmax view` into DIR/view (the physiological run's mass\n"
                    "points, else the largest transfer fraction's), linked from report.md (docs/view.md)");
       app.add_option("--gnuplot", f->gnuplot, "the gnuplot executable (default: found on PATH)")->type_name("PATH");
       app.add_flag("--quiet", f->quiet, "no progress, summary or warnings");
       app.footer(std::string(
           "usage: redmax gait-study (--setup ID_SETUP.xml | --model M.osim --coordinates Q.mot)\n"
           "                 [--external-loads LOADS.xml] [--lowpass HZ] [--t0 S] [--t1 S]\n"
           "                 [--muscle-mass transfer --transfer-body BODY [--mass-sweep V1,V2,...]]\n"
           "                 [MUSCLE-MASS OPTIONS] [--no-physiological]\n"
           "                 [--reserve-force F] [--residual-force F] [--step-interval K]\n"
           "                 [--muscle-class CLASS] [--no-plots] [--gnuplot PATH] [--quiet] --report DIR\n"
           "The trial's inputs are `redmax id`'s. Writes its own AnalyzeTool setup into DIR/setup/: the\n"
           "trial, OpenSim's StaticOptimization (exponent 2, muscle physiology on) and a CoordinateActuator\n"
           "on every coordinate that is not locked (<coord>_residual on the root joint's, <coord>_reserve on\n"
           "the others, controls unbounded), and runs it at zero muscle mass, at physiological muscle mass\n"
           "and, with --muscle-mass transfer, for each transfer fraction (0 included: it must equal zero mass\n"
           "exactly). DIR receives runs.csv, muscles.csv (per muscle and run: peak force, peak activation,\n"
           "force-time integral and their change from zero mass), plots muscle_forces and transfer_sweep,\n"
           "report.md (the muscles that change most) and summary.json (gait_study section).\n"
           "Exit codes: 0 every frame of every run converged, 1 a frame failed or the report could not be\n"
           "written, 2 bad input or usage.\n") + muscleMassFooter());
       return [f, &app] { return runGaitStudy(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
