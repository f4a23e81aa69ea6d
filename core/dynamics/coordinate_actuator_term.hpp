#pragma once
// OpenSim's CoordinateActuator as a ForceTerm with one control each (docs/forward.md):
//   f[coordinate] += optimal_force * u
// (a generalized force on the skeleton coordinate, N m or N; OpenSim applies no clamp of u).
#include <string>
#include <vector>

#include "core/dynamics/force_term.hpp"

namespace redmax {

class CoordinateActuatorTerm final : public ForceTerm {
 public:
  struct Actuator {
    std::string name;
    int coordinate = -1;  ///< skeleton coordinate index (q_r)
    double optimal_force = 1.0;
  };
  /// throws ModelError for a coordinate index outside the model
  CoordinateActuatorTerm(const Model& model, std::vector<Actuator> actuators);
  std::string name() const override { return "coordinate_actuators"; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  int numControls() const override { return static_cast<int>(actuators_.size()); }
  std::vector<std::string> controlNames() const override;
  const std::vector<Actuator>& actuators() const { return actuators_; }

 private:
  std::vector<Actuator> actuators_;
};

}  // namespace redmax
