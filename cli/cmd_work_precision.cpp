// `redmax work-precision`: error against cost for every integrator on the project's scenes
// (validation/work_precision/work_precision.hpp does the work; this file parses flags).
// Exit codes: 0 report written, 1 the report could not be written or a model failed to load,
// 2 bad input or usage.
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli/flags.hpp"
#include "converter/error.hpp"
#include "converter/id/id_engine.hpp"
#include "validation/work_precision/work_precision.hpp"

namespace redmax::cli {
namespace {

namespace fs = std::filesystem;


// --models, else ./osim_models, else osim_models beside an ancestor of the executable's folder
struct WorkPrecisionFlags {
  std::string report, models, scenes, integrators, gnuplot, studies, shared;
  bool quick = false, no_plots = false;
};

std::string findModelsDir(const WorkPrecisionFlags& f, const CLI::App& app) {
  if (given(app, "--models")) {
    const std::string* d = &f.models;
    if (!fs::is_regular_file(fs::path(*d) / "double_pendulum_via.osim"))
      throw UsageError{"--models " + *d + ": no double_pendulum_via.osim there"};
    return *d;
  }
  if (fs::is_regular_file("osim_models/double_pendulum_via.osim")) return "osim_models";
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  for (int up = 0; !ec && up < 5 && p.has_parent_path() && p != p.root_path(); ++up) {
    p = p.parent_path();
    if (fs::is_regular_file(p / "osim_models" / "double_pendulum_via.osim")) return (p / "osim_models").string();
  }
  throw UsageError{"cannot find osim_models/ (run from the repository root or pass --models DIR)"};
}

// --shared, else $REDMAX_SHARED_DIR, else ../shared beside the repository holding the models ("" if
// none: the ID studies then fall back to the running leg and say so)
std::string findSharedDir(const WorkPrecisionFlags& f, const CLI::App& app, const std::string& models_dir) {
  if (given(app, "--shared")) {
    const std::string* d = &f.shared;
    if (!fs::is_directory(*d)) throw UsageError{"--shared " + *d + ": not a directory"};
    return *d;
  }
  if (const char* env = std::getenv("REDMAX_SHARED_DIR"); env && *env && fs::is_directory(env)) return env;
  std::error_code ec;
  const fs::path repo = fs::absolute(models_dir, ec).parent_path();
  if (!ec && fs::is_directory(repo.parent_path() / "shared" / "opensim")) return (repo.parent_path() / "shared").string();
  return "";
}

int runWorkPrecision(const WorkPrecisionFlags& f, const CLI::App& app) {
  const std::string* dir = &f.report;
  if (dir->empty()) throw UsageError{"--report DIR is required"};
  validation::WorkPrecisionOptions opt;
  opt.quick = f.quick;
  opt.models_dir = findModelsDir(f, app);
  if (given(app, "--scenes")) opt.scenes = splitList(f.scenes);
  if (given(app, "--integrators")) opt.integrators = splitList(f.integrators);
  opt.gnuplot = f.no_plots ? "none" : f.gnuplot;
  if (given(app, "--studies")) {
    opt.studies = splitList(f.studies);
    if (opt.studies.empty()) throw UsageError{"--studies needs a list (integrators,masspoints,reduction,hard)"};
    const auto all = validation::workPrecisionStudyNames();
    for (const auto& st : opt.studies)
      if (std::find(all.begin(), all.end(), st) == all.end())
        throw UsageError{"--studies: unknown study '" + st + "' (expected integrators, masspoints, reduction, hard)"};
  }
  opt.shared_dir = findSharedDir(f, app, opt.models_dir);
  // the report folder must be creatable before the runs are spent
  std::error_code ec;
  fs::create_directories(*dir, ec);
  if (ec || !fs::is_directory(*dir)) {
    std::cerr << "error: " << *dir << ": cannot create the report directory" << (ec ? ": " + ec.message() : "") << "\n";
    return 1;
  }
  try {
    const auto res = validation::runWorkPrecision(*dir, opt, &std::cerr);
    for (const auto& s : res.scenes) {
      std::cout << s.name << ":";
      for (std::size_t k = 0; k < opt.targets.size(); ++k) {
        std::cout << "  error <= " << opt.targets[k] << ": ";
        if (s.recommended[k] < 0) {
          std::cout << "none";
        } else {
          const auto& r = s.runs[s.recommended[k]];
          std::cout << r.integrator << " " << r.knob << " " << r.value << " (error " << r.error << ", " << r.cpu_s
                    << " s CPU)";
        }
      }
      std::cout << "\n";
    }
    const auto& id = res.id_studies;
    if (id.has_masspoints || id.has_reduction)
      std::cout << "id studies on " << id.trial.name << (id.trial.note.empty() ? "" : " (" + id.trial.note + ")")
                << ":\n";
    if (id.has_masspoints) {
      std::cout << "  mass points per muscle: ";
      if (id.recommended_points < 0) std::cout << "no N reaches " << 100 * id.target << "% of the inertial effect\n";
      for (const auto& row : id.masspoints)
        if (row.value == id.recommended_points)
          std::cout << "N = " << row.value << " (error " << row.error.err_effect << " of the inertial effect, "
                    << row.cpu_per_frame_s << " s CPU per frame)\n";
    }
    if (id.has_reduction) {
      std::cout << "  top-K muscles with mass:";
      for (const auto& row : id.reduction) std::cout << " K=" << row.label << ": " << row.error.err_effect;
      std::cout << " (error of the inertial effect)\n";
    }
    if (res.files.plots_skipped) std::cout << "plots skipped: " << res.files.plots_note << "\n";
    std::cout << "report: " << *dir << "/report.md\n";
    return 0;
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const validation::ReportError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  } catch (const osim::IdEngineError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
}

CommandRegistration reg(
    {"work-precision", "error against CPU time for every integrator on the project's scenes", [](CLI::App& app) {
       auto f = std::make_shared<WorkPrecisionFlags>();
       app.add_option("--report", f->report, "the report folder (required)")->type_name("DIR");
       app.add_flag("--quick", f->quick, "0.5 s per scene and 3-rung ladders (about 30 s instead of minutes)");
       app.add_option("--models", f->models, "the osim_models folder (default: ./osim_models or the repository's)")
           ->type_name("DIR");
       app.add_option("--scenes", f->scenes,
                      "comma-separated subset of pendulum_straight,pendulum_via,pendulum_wrap,\n"
                      "finger,running_leg")
           ->type_name("LIST");
       app.add_option("--integrators", f->integrators,
                      "comma-separated subset of euler,symplectic,bdf1,sdirk2,rk45,cvode")
           ->type_name("LIST");
       app.add_option("--studies", f->studies,
                      "comma-separated subset of integrators,masspoints,reduction,hard (default all).\n"
                      "masspoints: ID torque error against 500 mass points per muscle for N = 2..100\n"
                      "and CPU time per frame, with the recommended N; reduction: only the top-K\n"
                      "muscles by inertia contribution carry mass, K = 0, 1, 2, 5, 10, all. Trial: set F\n"
                      "of the shared OpenSim data with physiological muscle mass (--quick, or without\n"
                      "the shared data: the running leg, and the report says so). Writes\n"
                      "id_masspoints.csv|png, id_reduction.csv|png, id_reduction_ranking.csv; hard:\n"
                      "stability cases (hard_cases.csv), the finger flick's largest force and impulse\n"
                      "survived, lumped vs inertial, per integrator and step (hard_flick.csv), the\n"
                      "energy jump at each wrap contact change per path model (hard_wrap_jumps.csv)")
           ->type_name("LIST");
       app.add_option("--shared", f->shared,
                      "the shared data folder holding opensim/ (default $REDMAX_SHARED_DIR, else\n"
                      "../shared beside the repository)")
           ->type_name("DIR");
       app.add_option("--gnuplot", f->gnuplot, "the gnuplot executable, or none (default: found on PATH)")
           ->type_name("PATH|none");
       app.add_flag("--no-plots", f->no_plots, "no plots");
       app.footer(
           "usage: redmax work-precision --report DIR [--quick] [--models DIR] [--scenes LIST] [--integrators LIST]\n"
           "                             [--studies LIST] [--shared DIR] [--gnuplot PATH|none] [--no-plots]\n"
           "Runs every integrator (euler, symplectic, bdf1, sdirk2 over fixed steps 1e-2..5e-5 s; rk45, cvode over\n"
           "rtol 1e-3..1e-10, atol = 1e-2 rtol) on the scenes pendulum_straight, pendulum_via, pendulum_wrap, finger\n"
           "and running_leg (osim_models/, muscle mass on their Type I/II/III muscles) and measures the state error\n"
           "at the end against rk45 at rtol 1e-12, CPU time, right-hand-side evaluations and energy drift per\n"
           "simulated second. Diverged runs are marked.\n"
           "Writes DIR/<scene>.csv, DIR/<scene>.png|svg (log-log error vs CPU time), DIR/report.md (tables and\n"
           "the recommended integrator per scene for errors <= 1e-3 and <= 1e-6) and DIR/summary.json.\n"
           "exit codes: 0 report written, 1 a model could not be loaded or the report not written, 2 bad input.");
       return [f, &app] { return runWorkPrecision(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
