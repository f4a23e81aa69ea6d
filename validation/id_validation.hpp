#pragma once
// `redmax validate` as a library function (DESIGN.md §3): one inverse-dynamics trial, processed
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
#include <limits>
#include <string>
#include <vector>

#include "converter/id/inverse_dynamics_tool.hpp"
#include "validation/compare/metrics.hpp"
#include "validation/report/report.hpp"

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
};

/// Run the validation and write the report into opt.report_dir.
/// Throws osim::ConvertError (bad model, coordinates, loads, setup or reference file) and
/// CompareError (a reference with no common column or no overlapping time): bad input, exit 2.
/// Throws osim::IdEngineError when the core cannot solve a frame, ReportError when the report
/// cannot be written: the run failed, exit 1. A Simbody engine that fails on a frame is recorded
/// as a failed check, not thrown.
IdValidationResult runIdValidation(const IdValidationOptions& opt);

/// The short summary `redmax validate` prints: one line per engine (frames, seconds, frames/s),
/// one per comparison (worst column, its RMS/peak and max/peak, PASS/FAIL), then the verdict.
std::string formatIdValidationSummary(const IdValidationResult& r);

}  // namespace redmax::validation
