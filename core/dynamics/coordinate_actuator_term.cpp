#include "core/dynamics/coordinate_actuator_term.hpp"

namespace redmax {

CoordinateActuatorTerm::CoordinateActuatorTerm(const Model& model, std::vector<Actuator> actuators)
    : actuators_(std::move(actuators)) {
  for (const Actuator& a : actuators_)
    if (a.coordinate < 0 || a.coordinate >= model.nr())
      throw ModelError("CoordinateActuator '" + a.name + "': coordinate index " + std::to_string(a.coordinate) +
                       " outside the model's " + std::to_string(model.nr()));
}

void CoordinateActuatorTerm::addForce(const Model&, const State&, const TermContext& ctx, VecX& f) const {
  for (size_t k = 0; k < actuators_.size(); ++k)
    f[actuators_[k].coordinate] += actuators_[k].optimal_force * ctx.control(static_cast<int>(k));
}

std::vector<std::string> CoordinateActuatorTerm::controlNames() const {
  std::vector<std::string> names;
  for (const Actuator& a : actuators_) names.push_back(a.name);
  return names;
}

}  // namespace redmax
