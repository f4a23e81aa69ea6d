#pragma once
// The MUSCLE-MASS OPTIONS of DESIGN.md section 3, shared by every command that builds a model with
// muscle mass (`redmax id`, `simulate`, `validate`, ...):
//   --muscle-mass none|physiological|transfer   (default none)
//   --muscles all|REGEX|top:K   --mass-points N   --mass-region fibre|whole
//   --specific-tension PA       --muscle-density KG_M3
//   --transfer-body BODY        --transfer-fraction F
// Meanings and defaults: converter/build/muscle_mass.hpp.
#include <set>
#include <string>

#include "cli/args.hpp"
#include "converter/build/muscle_mass.hpp"

namespace redmax::cli {

/// value-flag names (without dashes) of the muscle-mass options: add them to a command's Args
const std::set<std::string>& muscleMassFlagNames();

/// `names` plus the muscle-mass flags, for building an Args
std::set<std::string> withMuscleMassFlags(std::set<std::string> names);

/// The options from the flags (defaults for those not given). Throws UsageError for a value that
/// cannot be parsed or is out of range (N < 1, tension or density <= 0, F outside [0, 1), a bad
/// REGEX or top:K), for transfer without --transfer-body, and for --muscles, --mass-points,
/// --mass-region, --specific-tension, --muscle-density, --transfer-* given without a source that
/// uses them (a flag that would do nothing is a mistake).
osim::MuscleMassOptions parseMuscleMassFlags(const Args& args);

/// The options' lines for a command's --help (ends with a newline)
const char* muscleMassUsage();

}  // namespace redmax::cli
