#pragma once
// The flags of `redmax validate`, declared once: the command and the Python module's
// redmax.validate (python/redmax_module.cpp) parse them with these declarations.
#include <string>
#include <vector>

#include "cli/id_flags.hpp"
#include "validation/id_validation.hpp"

namespace redmax::cli {

struct ValidateFlags {
  IdInputFlags in;
  std::vector<std::string> references, published;
  std::string report, mass_sweep, sweep_columns, interpolation, gnuplot;
  double tolerance = validation::IdValidationOptions{}.reference_rms_rel;
  double max_tolerance = 0.0;
  double engine_tolerance = validation::IdValidationOptions{}.engine_rel;
  bool quiet = false, no_simbody = false, no_plots = false, view = false;
};

/// Declares the ID input flags (cli/id_flags.hpp), the comparisons, the mass sweep, --report,
/// --no-plots, --gnuplot and --quiet on `app`.
void addValidateFlags(CLI::App& app, ValidateFlags& f);

/// The validation's options from the parsed flags (progress on unless --quiet). Throws UsageError
/// for inconsistent flags (a sweep without a muscle-mass source, no --report, ...).
validation::IdValidationOptions parseValidateFlags(const ValidateFlags& f, const CLI::App& app);

}  // namespace redmax::cli
