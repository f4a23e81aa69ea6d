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

  int failed = 0;
  if (tool->runsMuscleAnalyses()) {
    const auto start = std::chrono::steady_clock::now();
    const osim::MuscleAnalysisRun mrun = tool->runMuscleAnalyses();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // OpenSim warns of a muscle it cannot equilibrate and records the state as it is
    for (const auto& w : mrun.failures) std::cerr << "warning: muscle equilibrium failed at " << w << "\n";
    std::vector<std::string> files;
    try {
      files = tool->writeMuscleAnalyses(mrun);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      return 2;
    }
    if (!f.quiet) {
      std::printf("analyze: muscle analyses: %zu frames, %zu muscles, %zu moment-arm coordinates, %zu actuators, "
                  "%zu equilibrium failures, %.3f s wall\n",
                  mrun.frames.size(), mrun.columns.muscles.size(), mrun.columns.coordinates.size(),
                  mrun.actuators.size(), mrun.failures.size(), wall);
      std::printf("  -> %zu files in %s\n", files.size(), tool->outputDirectory().c_str());
    }
  }
  if (!tool->runsStaticOptimization()) return 0;

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
                   (tool->setup().states_file.empty() ? tool->setup().coordinates_file : tool->setup().states_file).c_str(), fr.time, fr.status.c_str());
      continue;
    }
    iterations += fr.iterations;
    max_iterations = std::max(max_iterations, fr.iterations);
    violation = std::max(violation, fr.constraint_violation);
  }
  failed = run.failed;
  if (!f.quiet) {
    const int n = static_cast<int>(run.frames.size()), ok = n - run.failed;
    std::printf("analyze: %s: %d frames (%d failed), %zu actuators, %.1f mean / %d max iterations, "
                "max |A x - b| %.3g, muscle mass %.6g kg, %.3f s wall, %.0f frames/s\n",
                tool->setup().static_optimization.name.c_str(), n, run.failed, run.actuators.size(),
                ok > 0 ? static_cast<double>(iterations) / ok : 0.0, max_iterations, violation,
                tool->muscleMass(), wall, wall > 0 ? n / wall : 0.0);
    for (const auto& p : files) std::printf("  -> %s\n", p.c_str());
  }
  return failed > 0 ? 1 : 0;
}

CommandRegistration reg(
    {"analyze", "OpenSim's AnalyzeTool: static optimization, muscle analysis, actuation; with or without muscle mass", [](CLI::App& app) {
       auto f = std::make_shared<AnalyzeFlags>();
       addAnalyzeFlags(app, *f);
       app.footer(std::string(
           "usage: redmax analyze --setup ANALYZE_SETUP.xml [--out-dir DIR] [--muscle-class CLASS]\n"
           "                      [--quiet] [MUSCLE-MASS OPTIONS]\n"
           "Runs the setup's StaticOptimization, MuscleAnalysis and Actuation as OpenSim 4.x's AnalyzeTool\n"
           "does (docs/analyze.md). States: a states_file (OpenSim 4 or 3 state names: q, u and the muscles'\n"
           "states, unfiltered) or a coordinates_file processed as for inverse dynamics (pad and low-pass\n"
           "with lowpass_cutoff_frequency_for_coordinates, degrees to radians, quintic splines for q and u),\n"
           "the rows initial_time..final_time (every step_interval-th row, the first and the last).\n"
           "StaticOptimization: target accelerations from a second quintic spline through u, per frame\n"
           "min sum |x|^p (activation_exponent) subject to the inverse-dynamics generalized forces and the\n"
           "actuators' min/max control (muscles, CoordinateActuators of the model and force_set_files).\n"
           "MuscleAnalysis: each muscle at the state's activation (default_activation without one), its\n"
           "fibre in equilibrium with solve_for_equilibrium_for_auxiliary_states; lengths, velocities,\n"
           "forces, powers, moment arms and moments for moment_arm_coordinate_list. Actuation: force,\n"
           "speed and power of every actuator. With MUSCLE-MASS OPTIONS the generalized forces include the\n"
           "muscles' mass points. Other analyses of the setup are listed as not supported. Writes\n"
           "DIR/<name>_<analysis>_<quantity>.sto (OpenSim's names and headers) atomically. Exit codes:\n"
           "0 success, 1 a static-optimization frame did not converge (named on stderr and in the files'\n"
           "header, its row nan), 2 bad input or usage (nothing written).\n") +
           muscleMassFooter());
       return [f, &app] { return runAnalyze(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
