#pragma once
// Speed of inverse dynamics on a real trial, both engines in one run (`redmax bench --id-setup`):
// the time per frame of each engine's calcGeneralizedForces on the same processed inputs (the
// tool's splines and loads are evaluated once beforehand, so only the engines are timed), their
// ratio, and the time of a whole `redmax id` run (read and process the inputs, solve every frame
// with the core, write the .sto) against the frame count.
#include <string>
#include <vector>

#include "converter/id/inverse_dynamics_tool.hpp"

namespace redmax::validation {

struct IdSpeedOptions {
  osim::IdToolSettings settings;  ///< the same inputs as `redmax id`
  int batches = 5;                ///< each engine solves all frames `batches` times; the fastest counts
  bool simbody = true;
};

struct IdSpeedResult {
  std::string model;                 ///< model file
  int frames = 0;
  int dofs = 0;
  double setup_seconds = 0;          ///< reading and processing the inputs (tool construction)
  double core_us_per_frame = 0;      ///< fastest batch / frames
  double simbody_us_per_frame = 0;   ///< 0 when Simbody did not run
  std::string simbody_note;          ///< why it did not run, or the inertia fallback it needed
  double whole_run_seconds = 0;      ///< setup + core solve of every frame + writing the .sto
  double ratio() const { return simbody_us_per_frame > 0 ? core_us_per_frame / simbody_us_per_frame : 0; }
};

/// Time both engines on the trial. Throws what the tool throws for bad inputs (ConvertError).
IdSpeedResult timeIdEngines(const IdSpeedOptions& options);

/// A short table for the terminal.
std::string formatIdSpeed(const IdSpeedResult& r);

}  // namespace redmax::validation
