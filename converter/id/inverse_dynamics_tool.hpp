#pragma once
// OpenSim's InverseDynamicsTool as a library (docs/opensim_compatibility.md §7), engine-agnostic:
//
//   settings (setup file, overridden by flags)  -> resolveIdSettings -> IdToolConfig
//   IdToolConfig -> InverseDynamicsTool: model read and built (constraints ignored, muscles left
//     out), coordinates read, padded/resampled/filtered when a cutoff >= 0 is given, degrees ->
//     radians for Rotational columns, quintic natural splines; q functions by exact column name
//     (otherwise the coordinate's default: qdot = qddot = 0); external loads read and interpolated
//     (constant / piecewise linear / natural cubic); output rows findIndex(start)..findIndex(end)
//     on the processed time grid.
//   InverseDynamicsTool::run(engine) -> a Storage named "Inverse Dynamics Generalized Forces":
//     time, then <coord>_moment (Rotational) or <coord>_force (everything else), in q order.
//
// OpenSim compatibility (IdToolConfig::opensim_compat, default on): CustomJoints use Simbody's
// approximate velocity terms (FunctionBased::simbody_compat), and Ball/Free/Ellipsoid joints take
// the data's Euler-angle rates as Simbody's u (IdEngineOptions::rates_as_u). Off ("exact"): the
// core's exact kinematics with qdot = dq/dt everywhere; the output columns are then the
// generalized forces conjugate to the coordinates' rates.
#include <array>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/build/muscle_mass.hpp"
#include "converter/coordinates_file.hpp"
#include "converter/external_loads.hpp"
#include "converter/id/id_engine.hpp"
#include "converter/id_setup.hpp"
#include "converter/model_description.hpp"
#include "converter/signal/coordinate_pipeline.hpp"
#include "converter/signal/load_interpolant.hpp"
#include "converter/storage.hpp"

namespace redmax::osim {

/// What the user asked for. Unset optionals fall back to the setup file (if any), then to
/// OpenSim's defaults. Paths given here are used as given (relative to the current directory);
/// paths from the setup file are resolved against its folder.
struct IdToolSettings {
  std::string setup_file;  ///< "" = none
  std::optional<std::string> model_file, coordinates_file, external_loads_file, output_file;
  std::optional<double> lowpass_cutoff_hz;  ///< < 0: no filtering
  std::optional<double> t0, t1;
  /// ForceSet entries to exclude (keywords All, Actuators, Muscles, case-insensitive; otherwise
  /// group or force names). Without a setup file the default is {"Muscles"}.
  std::optional<std::vector<std::string>> forces_to_exclude;
  bool opensim_compat = true;
  /// muscle mass (default none: OpenSim's model); copied into IdToolConfig::muscle_mass
  MuscleMassOptions muscle_mass;
};

/// Settings after merging flags and setup: everything the tool needs.
struct IdToolConfig {
  std::string setup_file;
  std::string model_file;
  std::string coordinates_file;
  /// the coordinates table already read (e.g. the value columns of an AnalyzeTool states_file,
  /// relabelled by coordinate name); coordinates_file then only names it in messages
  std::optional<Storage> coordinates_table;
  std::string external_loads_file;  ///< "" = none
  /// where an ExternalLoads datafile is looked up first (OpenSim's working directory: the setup
  /// file's folder; "" = the current directory)
  std::string loads_working_dir;
  std::string output_file;  ///< "" = none given
  double lowpass_cutoff_hz = -1.0;
  double t0 = -std::numeric_limits<double>::infinity();
  double t1 = std::numeric_limits<double>::infinity();
  std::vector<std::string> forces_to_exclude;
  bool opensim_compat = true;
  /// muscle mass (converter/build/muscle_mass.hpp): applied after the coordinates are processed,
  /// so that --muscles top:K ranks over the trial's output frames; the engines then get the model
  /// with the bodies' mass reduced (model()) and the muscles with mass points (muscles())
  MuscleMassOptions muscle_mass;
  /// every muscle read as this OpenSim class (readOsimModel's renameType); "" = as written
  std::string muscle_class;
  std::vector<std::string> warnings;  ///< from the setup file (settings 4.x ignores)
};

/// Merge flags over the setup file. Throws ConvertError ("FILE:LINE: what") for an unreadable or
/// malformed setup, and for a missing model or coordinates file name (file "" for flags), or
/// t0 > t1, or non-finite values.
IdToolConfig resolveIdSettings(const IdToolSettings& settings);

/// The velocity convention an engine must use for a model built from `d` (IdToolConfig::
/// opensim_compat: rates_as_u for Ball/Free/Ellipsoid joints), as the tool gives it
/// (engineOptions()); for callers that build the model themselves (redmax.inverse_dynamics of arrays).
IdEngineOptions idEngineOptions(const ModelDescription& d, const BuildResult& build, bool opensim_compat);

/// The output column labels for `model` built from `d`: <coord>_moment (Rotational) or
/// <coord>_force, in q order (InverseDynamicsTool::outputLabels).
std::vector<std::string> idOutputLabels(const ModelDescription& d, const Model& model);

/// One coordinate's source of q(t).
struct IdCoordinateSource {
  std::string name;       ///< the coordinate
  int data_column = -1;   ///< column of the coordinates file with exactly this label; -1: none
  int spline = -1;        ///< index into processed().splines; -1: constant
  double constant = 0.0;  ///< the default value used when spline < 0 (qdot = qddot = 0)
  bool converted = false; ///< the column was multiplied by pi/180 (degrees file, Rotational)
};

/// One ExternalForce, ready to sample (converter/external_loads.hpp).
using IdLoadSource = LoadSource;

class InverseDynamicsTool {
 public:
  /// Read and prepare everything. Throws ConvertError ("FILE[:LINE]: what") for missing or
  /// malformed files, models the core cannot build for ID (an unsupported joint whose coordinates
  /// would need output columns), coordinates files with no column of the model, too few rows,
  /// and unknown bodies in the external loads.
  explicit InverseDynamicsTool(IdToolConfig config);

  const IdToolConfig& config() const { return config_; }
  const ModelDescription& description() const { return description_; }
  const BuildResult& build() const { return *build_; }
  /// the core model the engines get: with muscle mass, the bodies' mass already reduced
  const Model& model() const { return build_->model.skeleton(); }
  /// the whole model: skeleton and, with muscle mass, every built muscle (those with mass carry
  /// their points); without muscle mass no muscles (the model as OpenSim's ID sees it)
  const MusculoskeletalModel& musculoskeletalModel() const { return build_->model; }
  /// what the muscle-mass options did (source None: every muscle lumped, no bodies changed)
  const MuscleMassPlan& muscleMassPlan() const { return muscle_mass_plan_; }
  /// the description the model was built from (bodies with their mass reduced); the file's own
  /// description is description()
  const ModelDescription& massDescription() const { return mass_description_; }
  /// the velocity convention the engines must use (rates_as_u for Ball/Free/Ellipsoid joints in
  /// OpenSim-compatible mode)
  const IdEngineOptions& engineOptions() const { return engine_options_; }
  const Storage& coordinatesData() const { return coordinates_; }
  const signal::ProcessedCoordinates& processed() const { return processed_; }
  const std::vector<IdCoordinateSource>& coordinateSources() const { return sources_; }
  const std::vector<IdLoadSource>& loadSources() const { return loads_; }
  const signal::TimeWindow& window() const { return window_; }
  /// forces OpenSim would still apply that redmax does not model (name and class); empty for the
  /// shared sets, which exclude their muscles and have no other forces
  const std::vector<std::string>& unmodelledForces() const { return unmodelled_forces_; }
  /// everything OpenSim would log, and what redmax adds (missing columns, unmodelled forces)
  const std::vector<std::string>& warnings() const { return warnings_; }

  int numFrames() const { return window_.numRows(); }
  double frameTime(int k) const { return processed_.time[window_.first_row + k]; }
  /// output column labels: <coord>_moment or <coord>_force, in q order (no "time")
  std::vector<std::string> outputLabels() const;

  /// q, v = s'(t), vdot = s''(t) (nr) and the external loads at time t (any t, not only frames)
  void calcInputs(double t, VecX& q, VecX& v, VecX& vdot, std::vector<IdLoadSample>& loads) const;

  /// Solve every output frame with the engine (which must have been made for model() with
  /// engineOptions()). progress(done, total) is called after each frame when given. Throws
  /// IdEngineError on a frame the engine cannot solve or non-finite generalized forces.
  Storage run(IdEngine& engine, const std::function<void(int, int)>& progress = {}) const;

 private:
  IdToolConfig config_;
  ModelDescription description_;
  std::unique_ptr<BuildResult> build_;
  IdEngineOptions engine_options_;
  Storage coordinates_;
  signal::ProcessedCoordinates processed_;
  std::vector<IdCoordinateSource> sources_;
  std::vector<IdLoadSource> loads_;
  signal::TimeWindow window_;
  std::vector<std::string> unmodelled_forces_;
  std::vector<std::string> warnings_;
  MuscleMassPlan muscle_mass_plan_;
  ModelDescription mass_description_;

  void checkForces();
  void applyMuscleMassOptions();
  void prepareCoordinates();
  void prepareLoads();
};

/// The storage name OpenSim gives ID results
inline constexpr const char* kIdStorageName = "Inverse Dynamics Generalized Forces";

}  // namespace redmax::osim
