#pragma once
// `redmax validate` as a library function (docs/commands.md §1): one inverse-dynamics trial, processed
// once by converter/id's InverseDynamicsTool, solved by both engines (core and Simbody), and
// compared:
//   core_vs_simbody       every column, every frame: |core - simbody| <= engine_rel * column peak
//                         (plus a tiny absolute floor for columns that are ~0)
//   core_vs_<reference>   each reference .sto (e.g. OpenSim 4.6's own ID result, a published one):
//                         columns matched by name, the overlapping time range, the reference's
//                         rows as the grid with core interpolated; RMS <= reference_rms_rel * peak
// and a report directory (validation/report/report.hpp: summary.json, CSVs, plots, report.md)
// with each engine's wall time (frames, seconds, frames per second) in summary.speed.
// If the Simbody engine cannot build the model, the reason is recorded (summary.engines.simbody)
// and validation continues with core only; that alone does not fail the run.
//
// Muscle mass (issue 6). The comparisons above always use the zero-mass core and the zero-mass
// Simbody system (OpenSim has no muscle inertia: its results are zero-mass references). With
// IdValidationOptions::muscle_mass set, the core is also solved with that muscle mass and its
// difference from the zero-mass core is reported per column as the "inertial effect"
// (summary.inertial_effect, inertial_effect.csv, an overlay, core_mass_id.sto): a measurement,
// never a failure. With mass_sweep values, the core is solved once per value instead
// (validation/mass_sweep.hpp; summary.mass_sweep); of the sweep, its zero check (the value 0,
// massless points, reproduces the zero-mass result), the value 0 against each reference, and
// Simbody at every value can fail. In both cases, when the Simbody engine runs, Simbody
// with muscle inertia (plugin/simbody, the same model and mass points) solves the muscle-mass
// trial (every sweep value) too: core_mass_vs_simbody_mass at the engine tolerance, a
// check in the verdict (summary.simbody_mass_check), recorded only when wrapping muscles carry
// mass over the exact wrap model (simbodyMassCheckNotCountedReason).
#include <limits>
#include <string>
#include <vector>

#include "converter/build/muscle_mass.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "validation/compare/metrics.hpp"
#include "validation/mass_sweep.hpp"
#include "validation/report/report.hpp"
#include "view/view.hpp"

namespace redmax::validation {

/// One reference result to compare the core against.
struct IdReference {
  std::string path;   ///< an OpenSim-style .sto (time, then <coord>_moment / <coord>_force)
  std::string label;  ///< legend label and comparison suffix ("opensim", "published")
};

struct IdValidationOptions {
  osim::IdToolSettings settings;      ///< the same inputs as `redmax id`
  std::string loads_working_dir;      ///< overrides IdToolConfig::loads_working_dir if not ""
  std::vector<IdReference> references;
  std::string report_dir;             ///< required
  bool run_simbody = true;            ///< false: core only (recorded as skipped)
  /// core vs simbody: max |d| <= engine_rel * peak (and RMS likewise), absolute floor engine_abs
  double engine_rel = 1e-9;
  double engine_abs = 1e-10;
  /// core vs a reference: RMS <= reference_rms_rel * peak (+ reference_abs); max |d| <=
  /// reference_max_rel * peak (+ reference_abs), unlimited by default (max is reported only)
  double reference_rms_rel = 1e-6;
  double reference_max_rel = std::numeric_limits<double>::infinity();
  double reference_abs = 1e-9;
  Interpolation interpolation = Interpolation::Linear;
  std::string gnuplot;  ///< Report's hint: "" auto, "none" no plots, or a path
  bool progress = false;  ///< progress lines on stderr while the engines run
  /// muscle mass of the core's extra run (Source::None: none); with mass_sweep, the sweep's base
  osim::MuscleMassOptions muscle_mass;
  /// non-empty: a muscle-mass sweep over these values (mass_sweep.hpp) instead of one extra run
  std::vector<double> mass_sweep;
  /// columns the sweep's figures show (empty: chooseMainColumns)
  std::vector<std::string> sweep_columns;
  /// the page files of `redmax view` (view/view.hpp); given (index_html not empty), the trial's
  /// view (model, coordinates file, muscle mass; a sweep's largest value) is written into
  /// report_dir/view and linked from report.md
  view::ViewAssets view;
};

/// The core with muscle mass against the zero-mass core: per-column differences (a = with mass,
/// b = zero mass; rms_rel and max_rel relative to the zero-mass peak). Not pass/fail.
struct InertialEffect {
  osim::MuscleMassOptions options;
  double muscle_mass = 0;      ///< kg in mass points
  int muscles_with_mass = 0;
  std::string description;     ///< osim::describeMuscleMass
  double seconds = 0;          ///< solving every frame with mass
  std::vector<ColumnMetrics> metrics;  ///< every column, table order
  int largest = -1;            ///< the column with the largest max_rel (-1 if none)
  bool simbody_ran = false;    ///< Simbody with muscle inertia solved it too
  Comparison simbody_check;    ///< core_mass_vs_simbody_mass: counted unless simbody_not_counted says why
  std::string simbody_not_counted;
  std::string simbody_skipped; ///< why not, when the zero-mass Simbody ran but this one failed
  std::string simbody_note;    ///< the inertia fallback both engines needed for it ("" when none)
};

/// Wall time of one engine over the trial.
struct IdEngineRun {
  std::string name;
  bool ran = false;
  std::string skipped;  ///< why the engine did not run ("" if it ran)
  int frames = 0;
  double build_seconds = 0;  ///< making the engine from the model
  double seconds = 0;        ///< solving every frame
  double framesPerSecond() const { return seconds > 0 ? frames / seconds : 0.0; }
};

struct IdValidationResult {
  std::vector<IdEngineRun> engines;      ///< core, then simbody
  std::vector<Comparison> comparisons;   ///< core_vs_simbody (if it ran), then one per reference
  std::vector<std::string> warnings;     ///< the tool's warnings and the harness's own
  ReportFiles files;
  bool passed = false;                   ///< every comparison and check passed
  bool has_inertial_effect = false;      ///< options.muscle_mass set without a sweep
  InertialEffect inertial_effect;
  bool has_mass_sweep = false;           ///< options.mass_sweep given
  MassSweepResult mass_sweep;
};

/// Run the validation and write the report into opt.report_dir.
/// Throws osim::ConvertError (bad model, coordinates, loads, setup or reference file, muscle-mass
/// options the model rejects), std::invalid_argument (bad muscle-mass options or sweep values) and
/// CompareError (a reference with no common column or no overlapping time): bad input, exit 2.
/// Throws osim::IdEngineError when the core cannot solve a frame, ReportError when the report
/// cannot be written: the run failed, exit 1. A Simbody engine that fails on a frame is recorded
/// as a failed check, not thrown.
IdValidationResult runIdValidation(const IdValidationOptions& opt);

/// The short summary `redmax validate` prints: one line per engine (frames, seconds, frames/s),
/// one per comparison (worst column, its RMS/peak and max/peak, PASS/FAIL), the inertial effect or
/// the mass sweep when run, then the verdict.
std::string formatIdValidationSummary(const IdValidationResult& r);

}  // namespace redmax::validation
