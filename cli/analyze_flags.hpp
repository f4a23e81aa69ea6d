#pragma once
// The flags of `redmax analyze` (OpenSim's AnalyzeTool), declared once: the command and the Python
// module's redmax.analyze (python/redmax_module.cpp) parse them with these declarations.
#include <string>

#include "cli/flags.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "converter/analyze/analyze_tool.hpp"

namespace redmax::cli {

struct AnalyzeFlags {
  std::string setup, out_dir, muscle_class;
  bool quiet = false;
  MuscleMassFlags muscle_mass;
};

/// Declares --setup (required), --out-dir, --muscle-class, --quiet and the MUSCLE-MASS OPTIONS.
void addAnalyzeFlags(CLI::App& app, AnalyzeFlags& f);

/// The tool's settings from the parsed flags. Throws UsageError for bad muscle-mass flags.
osim::AnalyzeToolSettings parseAnalyzeFlags(const AnalyzeFlags& f, const CLI::App& app);

}  // namespace redmax::cli
