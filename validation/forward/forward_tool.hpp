#pragma once
// OpenSim's ForwardTool in the REDMAX core: the library behind `redmax forward` and
// `redmax simulate --controls` (docs/forward.md).
//
//   setup (converter/forward_setup.hpp) -> model_file read, force_set_files appended
//     (replace_force_set: the model's forces dropped), built as for `simulate`
//     (makeSimulationModel: constraints, muscle mass) -> --muscle-class override -> System:
//     the skeleton (+ MuscleTerm with mass) + MuscleForceTerm (muscles with a model) + the
//     ForceSet's actuators and passive forces (converter/build/force_terms.hpp) + the
//     external_loads_file as a SampledLoadsTerm; controllers from the ControllerSet
//     (ControlSetController, PrescribedController) and the tool's own controls_file, as
//     PrescribedControls
//   -> initial state: defaults, then states_file's closest earlier row to initial_time (no
//     interpolation; OpenSim 3 names r_elbow_flex, r_elbow_flex_u, BIClong.activation accepted
//     beside OpenSim 4's), then the muscles' equilibrium if the setup asks
//   -> rk45 (or another integrator) from initial_time to final_time with rtol = atol =
//     integrator_error_tolerance, maximum_integrator_step_size, maximum_number_of_integrator_steps
//   -> DIR/<name>_states.sto (time, /jointset/J/C/value, .../speed, every auxiliary state under
//     its OpenSim 4 name) and DIR/<name>_controls.sto (one column per actuator), written atomically;
//     with settings.view, DIR/<name>_view (`redmax view` of the model along those states).
#include <optional>
#include <string>
#include <vector>

#include "converter/build/muscle_mass.hpp"
#include "converter/controls.hpp"
#include "converter/forward_setup.hpp"
#include "converter/storage.hpp"
#include "core/integrators/integrator.hpp"
#include "validation/simulate/simulate.hpp"
#include "view/view.hpp"

namespace redmax::validation {

/// Controls from a file (ControlSet .xml or controls .sto) for every control of sys it names
/// (bare actuator name or <actuator>.excitation), as one PrescribedControls; names of the file
/// that match no actuator go to warnings. Throws osim::ConvertError for unreadable files.
void addControlsFile(System& sys, const std::string& file, std::vector<std::string>& warnings,
                     const std::vector<std::string>& actuator_list = {});

/// The setup's controllers (disabled ones skipped) added to sys. Throws osim::ConvertError naming
/// the setup file and the controller's line for a controller that cannot be built (no controls
/// file, a function that cannot be evaluated, more functions than actuators).
void addSetupControllers(System& sys, const osim::ForwardSetup& setup, std::vector<std::string>& warnings);

/// The muscles' force terms, actuators and passive forces of a loaded model, added to its
/// system: MuscleForceTerm over the muscles that have a muscle model, then the ForceSet's
/// CoordinateActuators, PointActuators, TorqueActuators (controls in that order), then its
/// CoordinateLimitForces, SpringGeneralizedForces, PointToPointSprings, BushingForces and contact
/// forces (converter/build/force_terms.hpp, docs/contact.md). model_forces false
/// (replace_force_set): only the forces that came from force_set_files. Muscles without a force
/// model, forces whose class is not modelled and contact geometry that nothing applied uses go to
/// not_applied (one line each; warnings when null). hard_contact: as addPassiveTerms.
void addActuatorTerms(SimulationModel& m, std::vector<std::string>& warnings, bool model_forces = true,
                      std::vector<std::string>* not_applied = nullptr, bool hard_contact = false);

/// Which of the ForceSet's passive forces an engine applies: all (the core), the contact forces
/// only (the Simbody engine: its own HuntCrossleyForce and SmoothSphereHalfSpaceForce), none.
enum class PassiveForces { All, ContactOnly, None };

/// Plain `simulate` (no controls): the ForceSet's passive forces and contacts (CoordinateLimitForce,
/// springs, bushings, HuntCrossleyForce, SmoothSphereHalfSpaceForce) added to m's system. What is
/// not applied goes to not_applied: the path forces and the actuators (one line each, every name
/// given), forces whose class is not modelled, contact geometry no applied force uses, and with
/// `which` other than All the forces the engine does not take (listed, with None every geometry).
/// hard_contact: HuntCrossleyForce and SmoothSphereHalfSpaceForce are left out (addHardConstraints
/// makes their geometry hard contacts) and their geometry is not listed here.
/// controls_hint completes "path forces exert no force without ..." (the command's way to drive
/// them); path forces named in `pulling` are left out of that line (the caller applies them).
void addPassiveTerms(SimulationModel& m, std::vector<std::string>& warnings, std::vector<std::string>& not_applied,
                     PassiveForces which = PassiveForces::All, bool hard_contact = false,
                     const std::string& controls_hint = "--controls", const std::vector<std::string>& pulling = {});

/// `simulate`'s hard modes (docs/contact.md §6).
struct HardConstraintOptions {
  std::string joint_limits;        ///< "": none; "hard": every coordinate's range; "clamped": the clamped ones
  double limit_restitution = 0.0;
  bool contact = false;            ///< ContactSphere / ContactHalfSpace pairs of the contact forces, hard
  double contact_restitution = 0.0;
  double contact_friction = -1.0;  ///< Coulomb mu for every pair; < 0: each force's dynamic_friction
};
/// What addHardConstraints made.
struct HardConstraintSummary {
  int limits = 0, pairs = 0;
};
/// Sets m.system's unilateral constraints (System::setUnilateral) from its description: joint
/// ranges as limits (not locked or prescribed coordinates), and for the contact forces'
/// geometry (HuntCrossleyForce: every sphere/half-space or sphere/sphere pair of its contact set
/// on different bodies, friction 2 u1 u2 / (u1 + u2) of the dynamic coefficients;
/// SmoothSphereHalfSpaceForce: its pair) hard contacts. Geometry it cannot use is named in
/// not_applied. Throws ModelError for a coordinate whose default lies outside its hard range.
HardConstraintSummary addHardConstraints(SimulationModel& m, const HardConstraintOptions& o,
                                         std::vector<std::string>& not_applied);

/// The message of a --strict refusal: the count, then every item not applied on its own line.
std::string strictRefusal(const std::vector<std::string>& not_applied);

/// A state of m's system from a states table: the closest row at or before `time` (the first row
/// when none is), every coordinate, speed and auxiliary state the table names (OpenSim 4 paths or
/// OpenSim 3 names); state.t = time. Throws osim::ConvertError naming `file`.
State forwardInitialState(const SimulationModel& m, const osim::Storage& table, const std::string& file, double time);

/// The auxiliary states of m's system that the table names at `row` (/forceset/M/S or OpenSim 3's
/// M.S) into s.z (sized and defaulted first when it does not fit). Throws osim::ConvertError
/// naming `file` for a non-finite value.
void readAuxiliaryStates(const System& sys, const osim::Storage& table, int row, const std::string& file, State& s);

/// A feedback law for a scene (OpenSim has no such controller class, so it is not read from XML):
/// the actuator's control gets bias + kp (target - q) + kd (0 - qdot) of the named coordinate,
/// clamped to [min, max], on top of the setup's controllers (core's ProportionalController).
struct FeedbackRule {
  std::string actuator, coordinate;
  double target = 0.0, kp = 0.0, kd = 0.0, bias = 0.0;
  double min = 0.0, max = 1.0;
};

struct ForwardToolSettings {
  std::string setup_file;
  std::optional<std::string> out_dir;  ///< replaces the setup's results_directory
  std::string muscle_class;            ///< "" keeps each muscle's class (OpenSim's renameType)
  osim::MuscleMassOptions muscle_mass;
  std::string integrator = "rk45";
  /// s between output rows (the last row is final_time); ignored when output_times is given
  double report_interval = 0.01;
  std::vector<double> output_times;    ///< exact output times in [initial, final] (e.g. a standard's)
  std::optional<double> tolerance;     ///< replaces integrator_error_tolerance (rtol = atol)
  /// refuse (std::invalid_argument naming each) when a force or contact geometry is not applied
  bool strict = false;
  /// the page files of `redmax view` (view/view.hpp); given (index_html not empty), write() also
  /// writes the run's view (the model along the states written, with the run's muscle mass) into
  /// DIR/<name>_view
  view::ViewAssets view;
  /// feedback controllers added after the setup's (std::invalid_argument for an unknown name)
  std::vector<FeedbackRule> feedback;
};

struct ForwardResult {
  osim::Storage states, controls;
  IntegratorStats stats;
  double wall_s = 0.0;
  bool failed = false;
  std::string failure;  ///< what diverged, with the time
};

class ForwardTool {
 public:
  /// Read everything and build the system and initial state. Throws osim::ConvertError
  /// ("FILE:LINE: what"), ModelError or std::invalid_argument (bad settings) on bad input.
  explicit ForwardTool(ForwardToolSettings settings);
  const osim::ForwardSetup& setup() const { return setup_; }
  const SimulationModel& model() const { return model_; }
  const System& system() const { return *model_.system; }
  const State& initialState() const { return initial_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// forces and contact geometry the run does not apply (addActuatorTerms)
  const std::vector<std::string>& notApplied() const { return not_applied_; }
  /// the results folder and the two output files
  std::string resultsDirectory() const;
  std::string statesPath() const;
  std::string controlsPath() const;
  /// DIR/<name>_view: the folder of the run's view (written when settings.view is given)
  std::string viewPath() const;

  ForwardResult run() const;
  /// the states and controls tables, atomically (the folder is created), then the view when
  /// settings.view is given (view::writeView's errors pass through; the tables are kept). Returns
  /// the view's summary (frames 0: none written).
  view::ViewSummary write(const ForwardResult& r) const;

 private:
  ForwardToolSettings settings_;
  osim::ForwardSetup setup_;
  SimulationModel model_;
  State initial_;
  std::vector<std::string> warnings_;
  std::vector<std::string> not_applied_;
};

/// Integrate sys from `initial` to t1, recording states (q, qdot expanded to the skeleton, z) and
/// controls at `times` (ascending, within [initial.t, t1]); shared by the ForwardTool and
/// `simulate --controls`.
ForwardResult runForward(const SimulationModel& m, const State& initial, const std::vector<double>& times,
                         const std::string& integrator, const IntegratorOptions& options, long max_total_steps);

}  // namespace redmax::validation
