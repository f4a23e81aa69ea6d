// `redmax analyze`: OpenSim's AnalyzeTool with its StaticOptimization analysis
// (docs/analyze.md). converter/analyze/ does the work; this file parses flags and reports.
// Exit codes: 2 bad input or usage (nothing written), 1 a frame that did not converge (the files
// are written with that row as nan and the frame named), 0 success.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/analyze_flags.hpp"
#include "converter/analyze/analyze_tool.hpp"

namespace redmax::cli {
namespace {

int runAnalyze(const AnalyzeFlags& f, const CLI::App& app) {
  const osim::AnalyzeToolSettings settings = parseAnalyzeFlags(f, app);
  const bool with_mass = settings.muscle_mass.source != osim::MuscleMassOptions::Source::None;

  std::unique_ptr<osim::AnalyzeTool> tool;
  try {
    tool = std::make_unique<osim::AnalyzeTool>(settings);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << f.setup << ": " << e.what() << "\n";
    return 2;
  }
  for (const auto& w : tool->warnings()) std::cerr << "warning: " << w << "\n";
  for (const auto& a : tool->unsupportedAnalyses())
    std::cerr << "warning: analysis " << a << " is not supported by redmax: not run, no output\n";
  if (with_mass && !f.quiet) std::cerr << tool->muscleMassSummary();

  const auto start = std::chrono::steady_clock::now();
  const osim::StaticOptimizationRun run = tool->runStaticOptimization();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<std::string> files;
  try {
    files = tool->writeStaticOptimization(run);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  int iterations = 0, max_iterations = 0;
  double violation = 0.0;
  for (const auto& fr : run.frames) {
    if (!fr.converged) {
      std::fprintf(stderr, "error: %s: static optimization failed at t = %.10g: %s\n",
                   tool->setup().coordinates_file.c_str(), fr.time, fr.status.c_str());
      continue;
    }
    iterations += fr.iterations;
    max_iterations = std::max(max_iterations, fr.iterations);
    violation = std::max(violation, fr.constraint_violation);
  }
  if (!f.quiet) {
    const int n = static_cast<int>(run.frames.size()), ok = n - run.failed;
    std::printf("analyze: %s: %d frames (%d failed), %zu actuators, %.1f mean / %d max iterations, "
                "max |A x - b| %.3g, muscle mass %.6g kg, %.3f s wall, %.0f frames/s\n",
                tool->setup().static_optimization.name.c_str(), n, run.failed, run.actuators.size(),
                ok > 0 ? static_cast<double>(iterations) / ok : 0.0, max_iterations, violation,
                tool->muscleMass(), wall, wall > 0 ? n / wall : 0.0);
    for (const auto& p : files) std::printf("  -> %s\n", p.c_str());
  }
  return run.failed > 0 ? 1 : 0;
}

CommandRegistration reg(
    {"analyze", "OpenSim's AnalyzeTool: static optimization, with or without muscle mass", [](CLI::App& app) {
       auto f = std::make_shared<AnalyzeFlags>();
       addAnalyzeFlags(app, *f);
       app.footer(std::string(
           "usage: redmax analyze --setup ANALYZE_SETUP.xml [--out-dir DIR] [--muscle-class CLASS]\n"
           "                      [--quiet] [MUSCLE-MASS OPTIONS]\n"
           "Runs the setup's StaticOptimization as OpenSim 4.x's AnalyzeTool does: the coordinates\n"
           "processed as for inverse dynamics (pad and low-pass with lowpass_cutoff_frequency_for_\n"
           "coordinates, degrees to radians, quintic splines for q and u), target accelerations from a\n"
           "second quintic spline through u, the frames initial_time..final_time (every step_interval-th\n"
           "row and the last), per frame min sum |x|^p (activation_exponent) subject to the inverse-\n"
           "dynamics generalized forces and the actuators' min/max control, muscle forces from\n"
           "use_muscle_physiology (rigid-tendon active fibre force) or the maximum isometric force,\n"
           "CoordinateActuators from the model and force_set_files. With MUSCLE-MASS OPTIONS the\n"
           "generalized forces include the muscles' mass points. Other analyses of the setup are listed\n"
           "as not supported. Writes DIR/<name>_<analysis>_activation.sto, _force.sto (OpenSim's names\n"
           "and headers) atomically. Exit codes: 0 success, 1 a frame did not converge (named on stderr\n"
           "and in the files' header, its row nan), 2 bad input or usage (nothing written).\n") +
           muscleMassFooter());
       return [f, &app] { return runAnalyze(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
