#pragma once
// The MUSCLE-MASS OPTIONS of docs/commands.md §1, shared by every command that builds a model with
// muscle mass (`redmax id`, `simulate`, `validate`, ...):
//   --muscle-mass none|physiological|transfer   (default none)
//   --muscles all|REGEX|top:K   --mass-points N   --mass-region fibre|whole
//   --specific-tension PA       --muscle-density KG_M3
//   --transfer-body BODY        --transfer-fraction F
//   --wrap smooth|exact|neural|lumped  --wrap-width W  --wrap-network FILE
//     the wrap model of wrapping (Type III) muscles with mass. Default smooth: every command that
//     builds muscle mass gives wrapping muscles of a supported shape (core/muscles/wrap_muscle.hpp)
//     their mass over the smooth model (C2 across contact changes, so energy-consistent); exact and
//     neural are the dissertation's routes; lumped keeps them massless.
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

/// The wrap flags alone (--wrap, --wrap-width, --wrap-network) into o.wrap_mass and o.wrap, for a
/// source that gives mass (also `simulate --muscle-mass-kg`). Not given: wrap_mass on, smooth
/// model, default width. lumped: wrap_mass off. Throws UsageError for an unknown model, a width
/// that is not a positive finite number of metres or given without smooth/neural, --wrap-network
/// without neural, neural without --wrap-network or with a file loadWrapNetwork refuses. neural
/// sets o.wrap.network and a WrapFallbackMonitor (o.wrap.monitor) that warns on stderr once per
/// muscle; commands print its summary().
void parseWrapFlags(const Args& args, osim::MuscleMassOptions& o);

/// true when any of --wrap, --wrap-width, --wrap-network is given
bool hasWrapFlags(const Args& args);

/// The options' lines for a command's --help (ends with a newline)
const char* muscleMassUsage();

}  // namespace redmax::cli
