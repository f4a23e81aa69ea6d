#include "validation/analyze_speed.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

#include "validation/id_speed.hpp"

namespace redmax::validation {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// fastest of `batches` calls of run(), seconds; the last result goes to *out
template <class Run, class Out>
double fastest(int batches, Run run, Out* out) {
  double best = std::numeric_limits<double>::infinity();
  for (int b = 0; b < std::max(1, batches); ++b) {
    const auto t0 = Clock::now();
    *out = run();
    best = std::min(best, since(t0));
  }
  return best;
}

}  // namespace

AnalyzeSpeedResult timeAnalyze(const AnalyzeSpeedOptions& options) {
  AnalyzeSpeedResult r;
  r.setup = options.settings.setup_file;
  osim::AnalyzeToolSettings massless = options.settings;
  massless.muscle_mass = {};
  const auto t_setup = Clock::now();
  const osim::AnalyzeTool tool(massless);
  r.setup_seconds = since(t_setup);

  if (tool.runsStaticOptimization()) {
    osim::StaticOptimizationRun run;
    r.so_seconds = fastest(options.batches, [&] { return tool.runStaticOptimization(); }, &run);
    r.so_frames = static_cast<int>(run.frames.size());
    r.so_failed = run.failed;
    r.actuators = static_cast<int>(run.actuators.size());
    double it = 0;
    for (const auto& f : run.frames) it += f.iterations;
    r.so_mean_iterations = run.frames.empty() ? 0.0 : it / static_cast<double>(run.frames.size());
    if (options.muscle_mass) {
      osim::AnalyzeToolSettings with = options.settings;
      with.muscle_mass = IdSpeedOptions::defaultMuscleMass();
      const osim::AnalyzeTool mass_tool(with);
      r.muscle_mass_kg = mass_tool.muscleMass();
      osim::StaticOptimizationRun mrun;
      r.so_mass_seconds = fastest(options.batches, [&] { return mass_tool.runStaticOptimization(); }, &mrun);
      r.so_mass_frames = static_cast<int>(mrun.frames.size());
      r.so_mass_failed = mrun.failed;
    }
  }
  if (tool.runsMuscleAnalyses()) {
    osim::MuscleAnalysisRun run;
    r.ma_seconds = fastest(options.batches, [&] { return tool.runMuscleAnalyses(); }, &run);
    r.ma_frames = static_cast<int>(run.frames.size());
    r.muscles = static_cast<int>(run.columns.muscles.size());
  }
  return r;
}

std::string formatAnalyzeSpeed(const AnalyzeSpeedResult& r) {
  char buf[1024];
  std::string s;
  std::snprintf(buf, sizeof buf, "redmax analyze on %s (fastest of the passes, 1 thread; setup %.3f s apart)\n",
                r.setup.c_str(), r.setup_seconds);
  s += buf;
  if (r.so_frames > 0) {
    std::snprintf(buf, sizeof buf,
                  "  StaticOptimization: %d frames, %d actuators, %.1f IPOPT iterations per frame, %d failed: "
                  "%.4f s, %.1f frames/s\n",
                  r.so_frames, r.actuators, r.so_mean_iterations, r.so_failed, r.so_seconds,
                  r.perSecond(r.so_frames, r.so_seconds));
    s += buf;
    if (r.so_mass_frames > 0) {
      std::snprintf(buf, sizeof buf,
                    "  StaticOptimization with muscle mass (physiological, %.3f kg): %d failed: %.4f s, %.1f frames/s "
                    "(time ratio with / without mass %.3f)\n",
                    r.muscle_mass_kg, r.so_mass_failed, r.so_mass_seconds, r.perSecond(r.so_mass_frames, r.so_mass_seconds),
                    r.so_seconds > 0 ? r.so_mass_seconds / r.so_seconds : 0.0);
      s += buf;
    }
  }
  if (r.ma_frames > 0) {
    std::snprintf(buf, sizeof buf, "  MuscleAnalysis + Actuation: %d frames, %d muscles: %.4f s, %.1f frames/s\n",
                  r.ma_frames, r.muscles, r.ma_seconds, r.perSecond(r.ma_frames, r.ma_seconds));
    s += buf;
  }
  s += "  To compare: time OpenSim's `opensim-cmd run-tool SETUP` on the same setup (frames / its wall time).\n";
  return s;
}

}  // namespace redmax::validation
