#include "plugin/simbody/muscle_inertia.hpp"

namespace redmax::simbody {

MatterMap makeMatterMap(const SimbodyModel& sm, const Model& model) {
  MatterMap map;
  for (int b = 0; b < model.nb(); ++b) map.mobod_of_body.push_back(sm.mobods[b].getMobilizedBodyIndex());
  // core coordinate -> Simbody q (Euler angles: the same numbers, possibly another order)
  map.q_of_coordinate.assign(model.nr(), -1);
  for (const MobilizerMap& mm : sm.map)
    for (int k = 0; k < mm.nq; ++k) map.q_of_coordinate[mm.q_index + k] = mm.simbody_q + k;
  return map;
}

MuscleInertia::MuscleInertia(const SimbodyModel& sm, const MusculoskeletalModel& model)
    : impl_(sm.matter, makeMatterMap(sm, model.skeleton()), model.skeleton(), model.muscles(),
            model.skeleton().gravity()) {}

VecX MuscleInertia::calcGeneralizedForces(const SimTK::State& state, const VecX& udot) {
  SimTK::Vector f_u;
  impl_.calcGeneralizedForces(state, toSimTK(udot), f_u);
  return fromSimTK(f_u);
}

}  // namespace redmax::simbody
