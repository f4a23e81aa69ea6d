#pragma once
// The finger-flick stability study of [D Sec. 6.2.5, Fig. 1.1]: an index finger whose flexors FDP
// and FDS are lumped into the bones (OpenSim's view) or carry 0.2 kg each in mass points, a force
// on the fingertip during the first two 1 ms steps, semi-implicit Euler at 1 ms for 1 s. A run
// survives when it ends without a NaN/divergence and without gaining energy after the flick: the
// finger (under gravity or not) is conservative once the flick ends, so a gain is numerical; the
// total energy may not exceed its value at the end of the flick by more than `energy_growth` times
// the largest kinetic energy seen so far. (The model has no joint limits, so a joint may turn
// freely: excursions are no sign of instability here and are not checked.)
// The largest force survived is found by a geometric scan followed by bisection.
#include <string>
#include <vector>

#include "validation/simulate/simulate.hpp"

namespace redmax::validation {

struct FlickOptions {
  std::string model_path;               ///< e.g. osim_models/finger.osim
  std::string target = "fingertip";     ///< body, marker or BODY@x,y,z (ImpulseSpec)
  Vec3 direction = Vec3::UnitY();       ///< unit force direction, ground frame (+y: dorsal)
  double impulse_time = 0.002;          ///< s (two 1 ms steps)
  std::string integrator = "euler";
  double dt = 1e-3;
  double duration = 1.0;
  double energy_growth = 0.5;           ///< allowed energy gain, as a fraction of the max kinetic energy
  bool gravity = true;                  ///< false: gravity off (the finger rests until flicked)
  /// muscle name -> kg of mass points (empty: lumped)
  std::vector<std::pair<std::string, double>> muscle_masses;
  int mass_points = 20;
};

struct FlickRun {
  double force = 0.0;   ///< N
  bool survived = false;
  std::string why;      ///< failure reason ("" when it survived)
};

/// One run with a force of magnitude `force` (N) along options.direction.
FlickRun runFlick(const FlickOptions& options, double force);

struct FlickSearch {
  double largest_survived = 0.0;  ///< N; 0 if even `lo` failed
  double smallest_failed = 0.0;   ///< N; +inf if even `hi` survived
  std::string first_failure;      ///< why the run at smallest_failed failed
  std::vector<FlickRun> runs;     ///< every run, in the order made
};

/// Scan forces lo, lo*step, ... up to hi until one fails, then bisect (geometric mean) between the
/// last survivor and the first failure until their ratio is below 1 + rel_tol.
FlickSearch findLargestSurvivedFlick(const FlickOptions& options, double lo = 0.5, double hi = 2000.0,
                                     double step = 2.0, double rel_tol = 0.01);

/// One line of the study table: the thresholds of one integrator, variant and gravity setting.
struct FlickStudyRow {
  std::string integrator;
  double dt = 0.0;           ///< s
  std::string variant;       ///< "lumped" or "inertial"
  bool gravity = true;
  FlickSearch artifact;      ///< energy-growth criterion (options.energy_growth)
  FlickSearch divergence;    ///< NaN/overflow only
};

/// The study of [D 6.2.5]: for each gravity setting, step size (empty: base.dt), integrator and
/// variant (lumped; inertial with `inertial_kg` in each of FDP and FDS), the largest force survived
/// under both criteria. The flick lasts base.impulse_time whatever the step.
std::vector<FlickStudyRow> runFlickStudy(const FlickOptions& base, const std::vector<std::string>& integrators,
                                         const std::vector<bool>& gravity, double inertial_kg = 0.2,
                                         const std::vector<double>& dts = {});

/// The rows as a markdown table (forces in N, the first failing force in brackets) and as CSV.
std::string formatFlickTable(const std::vector<FlickStudyRow>& rows);
std::string formatFlickCsv(const std::vector<FlickStudyRow>& rows);

}  // namespace redmax::validation
