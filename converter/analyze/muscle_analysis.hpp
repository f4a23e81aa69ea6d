#pragma once
// OpenSim 4's MuscleAnalysis and Actuation analyses of the AnalyzeTool (docs/analyze.md, "MuscleAnalysis", "Actuation").
//
// Per recorded frame (AnalyzeTool::run): the skeleton's q and u from the coordinates or states
// file; each muscle's states from the states file where it has them, otherwise the model's
// defaults (default_activation, default_fiber_length); with
// solve_for_equilibrium_for_auxiliary_states, OpenSim's equilibrateMuscles at that state (the
// model's equilibrate(): the fibre length that balances fibre and tendon at the state's
// activation); then the muscle's outputs (MuscleAnalysis::record) at that state:
//   Length, TendonLength, FiberLength, NormalizedFiberLength, PennationAngle, FiberVelocity,
//   NormFiberVelocity, PennationAngularVelocity (-v_f tan(phi) / l_f, fixed-width pennation),
//   TendonForce, FiberForce, ActiveFiberForce, PassiveFiberForce, ...AlongTendon (times cos phi),
//   TendonPower (-F_T v_T, v_T = ldot - v_f cos phi + l_f sin phi phidot), MuscleActuatorPower
//   (-F_T ldot);
//   MomentArm_<coord> = -dl/dq_coord (the generalized force of a unit tension as the forward
//   simulation applies it, MuscleForceTerm::calcPath) and Moment_<coord> = MomentArm * TendonForce.
// Actuation: every actuator of the force set that applies force, in file order: its force
// (a muscle's tendon force; another actuator's control times optimal force, the controls from the
// setup's controllers and 0 without one, as in OpenSim's AnalyzeTool), speed (the path's
// lengthening speed; the coordinate's speed) and power (-F ldot for a path actuator; F qdot).
#include <string>
#include <vector>

#include "converter/storage.hpp"
#include "core/dynamics/constraint.hpp"
#include "core/model/musculoskeletal_model.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "core/skeleton/workspace.hpp"
#include "core/spatial/types.hpp"

namespace redmax::osim {

struct MuscleAnalysisSettings {
  bool present = false;  ///< the AnalysisSet has a MuscleAnalysis that is on
  std::string name = "MuscleAnalysis";
  int step_interval = 1;
  std::vector<std::string> muscle_list = {"all"};
  std::vector<std::string> coordinate_list = {"all"};  ///< moment_arm_coordinate_list
  bool compute_moments = true;
  int line = 0;
};

struct ActuationSettings {
  bool present = false;  ///< the AnalysisSet has an Actuation that is on
  std::string name = "Actuation";
  int step_interval = 1;
  int line = 0;
};

/// What one frame gives the muscles: the skeleton's state and the muscle states the states file
/// holds (z_given[m][j]: muscle m's j-th state, nan where the file has no column; empty: none).
struct MuscleFrameInput {
  double time = 0.0;
  VecX q, u;
  std::vector<std::vector<double>> z_given;
  /// per muscle: its excitation from the setup's controllers (empty: no controller; a muscle with
  /// an activation state then sees that activation, one without sees 0)
  VecX excitation;
  VecX controls;  ///< the controls of every actuator (the tool's list), copied to the frame
};

/// Every muscle of a model at one frame, after OpenSim's equilibrateMuscles.
struct MuscleFrame {
  double time = 0.0;
  VecX q, u;                              ///< (nr)
  VecX length, speed;                     ///< path length and lengthening speed  (nm)
  MatX dl_dq;                             ///< d length / dq = -moment arm        (nm x nr)
  std::vector<hill::MuscleOutput> out;    ///< per muscle; nan where it has no force model
  std::vector<std::vector<double>> z;     ///< the states the outputs were computed at
  VecX controls;                          ///< MuscleFrameInput::controls
  VecX actuator_speed;                    ///< per Actuation column: actuatorSpeeds (empty: none)
  /// nr x nr: column k is OpenSim's coupling vector of coordinate k (constraintCoupling); the
  /// moment arm about k is -dl/dq . column k. Empty: the identity (no constraints)
  MatX coupling;
  std::vector<std::string> failures;      ///< "muscle: why" for muscles that did not equilibrate
};

/// Evaluates MuscleFrames of a model (its paths and force models). Immutable after construction.
class MuscleFrameEvaluator {
 public:
  /// skeleton: the model the q belong to (the geometry's skeleton or the same coordinates)
  MuscleFrameEvaluator(const Model& skeleton, const MusculoskeletalModel& geometry);
  ~MuscleFrameEvaluator();
  MuscleFrameEvaluator(const MuscleFrameEvaluator&) = delete;
  MuscleFrameEvaluator& operator=(const MuscleFrameEvaluator&) = delete;

  /// equilibrate: OpenSim's solve_for_equilibrium_for_auxiliary_states. A muscle that cannot be
  /// equilibrated keeps its given/default states and is named in failures (OpenSim warns and
  /// records the unequilibrated state).
  MuscleFrame evaluate(const MuscleFrameInput& in, bool equilibrate) const;

 private:
  struct Impl;
  const Model& skeleton_;
  const MusculoskeletalModel& geometry_;
  Impl* impl_;
};

/// OpenSim's MomentArmSolver::computeCouplingVector for each coordinate k of `coordinates`: the
/// speeds u = e_k projected onto the constraints' velocity null space {u : G(q) u = 0} (least
/// squares with unit weights, as Simbody's projectU with equal speed weights), divided by u_k.
/// The moment arm about k is then the generalized force of a unit tension along that motion,
/// -dl/dq . c_k: for a coupler q_d = f(q_i) the total derivative -(dl/dq_i + dl/dq_d f'(q_i)).
/// Other columns are e_k. Returns nr x nr.
MatX constraintCoupling(const Model& skeleton, const std::vector<std::shared_ptr<const Constraint>>& constraints,
                        const VecX& q, const std::vector<int>& coordinates);

/// The pennation angular velocity and tendon velocity of the fixed-width pennation model
/// (MuscleFixedWidthPennationModel: phidot = -v_f tan(phi) / l_f when pennated, else 0;
/// v_T = ldot - v_f cos(phi) + l_f sin(phi) phidot).
double pennationAngularVelocity(const hill::MuscleOutput& o);
double tendonVelocity(const hill::MuscleOutput& o, double path_speed);

/// OpenSim's MuscleDynamicsInfo fibre powers (W, MuscleAnalysis's FiberActivePower and
/// FiberPassivePower): active -(F_active + F_damping) v_f, the damping lumped into the active power
/// as Millard2012EquilibriumMuscle and DeGrooteFregly2016Muscle do; passive -F_elastic v_f. nan
/// where the class does not split its passive force (passive_fiber_elastic_force nan).
double fiberActivePower(const hill::MuscleOutput& o);
double fiberPassivePower(const hill::MuscleOutput& o);

/// One column set of the analyses: which muscles (geometry indices) and coordinates (core
/// indices) a MuscleAnalysis reports, by OpenSim's rules ("all": every Muscle of the force set /
/// every coordinate of the CoordinateSet; named ones that are absent are dropped with a warning).
struct MuscleAnalysisColumns {
  std::vector<std::string> muscles;
  std::vector<int> muscle_index;
  std::vector<std::string> classes;  ///< per muscle: its OpenSim class ("" without a force model)
  std::vector<std::string> coordinates;
  std::vector<int> coordinate_index;
};

/// The MuscleAnalysis files' tables, in OpenSim's print order (MomentArm_<q>..., Moment_<q>...,
/// PennationAngle, Length, FiberLength, NormalizedFiberLength, TendonLength, FiberVelocity,
/// NormFiberVelocity, PennationAngularVelocity, TendonForce, FiberForce, ActiveFiberForce,
/// PassiveFiberForce, ActiveFiberForceAlongTendon, PassiveFiberForceAlongTendon, FiberActivePower,
/// FiberPassivePower, TendonPower, MuscleActuatorPower); each Storage's name is the quantity.
/// Where OpenSim's Muscle getters read a cache entry the class never sets, the value is nan as
/// OpenSim prints it: for the *_Deprecated classes FiberForce, PennationAngularVelocity, the
/// powers and MuscleActuatorPower; for RigidTendonMuscle PennationAngularVelocity (and its
/// TendonPower is 0, as its calcMuscleDynamicsInfo sets it).
std::vector<Storage> muscleAnalysisTables(const MuscleAnalysisSettings& settings, const MuscleAnalysisColumns& columns,
                                          const std::vector<const MuscleFrame*>& frames);

/// One actuator of the Actuation analysis.
struct ActuationColumn {
  std::string name;
  int path = -1;        ///< geometry path (muscle or PathActuator): its speed is the lengthening speed
  bool muscle = false;  ///< its force is the muscle's tendon force (else control 0: force 0)
  int coordinate = -1;  ///< core coordinate of a CoordinateActuator: its speed is the coordinate's
  int control = -1;     ///< its entry of MuscleFrame::controls (-1: none, control 0)
  double optimal_force = 1.0;  ///< a non-muscle actuator's force is control * optimal_force
  /// PointActuator: its core body (-1: ground) and `point` as written; TorqueActuator: bodies A
  /// and B (-1: ground) and the unit axis as written. Their speeds: actuatorSpeeds.
  enum class Rigid { None, Point, Torque } rigid = Rigid::None;
  int body_a = -1, body_b = -1;
  Vec3 vector = Vec3::Zero();
};

/// The speeds OpenSim's PointActuator::calcSpeed and TorqueActuator::calcSpeed give at the
/// skeleton state of `sk` (Stage::Velocity), per column (nan for other columns):
///   PointActuator   |v| of the station `point` of its body in ground: OpenSim takes the property
///                   as a body-frame station even with point_is_global, and the speed is a norm
///                   (never negative), so its power F |v| is not the force's power F d.v
///   TorqueActuator  (omega_A - omega_B) . axis with both angular velocities in ground and the
///                   axis as written (OpenSim does not rotate it into ground when torque_is_global
///                   is false)
VecX actuatorSpeeds(const std::vector<ActuationColumn>& columns, const SkeletonWorkspace& sk);

/// ActuatorForces, ActuatorSpeeds, ActuatorPowers (Actuation::record) over the frames.
std::vector<Storage> actuationTables(const std::vector<ActuationColumn>& columns,
                                     const std::vector<const MuscleFrame*>& frames);

/// OpenSim's description lines of the two analyses' files
std::string muscleAnalysisDescription();
std::string actuationDescription();

}  // namespace redmax::osim
