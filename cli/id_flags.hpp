#pragma once
// The input flags `redmax id` and `redmax validate` share (an InverseDynamicsTool's inputs), declared
// once: --setup, --model, --coordinates, --external-loads, --lowpass, --t0, --t1,
// --forces-to-exclude, --exact / --opensim-compat, and the MUSCLE-MASS OPTIONS.
#include <string>

#include "cli/flags.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"

namespace redmax::cli {

struct IdInputFlags {
  std::string setup, model, coordinates, external_loads, forces_to_exclude;
  double lowpass = -1.0, t0 = 0.0, t1 = 0.0;
  bool exact = false, opensim_compat = false;
  MuscleMassFlags muscle_mass;
};

/// Declares the flags on `app` (help groups "Inputs" and "Muscle mass").
void addIdInputFlags(CLI::App& app, IdInputFlags& f);

/// The settings from the flags, without the muscle mass (callers parse it: validate's sweep gives the
/// transfer fractions). `command` names the command in messages ("id needs --setup ...").
/// Throws UsageError when neither a setup nor a model with coordinates is given, for --t0 after
/// --t1, and for --exact with --opensim-compat.
osim::IdToolSettings parseIdInputFlags(const IdInputFlags& f, const CLI::App& app, const std::string& command);

}  // namespace redmax::cli
