#pragma once
// The finger-flick stability study of [D Sec. 6.2.5, Fig. 1.1]: an index finger whose flexors FDP
// and FDS are lumped into the bones (OpenSim's view) or carry 0.2 kg each in mass points, a force
// on the fingertip during the first two 1 ms steps, semi-implicit Euler at 1 ms for 1 s. A run
// survives when it ends without a NaN/divergence and without gaining energy after the flick: the
// finger (under gravity or not) is conservative once the flick ends, so a gain is numerical; the
// total energy may not exceed its value at the end of the flick by more than `energy_growth` times
// the largest kinetic energy seen so far. Without joint limits a joint may turn freely, through
// the bone (every run records the largest excursion beyond a coordinate's range; it is no sign of
// instability there); with `joint_limits` the ranges are hard unilateral constraints of the bdf1
// step (docs/contact.md §6), so the finger stops at its ranges.
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
  /// "": no limits; "hard" (every coordinate's range) or "clamped" (the clamped ones) as hard
  /// unilateral constraints (bdf1 only), with this restitution
  std::string joint_limits;
  double limit_restitution = 0.0;
};

struct FlickRun {
  double force = 0.0;   ///< N
  bool survived = false;
  std::string why;      ///< failure reason ("" when it survived)
  double max_excursion = 0.0;  ///< rad (m): the largest excursion of a coordinate beyond its range
};

/// One run with a force of magnitude `force` (N) along options.direction.
FlickRun runFlick(const FlickOptions& options, double force);

struct FlickSearch {
  double largest_survived = 0.0;  ///< N; 0 if even `lo` failed
  double smallest_failed = 0.0;   ///< N; +inf if even `hi` survived
  double excursion = 0.0;         ///< max_excursion of the run at largest_survived
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
