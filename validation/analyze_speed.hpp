#pragma once
// Speed of `redmax analyze` on a setup (`redmax bench --analyze-setup`): frames per second of each
// analysis the setup runs, the tool's construction (reading the model and data, processing the
// coordinates) timed apart. Static optimization is timed without and with muscle mass
// (physiological mass in every muscle, as `redmax id --muscle-mass physiological`). OpenSim's
// AnalyzeTool on the same setups: validation/bench/opensim_side_by_side_bench.cpp.
#include <string>

#include "converter/analyze/analyze_tool.hpp"

namespace redmax::validation {

struct AnalyzeSpeedOptions {
  osim::AnalyzeToolSettings settings;  ///< the same inputs as `redmax analyze` (muscle_mass ignored)
  int batches = 3;                     ///< each analysis runs over all frames `batches` times; the fastest counts
  bool muscle_mass = true;             ///< also time static optimization with physiological muscle mass
};

struct AnalyzeSpeedResult {
  std::string setup;
  double setup_seconds = 0;            ///< AnalyzeTool construction (massless)
  int so_frames = 0, so_failed = 0, actuators = 0;
  double so_seconds = 0;               ///< fastest pass over every static-optimization frame
  double so_mean_iterations = 0;
  int so_mass_frames = 0, so_mass_failed = 0;
  double so_mass_seconds = 0, muscle_mass_kg = 0;
  int ma_frames = 0, muscles = 0;
  double ma_seconds = 0;               ///< fastest pass of MuscleAnalysis and Actuation
  double perSecond(int frames, double seconds) const { return seconds > 0 ? frames / seconds : 0.0; }
};

/// Time the setup's analyses. Throws what the tool throws for bad input (ConvertError).
AnalyzeSpeedResult timeAnalyze(const AnalyzeSpeedOptions& options);

/// A short table for the terminal.
std::string formatAnalyzeSpeed(const AnalyzeSpeedResult& r);

}  // namespace redmax::validation
