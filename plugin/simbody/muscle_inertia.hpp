#pragma once
// Muscle inertia in a Simbody system built from a core model (model_to_simbody.hpp): the
// generalized forces of muscle mass points [D Eq. 5.4-5.7]. A thin wrapper: it builds the
// MatterMap of its SimbodyModel (core body -> mobilized body, core coordinate -> q slot) and
// delegates to MatterMuscleInertia (plugin/simbody/matter_muscle_inertia.hpp), which states the
// kinematics, the path maps and the forces in full and is the same code the OpenSim plugin runs on
// OpenSim's own system.
//
// Only TUs that need Simbody include this header (plugin/simbody/simbody_include.hpp).
#include <string>
#include <vector>

#include "core/model/musculoskeletal_model.hpp"
#include "plugin/simbody/matter_muscle_inertia.hpp"
#include "plugin/simbody/model_to_simbody.hpp"

namespace redmax::simbody {

/// The MatterMap of a SimbodyModel built from `model`: its own mobilized bodies and q slots.
MatterMap makeMatterMap(const SimbodyModel& sm, const Model& model);

/// Muscle mass points of a Simbody system built from `model`'s skeleton. Keeps references to `sm`
/// (it must outlive this object); copies the model's muscles. Muscles without mass points are
/// skipped.
class MuscleInertia {
 public:
  /// Validates the muscles against the skeleton (validateMuscle: throws ModelError); the
  /// skeleton's gravity acts on the mass points.
  MuscleInertia(const SimbodyModel& sm, const MusculoskeletalModel& model);

  /// f_u (nu, Simbody u order) of the mass points at `state` (realized to Stage::Velocity at
  /// least) for generalized accelerations udot (nu). Throws MuscleError for a degenerate path.
  void calcGeneralizedForces(const SimTK::State& state, const SimTK::Vector& udot, SimTK::Vector& f_u) {
    impl_.calcGeneralizedForces(state, udot, f_u);
  }
  VecX calcGeneralizedForces(const SimTK::State& state, const VecX& udot);

  /// kinetic energy 1/2 sum m_a |xdot_a|^2 (J) and gravitational potential -sum m_a g . x_a (J,
  /// world origin) of the mass points at `state` (Stage::Velocity)
  double kineticEnergy(const SimTK::State& state) { return impl_.kineticEnergy(state); }
  double potentialEnergy(const SimTK::State& state) { return impl_.potentialEnergy(state); }

  /// mass point positions (world) of the m-th muscle with mass points after the last evaluation
  const std::vector<Vec3>& massPointPositions(int m) const { return impl_.massPointPositions(m); }
  const std::vector<Muscle>& muscles() const { return impl_.muscles(); }
  /// sum of all mass-point masses (kg)
  double totalMass() const { return impl_.totalMass(); }

 private:
  MatterMuscleInertia impl_;
};

}  // namespace redmax::simbody
