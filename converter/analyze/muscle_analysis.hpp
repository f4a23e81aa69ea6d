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
// (a muscle's tendon force; a CoordinateActuator's control times optimal force, and controls are 0
// without a controller, as in OpenSim's AnalyzeTool without controls), speed (the path's
// lengthening speed; the coordinate's speed) and power (-F ldot for a path actuator; F qdot).
#include <string>
#include <vector>

#include "converter/storage.hpp"
#include "core/model/musculoskeletal_model.hpp"
#include "core/muscles/hill/muscle_model.hpp"
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
};

/// Every muscle of a model at one frame, after OpenSim's equilibrateMuscles.
struct MuscleFrame {
  double time = 0.0;
  VecX q, u;                              ///< (nr)
  VecX length, speed;                     ///< path length and lengthening speed  (nm)
  MatX dl_dq;                             ///< d length / dq = -moment arm        (nm x nr)
  std::vector<hill::MuscleOutput> out;    ///< per muscle; nan where it has no force model
  std::vector<std::vector<double>> z;     ///< the states the outputs were computed at
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

/// The pennation angular velocity and tendon velocity of the fixed-width pennation model
/// (MuscleFixedWidthPennationModel: phidot = -v_f tan(phi) / l_f when pennated, else 0;
/// v_T = ldot - v_f cos(phi) + l_f sin(phi) phidot).
double pennationAngularVelocity(const hill::MuscleOutput& o);
double tendonVelocity(const hill::MuscleOutput& o, double path_speed);

/// One column set of the analyses: which muscles (geometry indices) and coordinates (core
/// indices) a MuscleAnalysis reports, by OpenSim's rules ("all": every Muscle of the force set /
/// every coordinate of the CoordinateSet; named ones that are absent are dropped with a warning).
struct MuscleAnalysisColumns {
  std::vector<std::string> muscles;
  std::vector<int> muscle_index;
  std::vector<std::string> coordinates;
  std::vector<int> coordinate_index;
};

/// The MuscleAnalysis files' tables, in OpenSim's print order (MomentArm_<q>..., Moment_<q>...,
/// PennationAngle, Length, FiberLength, NormalizedFiberLength, TendonLength, FiberVelocity,
/// NormFiberVelocity, PennationAngularVelocity, TendonForce, FiberForce, ActiveFiberForce,
/// PassiveFiberForce, ActiveFiberForceAlongTendon, PassiveFiberForceAlongTendon, TendonPower,
/// MuscleActuatorPower); each Storage's name is the quantity.
std::vector<Storage> muscleAnalysisTables(const MuscleAnalysisSettings& settings, const MuscleAnalysisColumns& columns,
                                          const std::vector<const MuscleFrame*>& frames);

/// One actuator of the Actuation analysis.
struct ActuationColumn {
  std::string name;
  int path = -1;        ///< geometry path (muscle or PathActuator): its speed is the lengthening speed
  bool muscle = false;  ///< its force is the muscle's tendon force (else control 0: force 0)
  int coordinate = -1;  ///< core coordinate of a CoordinateActuator: its speed is the coordinate's
};

/// ActuatorForces, ActuatorSpeeds, ActuatorPowers (Actuation::record) over the frames.
std::vector<Storage> actuationTables(const std::vector<ActuationColumn>& columns,
                                     const std::vector<const MuscleFrame*>& frames);

/// OpenSim's description lines of the two analyses' files
std::string muscleAnalysisDescription();
std::string actuationDescription();

}  // namespace redmax::osim
