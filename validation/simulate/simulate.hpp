#pragma once
// Forward simulation of an OpenSim model in the REDMAX core: the driver behind `redmax simulate`
// (docs/commands.md §1), reusable by studies (finger flick, work-precision reports).
//
//   .osim --readOsimModel--> description --(muscle mass)--> buildCoreModel (constraints on)
//         --> System: skeleton (gravity from the model) + MuscleTerm (muscles with mass points)
//                     + constraints (locked, coupled, prescribed coordinates, welds) + impulses
//         --> makeIntegrator(name) --> rows of (t, q, qdot, kinetic, potential, total energy)
//
// Output columns (OpenSim's absolute state names, so that OpenSim 4 reads the file as states):
//   time, /jointset/<joint>/<coord>/value for every coordinate (q order), then
//   /jointset/<joint>/<coord>/speed for every coordinate, then kinetic_energy, potential_energy,
//   total_energy. SI units, radians (inDegrees=no). With constraints or hyper-reduced coordinates
//   every skeleton coordinate is written (the expanded state).
//
// Energy. Kinetic energy is the skeleton's plus the mass points'; potential energy is gravity's
// (reference: the world origin) plus the ForceTerms' (joint springs when the core model has any).
// The impulse loads are non-conservative and add no potential.
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/build/muscle_mass.hpp"
#include "converter/model_description.hpp"
#include "converter/storage.hpp"
#include "core/dynamics/force_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"

namespace redmax::validation {

/// A force on a body while the simulation time t < duration (the dissertation's fingertip flick,
/// 6.2.5: applied during the first two 1 ms steps; runs start at t = 0 unless --initial says so). `target` names a body, a marker (the force acts at the
/// marker) or "BODY@x,y,z" (a point in the body frame, m).
struct ImpulseSpec {
  std::string target;
  Vec3 force_w = Vec3::Zero();  ///< N, ground (world) frame
  double duration = 0.0;        ///< s: active while t < duration
};

/// Parse "TARGET:FX,FY,FZ:DURATION" (force in N in the ground frame, duration in s). Throws
/// std::invalid_argument with the text and what is wrong.
ImpulseSpec parseImpulse(const std::string& text);

/// How the model is set up for simulation.
struct SimulationModelOptions {
  /// --muscle-mass options (none: the model as OpenSim sees it)
  osim::MuscleMassOptions muscle_mass;
  /// explicit per-muscle masses in kg (--muscle-mass-kg NAME=KG): ADDED to the model (no body
  /// gives mass; the dissertation's finger carries 0.2 kg per flexor, four times its bones), spread
  /// over muscle_mass.mass_points points in muscle_mass.region. Excludes a muscle-mass source.
  std::vector<std::pair<std::string, double>> explicit_masses;
  /// keep the muscles' quadratic velocity vector (false: the dissertation's energy experiment 6.2.4)
  bool quadratic_velocity = true;
  std::vector<ImpulseSpec> impulses;
  /// replaces the model's gravity (m/s^2, ground frame) when set, e.g. zero for a flick study
  std::optional<Vec3> gravity;
  osim::BuildOptions build;  ///< constraints on by default
};

/// A ForceTerm applying constant world forces at body points while t < t_end (no potential).
class ImpulseLoads final : public ForceTerm {
 public:
  struct Load {
    int body = -1;
    Vec3 point_i = Vec3::Zero();  // body frame
    Vec3 force_w = Vec3::Zero();  // world frame
    double t_end = 0.0;
  };
  explicit ImpulseLoads(std::vector<Load> loads) : loads_(std::move(loads)) {}
  std::string name() const override { return "impulse_loads"; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  const std::vector<Load>& loads() const { return loads_; }
  /// true while any load acts at time t
  bool active(double t) const;

 private:
  std::vector<Load> loads_;
};

/// A model ready to simulate.
struct SimulationModel {
  osim::ModelDescription description;  ///< after the muscle mass moved (if it did)
  /// build.model: the model with everything that defines it (gravity, muscles with their mass
  /// points, constraints)
  osim::BuildResult build;
  std::shared_ptr<const MuscleTerm> muscle_term;    ///< null when no muscle carries mass
  std::shared_ptr<const ImpulseLoads> impulses;     ///< null without impulses
  std::shared_ptr<System> system;
  std::vector<std::string> q_labels, u_labels;      ///< output column names (nr each)
  std::vector<std::string> coordinate_names;        ///< skeleton q order (nr)
  std::string mass_summary;  ///< human-readable: who carries mass, what moved (empty when lumped)
  double added_mass = 0.0;   ///< kg added by explicit masses (not taken from a body)
  double muscle_mass = 0.0;  ///< kg carried by mass points in total
};

/// Read, give muscles mass, build. Throws osim::ConvertError (FILE:LINE), std::invalid_argument
/// (bad options, e.g. an unknown muscle or body name) or ModelError.
SimulationModel loadSimulationModel(const std::string& osim_path, const SimulationModelOptions& options);
SimulationModel makeSimulationModel(const osim::ModelDescription& d, const SimulationModelOptions& options);

/// Marker `name` of m's MarkerSet in the core model: its core body (-1 when it sits on ground or on
/// a body the core model split away) and its location in that body's frame (the marker's frame
/// offset applied); found false when the MarkerSet has no such marker (mk then null).
struct CoreMarker {
  const osim::MarkerDesc* mk = nullptr;
  int body = -1;
  Vec3 point = Vec3::Zero();
};
CoreMarker findCoreMarker(const SimulationModel& m, const std::string& name);

/// The model's default state: each coordinate's default_value and default_speed_value, at t = 0,
/// projected onto the constraints.
State defaultInitialState(const SimulationModel& m);

/// A state from a states/motion table: the row whose time equals `time` (within 1e-9 s; NaN: the
/// row at t = 0 if there is one, else the first row). Columns are matched by coordinate name,
/// OpenSim's absolute state path (/jointset/J/C/value, /speed) or <coord>_u (OpenSim 3 speeds);
/// rotational values and speeds are converted from degrees when the table says inDegrees=yes;
/// coordinates absent from the table keep their defaults. The state's time is the row's. Throws
/// osim::ConvertError naming `file` when no column matches or no row has that time.
State initialStateFromStorage(const SimulationModel& m, const osim::Storage& table, const std::string& file,
                              double time = std::numeric_limits<double>::quiet_NaN());

struct SimulateOptions {
  std::string integrator = "rk45";   ///< euler, symplectic, bdf1, sdirk2, rk45, cvode
  IntegratorOptions integrator_options;
  double duration = 1.0;             ///< s, simulated from the initial state's time
  /// s between output rows; 0: 0.01 s, or dt when the fixed step is larger. Fixed-step methods
  /// round it to a whole number of steps, so that every step has length dt.
  double output_dt = 0.0;
  /// called after every output row with the time reached (progress reports)
  std::function<void(double t)> on_row;
  /// called after every output row; a non-empty return stops the run as a failure with that message
  /// (studies use it to call a run unstable, e.g. when its energy grows)
  std::function<std::string(const State& s, double kinetic, double potential)> check;
  /// network wrap model: receives the fallback counts of the run's workspaces after every span
  /// (so its sink warns early); null: not counted. Only simulate() (the core engine) fills it.
  WrapFallbackMonitor* wrap_fallbacks = nullptr;
};

/// The contacts of a run (docs/contact.md), sampled at the output rows.
struct ContactStats {
  int contacts = 0;            ///< contact pairs the system's contact terms watch (0: none)
  int active_final = 0;        ///< touching at the last row
  int active_max = 0;          ///< most touching at one row
  double max_penetration = 0.0;  ///< m, over all rows and contacts
  std::string deepest;         ///< the contact that had it
  double deepest_time = 0.0;
  /// the largest |sum of the contact forces| on the second surfaces (the spheres) at one row: the
  /// ground reaction when the ground's half-space is every pair's first surface (N)
  double max_force = 0.0;
  double max_force_up = 0.0;   ///< its world y component (OpenSim's up) at that row (N)
  double max_force_time = 0.0;
};

struct SimulationResult {
  osim::Storage states;     ///< the rows reached (up to the failure if the run failed)
  ContactStats contacts;
  State final_state;        ///< system state at the last row
  IntegratorStats stats;    ///< summed over the run's segments
  double wall_s = 0.0;
  double energy_initial = 0.0, energy_final = 0.0;
  /// max over rows of |E(t) - E(t0)|, absolute (J) and relative to max(|E(t0)|, max kinetic energy)
  double energy_drift_abs = 0.0, energy_drift_rel = 0.0;
  bool failed = false;
  std::string failure;      ///< what diverged or failed the check, with the time and step
  double failure_time = 0.0, failure_step = 0.0;
};

/// An empty states table of m's runs (core or Simbody): q, qdot, then the three energy columns,
/// then the system's auxiliary states (System::stateNames(), docs/forward.md) when it has any.
SimulationResult makeStatesResult(const SimulationModel& m);

/// The rows of a run's STATES table (time; q, qdot, kinetic, potential and total energy) and its
/// energy bookkeeping, shared by the core and the Simbody drivers so that both report drift alike.
class StateRecorder {
 public:
  explicit StateRecorder(SimulationResult& res) : res_(res) {}
  /// Append a row and update res's energies. False when a value is not finite: res.failed is set
  /// and res.failure says so at time t, followed by `where` (e.g. " (Simbody)").
  /// z: the auxiliary states (empty without), after the energies.
  bool add(double t, const VecX& q, const VecX& qdot, double K, double V, const std::string& where = "",
           const VecX& z = VecX());
  /// Copy the rows into res.states.data (one column per label of res.states) and set
  /// res.energy_drift_rel.
  void finish();

 private:
  SimulationResult& res_;
  std::vector<VecX> rows_;
  double max_ke_ = 0.0;
};

/// Integrate from `initial` for options.duration. A NaN, divergence or a failed check stops the run:
/// failed is set, failure names the time, the coordinate (by name) and the step. A contact whose
/// penetration exceeds its sphere's radius at an output row stops the run too (the step was too
/// large for the contact's stiffness; docs/contact.md §3). Impulse end times
/// are breakpoints: adaptive methods restart there, so the switch-off is not smoothed over. Throws
/// std::invalid_argument for bad options (unknown integrator, non-positive dt or duration).
SimulationResult simulate(const SimulationModel& m, const State& initial, const SimulateOptions& options);

/// Kinetic and potential energy of a system state.
std::pair<double, double> calcEnergies(const SimulationModel& m, const State& s);

}  // namespace redmax::validation
