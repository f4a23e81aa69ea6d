#pragma once
// OpenSim's AnalyzeTool with its StaticOptimization analysis (docs/analyze.md), on the inverse-
// dynamics tool's input processing (converter/id/inverse_dynamics_tool.hpp):
//
//   setup (readAnalyzeSetup) -> AnalyzeTool: the model, the force set (the model's, then
//     force_set_files appended or, with replace_force_set, instead), the coordinates processed as
//     the AnalyzeTool does (pad + low-pass when the cutoff is >= 0, degrees -> radians, quintic
//     natural splines: q, u = s'), the frames findIndex(initial_time) .. findIndex(final_time) of
//     the processed grid, every step_interval-th row plus the first and the last.
//   StaticOptimization per frame: the target accelerations are the derivative of a second quintic
//     spline through the speeds u of every processed row (OpenSim's GCVSplineSet(5, states store)
//     in StaticOptimization::begin); b = inverse dynamics at (q, u, udot_target) with gravity and
//     the external loads (and the muscles' mass points with MUSCLE-MASS OPTIONS); column j of A =
//     F_j (-dl_j/dq) for a muscle (F_j = max isometric force, or with use_muscle_physiology
//     calcInextensibleTendonActiveFiberForce(1) at the frame's path length and speed), the optimal
//     force on its coordinate for a CoordinateActuator; rows: the coordinates that are not locked.
//     Solved by converter/analyze/static_optimization.hpp, warm-started from the previous frame.
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "converter/analyze/muscle_analysis.hpp"
#include "converter/build/muscle_mass.hpp"
#include "converter/controls.hpp"
#include "converter/error.hpp"
#include "converter/storage.hpp"
#include "core/spatial/types.hpp"

namespace redmax::osim {

/// One entry of the setup's AnalysisSet.
struct AnalysisEntry {
  std::string class_name;  ///< e.g. "StaticOptimization", "MuscleAnalysis"
  std::string name;
  bool on = true;
  int line = 0;
};

struct StaticOptimizationSettings {
  bool present = false;  ///< the AnalysisSet has a StaticOptimization that is on
  std::string name = "StaticOptimization";
  double start_time = 0.0, end_time = 0.0;  ///< read; OpenSim 4 records every tool frame anyway
  int step_interval = 1;
  double activation_exponent = 2.0;
  bool use_muscle_physiology = true;
  double optimizer_convergence_criterion = 1e-4;
  int optimizer_max_iterations = 100;
  bool use_model_force_set = true;
  int line = 0;
};

struct AnalyzeSetup {
  std::string name, source_file, directory;
  std::string model_file, coordinates_file, states_file, speeds_file, external_loads_file;
  std::string results_directory;  ///< resolved; the setup's folder when empty
  std::vector<std::string> force_set_files;
  bool replace_force_set = false;
  double initial_time = 0.0, final_time = 1.0;
  double lowpass_cutoff_frequency_for_coordinates = -1.0;
  bool solve_for_equilibrium_for_auxiliary_states = false;
  int output_precision = 8;
  /// the setup's ControllerSet (ControlSetController, PrescribedController) and the tool's own
  /// (OpenSim 3) controls_file, resolved; the controls drive MuscleAnalysis and Actuation
  std::vector<ControllerSetupDesc> controllers;
  std::string controls_file;
  std::vector<AnalysisEntry> analyses;
  StaticOptimizationSettings static_optimization;
  MuscleAnalysisSettings muscle_analysis;
  ActuationSettings actuation;
  std::vector<std::string> warnings;
};

/// Read an AnalyzeTool setup (paths resolved against its folder). Throws ConvertError
/// ("FILE:LINE: what") on malformed input, an AnalysisSet that is empty or holds no analysis
/// that is on.
AnalyzeSetup readAnalyzeSetup(const std::string& path);

struct AnalyzeToolSettings {
  std::string setup_file;
  std::optional<std::string> out_dir;       ///< replaces results_directory
  std::optional<std::string> muscle_class;  ///< every muscle read as this class (renameType)
  MuscleMassOptions muscle_mass;
};

/// One recorded frame of static optimization.
struct StaticOptimizationFrame {
  double time = 0.0;
  VecX activation;  ///< controls, one per actuator (na)
  VecX force;       ///< actuator forces control * F_j (na)
  int iterations = 0;
  double constraint_violation = 0.0;  ///< max |A x - b|, N or N m
  bool converged = false;
  std::string status;  ///< the solver's status, or why the frame could not be set up
};

struct StaticOptimizationRun {
  std::vector<std::string> actuators;  ///< column labels, OpenSim's force-set order
  std::vector<bool> is_muscle;
  std::vector<StaticOptimizationFrame> frames;
  int failed = 0;  ///< frames that did not converge
};

/// The recorded frames of MuscleAnalysis and Actuation (one evaluation per row either records).
struct MuscleAnalysisRun {
  std::vector<MuscleFrame> frames;
  std::vector<char> muscle_analysis, actuation;  ///< per frame: recorded by that analysis
  MuscleAnalysisColumns columns;
  std::vector<ActuationColumn> actuators;
  std::vector<std::string> failures;  ///< "t = T: muscle: why" (equilibrium failures OpenSim warns of)
};

class AnalyzeTool {
 public:
  /// Reads and checks everything (model, force set files, coordinates, external loads, muscle
  /// class, muscle mass, states file). Throws ConvertError for bad input: a setup with no analysis
  /// redmax runs, a coordinate the actuators must drive that the coordinates file lacks (at the
  /// file's label line), an actuator class static optimization does not model, bounds with
  /// min > max.
  explicit AnalyzeTool(AnalyzeToolSettings settings);
  ~AnalyzeTool();
  AnalyzeTool(const AnalyzeTool&) = delete;
  AnalyzeTool& operator=(const AnalyzeTool&) = delete;

  const AnalyzeSetup& setup() const { return setup_; }
  const std::string& outputDirectory() const { return out_dir_; }
  /// analyses of the setup that are on and that redmax does not run, by name and class
  const std::vector<std::string>& unsupportedAnalyses() const { return unsupported_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// the muscle mass the inverse dynamics carries (kg; 0 without MUSCLE-MASS OPTIONS)
  double muscleMass() const;
  std::string muscleMassSummary() const;

  bool runsStaticOptimization() const { return setup_.static_optimization.present; }
  bool runsMuscleAnalyses() const { return setup_.muscle_analysis.present || setup_.actuation.present; }

  /// MuscleAnalysis and Actuation (docs/analyze.md, "MuscleAnalysis", "Actuation"): the muscles at each recorded row after
  /// equilibrium (with solve_for_equilibrium_for_auxiliary_states).
  MuscleAnalysisRun runMuscleAnalyses() const;
  /// `<name>_<MuscleAnalysis>_<quantity>.sto` and `<name>_<Actuation>_force/speed/power.sto`,
  /// formatted first, then each written atomically; returns the paths.
  std::vector<std::string> writeMuscleAnalyses(const MuscleAnalysisRun& run) const;

  /// Every recorded frame. A frame that does not converge is kept with converged = false.
  StaticOptimizationRun runStaticOptimization() const;

  /// `<name>_<analysis>_activation.sto` and `_force.sto` as OpenSim writes them; rows of failed
  /// frames hold nan. Written atomically; returns the paths.
  std::vector<std::string> writeStaticOptimization(const StaticOptimizationRun& run) const;

 private:
  struct Impl;
  void prepareMuscleAnalyses();
  AnalyzeSetup setup_;
  AnalyzeToolSettings settings_;
  std::string out_dir_;
  std::vector<std::string> unsupported_, warnings_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace redmax::osim
