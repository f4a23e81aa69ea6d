#pragma once
// Hill-type musculotendon force models (OpenSim's Muscle classes): the interface between a
// muscle's path (length and lengthening speed, core/muscles/path_kinematics.hpp), its control
// (excitation), its own first-order states (activation, fibre length, ...) and the tendon force it
// applies along the path. A MuscleModel is immutable model data shared by threads; everything it
// computes at a state goes to the caller's MuscleOutput and zdot.
//
// The states of one muscle are named as OpenSim 4 names them under the muscle
// (/forceset/<muscle>/<stateName>), in the order stateNames() gives; a System stores them in
// State::z (docs/muscle_dynamics.md).
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace redmax::hill {

/// A muscle model could not be evaluated or equilibrated (no fibre length balances the tendon,
/// a state out of its domain); the message names the muscle.
class MuscleModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What the path and the controller give a muscle at one instant.
struct MusculotendonInput {
  double length = 0.0;      ///< musculotendon (path) length l_MT, m
  double speed = 0.0;       ///< lengthening speed dl_MT/dt, m/s
  double excitation = 0.0;  ///< control u, as OpenSim passes it (OpenSim's muscles do not clamp
                            ///< it to [min_control, max_control]: controllers do)
};

/// OpenSim's Muscle outputs at one state; forces in N, lengths in m, velocities in m/s.
struct MuscleOutput {
  double tendon_force = 0.0;  ///< tension along the path (>= 0 pulls the path's ends together)
  double activation = 0.0;
  double fiber_length = 0.0;
  double fiber_velocity = 0.0;   ///< d(fiber_length)/dt
  double pennation_angle = 0.0;  ///< rad
  double tendon_length = 0.0;
  double active_fiber_force = 0.0;   ///< along the fibre
  double passive_fiber_force = 0.0;  ///< along the fibre (elastic + damping)
  /// the conservative (elastic) part of passive_fiber_force; the rest is damping, which OpenSim
  /// counts in the fibre's active power (MuscleDynamicsInfo::fiberActivePower). nan where the
  /// class leaves OpenSim's powers undefined (the *_Deprecated classes).
  double passive_fiber_elastic_force = std::numeric_limits<double>::quiet_NaN();
  double normalized_fiber_length = 0.0;
  double normalized_fiber_velocity = 0.0;  ///< fiber_velocity / (max_contraction_velocity * l_opt)
};

class MuscleModel {
 public:
  virtual ~MuscleModel() = default;
  /// the OpenSim class whose equations this model computes (e.g. "Thelen2003Muscle")
  virtual std::string className() const = 0;
  /// names of this muscle's states in OpenSim 4 order ("activation", "fiber_length"); may be empty
  virtual const std::vector<std::string>& stateNames() const = 0;
  int numStates() const { return static_cast<int>(stateNames().size()); }
  /// the model's default state (default_activation, default_fiber_length, ...)   (numStates)
  virtual void defaultState(double* z) const = 0;
  /// outputs and state derivatives zdot (numStates) at states z and input `in`
  virtual void calc(const double* z, const MusculotendonInput& in, MuscleOutput& out,
                    double* zdot) const = 0;
  /// OpenSim's computeInitialFiberEquilibrium: set the fibre-length state (if the model has one)
  /// so that fibre and tendon forces balance at `in`, keeping the other entries of z. Throws
  /// MuscleModelError when no fibre length does.
  virtual void equilibrate(const MusculotendonInput& in, double* z) const = 0;

  /// OpenSim's calcInextensibleTendonActiveFiberForce(s, activation), which static optimization
  /// uses with use_muscle_physiology: the active fibre force (N) at `activation` with a rigid
  /// tendon at its slack length, the fibre length from the path length through the class's
  /// pennation model and the fibre velocity from the path's lengthening speed; each class states
  /// OpenSim's rules (along the tendon or the fibre, zero at the minimum fibre length). The base
  /// throws MuscleModelError: a class without it cannot take part in static optimization with
  /// muscle physiology.
  virtual double inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const {
    (void)in;
    (void)activation;
    throw MuscleModelError(className() + ": calcInextensibleTendonActiveFiberForce is not modelled");
  }

  /// the muscle's control bounds (OpenSim's min_control, max_control, after the class defaults)
  virtual double minControl() const { return 0.0; }
  virtual double maxControl() const { return 1.0; }
  /// the parameters the model computes with (after OpenSim's defaults), in a fixed order, for
  /// reports (`redmax convert`)
  virtual std::vector<std::pair<std::string, double>> parameterList() const { return {}; }
};

}  // namespace redmax::hill
