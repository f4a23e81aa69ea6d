#pragma once
// OpenSim's PointActuator and TorqueActuator as ForceTerms with one control each (docs/forward.md
// §3). The actuation is u * optimal_force (OpenSim's computeActuation; no clamp of u):
//   PointActuator   world force F = a d_w at the body station p (d the unit direction, in the
//                   body frame or ground with force_is_global; p in the body frame, or with
//                   point_is_global the body station that is at the ground point now, as
//                   findStationLocationInAnotherFrame gives it) -> f += J_p^T F
//   TorqueActuator  world torque T = a n_w on bodyA and -T on bodyB (n the unit axis, in bodyA's
//                   frame or ground with torque_is_global); ground takes nothing
// Both are explicit (no stiffness), and addActuation gives one actuator's generalized force for
// any actuation: static optimization's column of A is addActuation at optimal_force.
#include <string>
#include <vector>

#include "core/dynamics/force_term.hpp"

namespace redmax {

class PointActuatorTerm final : public ForceTerm {
 public:
  struct Actuator {
    std::string name;
    int body = -1;                     ///< core body (>= 0; an actuator on ground does nothing)
    Vec3 point = Vec3::Zero();         ///< body frame, or ground with point_is_global
    bool point_is_global = false;
    Vec3 direction = Vec3::UnitX();    ///< non-zero; made unit (SimTK::UnitVec3)
    bool force_is_global = false;
    double optimal_force = 1.0;
  };
  /// throws ModelError for a body outside the model, a zero or non-finite direction or point
  PointActuatorTerm(const Model& model, std::vector<Actuator> actuators);
  std::string name() const override { return "point_actuators"; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  int numControls() const override { return static_cast<int>(actuators_.size()); }
  std::vector<std::string> controlNames() const override;
  const std::vector<Actuator>& actuators() const { return actuators_; }
  /// add actuator k's generalized force at actuation `force` (N) to f; needs Stage::Position
  void addActuation(const Model& model, const SkeletonWorkspace& sk, int k, double force, VecX& f) const;
  /// actuator k's application point (body frame) and unit force direction (world) at sk
  void calcPointAndDirection(const SkeletonWorkspace& sk, int k, Vec3& point_i, Vec3& direction_w) const;

 private:
  std::vector<Actuator> actuators_;
};

class TorqueActuatorTerm final : public ForceTerm {
 public:
  struct Actuator {
    std::string name;
    int body_a = -1, body_b = -1;      ///< core bodies; -1: ground
    Vec3 axis = Vec3::UnitZ();         ///< non-zero; made unit
    bool torque_is_global = true;
    double optimal_force = 1.0;
  };
  /// throws ModelError for a body outside the model, a zero or non-finite axis
  TorqueActuatorTerm(const Model& model, std::vector<Actuator> actuators);
  std::string name() const override { return "torque_actuators"; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  int numControls() const override { return static_cast<int>(actuators_.size()); }
  std::vector<std::string> controlNames() const override;
  const std::vector<Actuator>& actuators() const { return actuators_; }
  /// add actuator k's generalized force at actuation `torque` (N m) to f; needs Stage::Position
  void addActuation(const Model& model, const SkeletonWorkspace& sk, int k, double torque, VecX& f) const;
  /// actuator k's unit axis in the world at sk
  Vec3 axisInWorld(const SkeletonWorkspace& sk, int k) const;

 private:
  std::vector<Actuator> actuators_;
};

}  // namespace redmax
