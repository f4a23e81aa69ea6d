#pragma once
// What muscle inertia does to a gait study's static optimization (`redmax gait-study`, docs/analyze.md,
// "Gait study"): one trial (model, coordinates, external loads, as for inverse dynamics), OpenSim's
// StaticOptimization run by the AnalyzeTool at zero muscle mass, at physiological muscle mass and
// over a transfer sweep (a fraction of one body's mass moved into the muscles that span it), and
// per muscle the change of peak force, peak activation and force-time integral from the zero-mass run.
//
// The study writes its own AnalyzeTool setup into REPORT/setup/: the trial's files by absolute path,
// StaticOptimization with OpenSim's defaults (activation exponent 2, muscle physiology on), and a
// force set of CoordinateActuators, one per coordinate that is not locked or prescribed: residuals
// (`<coord>_residual`) on the pelvis (root) coordinates, reserves (`<coord>_reserve`) on every other,
// controls unbounded. Gait trials need them: the pelvis has no muscle, and a few joints (arms,
// lumbar) have none or too few to meet the inverse-dynamics moments.
#include <string>
#include <vector>

#include "converter/analyze/analyze_tool.hpp"
#include "converter/build/muscle_mass.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "validation/report/report.hpp"
#include "view/view.hpp"

namespace redmax::validation {

struct GaitStudyOptions {
  /// the trial (model, coordinates, external loads, lowpass, t0, t1), as `redmax id` resolves it
  osim::IdToolConfig trial;
  /// mass points, region, specific tension, density of the physiological and transfer runs
  osim::MuscleMassOptions base;
  bool physiological = true;            ///< run physiological muscle mass
  std::string transfer_body;            ///< "" = no transfer sweep
  std::vector<double> transfer_values;  ///< fractions in [0, 1); 0 is added
  double reserve_optimal_force = 1.0;   ///< N m or N per unit control
  double residual_optimal_force = 1.0;  ///< of the pelvis (root joint) coordinates
  int step_interval = 1;                ///< StaticOptimization's step_interval
  std::string muscle_class;             ///< "" = as written
  bool progress = false;                ///< a line per run on stderr
};

/// One static-optimization run of the study.
struct GaitStudyRun {
  std::string label;          ///< "zero", "physiological", "transfer 0.4"
  double muscle_mass = 0.0;   ///< kg on mass points
  double wall_s = 0.0;
  osim::StaticOptimizationRun so;
};

/// Per muscle, from the frames that converged in every run.
struct GaitStudyMuscle {
  std::string name;
  std::vector<double> peak_force, peak_activation, force_integral;  ///< per run (N, -, N s)
};

struct GaitStudyResult {
  std::string setup_file, reserves_file;
  std::vector<std::string> reserves;   ///< the generated actuators' names
  std::vector<std::string> warnings;   ///< the tool's (unmodelled forces, ...)
  std::vector<GaitStudyRun> runs;      ///< zero first
  std::vector<GaitStudyMuscle> muscles;
  int frames = 0, frames_used = 0;     ///< recorded frames; those converged in every run
};

/// Write the study's setup into setup_dir and run every value. Throws osim::ConvertError for bad
/// input (as `redmax analyze`), std::invalid_argument for bad options.
GaitStudyResult runGaitStudy(const GaitStudyOptions& options, const std::string& setup_dir);

/// relative change (x - x0) / |x0|, nan when x0 is 0
double relativeChange(double x, double x0);

/// Tables, plots, checks and the text of the study into the report.
void addGaitStudy(const GaitStudyResult& result, const GaitStudyOptions& options, Report& report);

/// The trial's `redmax view` in report_dir/view, linked from report.md: the mass points of the
/// physiological run, else of the largest transfer fraction, else none. Throws ReportError.
void addGaitStudyView(const GaitStudyOptions& options, const std::string& report_dir,
                      const view::ViewAssets& assets, Report& report);

}  // namespace redmax::validation
