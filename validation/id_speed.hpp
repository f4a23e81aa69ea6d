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
  /// also time the core with muscle mass (default: physiological mass in every muscle, 20 points,
  /// wrapping muscles on the smooth model, as `redmax id --muscle-mass physiological`); Source::None
  /// skips it
  osim::MuscleMassOptions muscle_mass = defaultMuscleMass();
  static osim::MuscleMassOptions defaultMuscleMass() {
    osim::MuscleMassOptions m;
    m.source = osim::MuscleMassOptions::Source::Physiological;
    m.wrap_mass = true;
    return m;
  }
};

struct IdSpeedResult {
  std::string model;                 ///< model file
  int frames = 0;
  int dofs = 0;
  double setup_seconds = 0;          ///< reading and processing the inputs (tool construction)
  double core_us_per_frame = 0;      ///< fastest batch / frames
  double simbody_us_per_frame = 0;   ///< 0 when Simbody did not run
  std::string simbody_note;          ///< why it did not run, or the inertia fallback it needed
  double core_mass_matrix_us = 0;    ///< the core's reference route tau = M qddot - f (CoreIdEngine::Route)
  double bare_recursive_us = 0;      ///< inverseDynamicsRecursive alone on the same tree and frames
                                     ///< (no loads, no OpenSim input mapping): the floor of the trial path
  // with muscle mass (0 when not timed)
  int mass_muscles = 0, mass_points = 0;
  double muscle_mass_kg = 0;
  double core_mass_us = 0;           ///< recursive route (mass points as body wrenches)
  double core_mass_matrix_mass_us = 0;  ///< mass-matrix route
  double whole_run_seconds = 0;      ///< setup + core solve of every frame + writing the .sto
  double ratio() const { return simbody_us_per_frame > 0 ? core_us_per_frame / simbody_us_per_frame : 0; }
};

/// Time both engines on the trial. Throws what the tool throws for bad inputs (ConvertError).
IdSpeedResult timeIdEngines(const IdSpeedOptions& options);

/// A short table for the terminal.
std::string formatIdSpeed(const IdSpeedResult& r);

}  // namespace redmax::validation
