#pragma once
// The flags of `redmax forward` (OpenSim's ForwardTool), declared once: the command and the Python
// module's redmax.forward (python/redmax_module.cpp) parse them with these declarations.
#include <string>

#include "cli/flags.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "validation/forward/forward_tool.hpp"

namespace redmax::cli {

struct ForwardFlags {
  std::string setup, out_dir, muscle_class, integrator = "rk45";
  double report_interval = 0.01, tolerance = 0.0;
  bool quiet = false, strict = false, view = false;
  MuscleMassFlags mm;
};

/// Declares --setup, --out-dir, --muscle-class, --integrator, --report-interval, --tolerance,
/// --quiet, --strict, --view and the MUSCLE-MASS OPTIONS on `app`.
void addForwardFlags(CLI::App& app, ForwardFlags& f);

/// The tool's settings from the parsed flags. Throws UsageError without --setup, for bad
/// muscle-mass flags and for --view when the page files cannot be found.
validation::ForwardToolSettings parseForwardFlags(const ForwardFlags& f, const CLI::App& app);

}  // namespace redmax::cli
