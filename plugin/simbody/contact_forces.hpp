#pragma once
// OpenSim's compliant contact forces as Simbody's own force elements, for side-by-side runs with
// the core's ContactForceTerms (core/dynamics/contact_force_terms.hpp, docs/contact.md §5): each
// HuntCrossleyForce becomes one contact set of a SimTK::GeneralContactSubsystem (spheres and
// half-spaces on their mobilized bodies) with a SimTK::HuntCrossleyForce holding each surface's
// material; each SmoothSphereHalfSpaceForce a SimTK::SmoothSphereHalfSpaceForce. Simbody's code, not
// the core's equations: agreement between the two is what the comparison checks.
#include <memory>
#include <vector>

#include "core/dynamics/contact_force_terms.hpp"
#include "plugin/simbody/model_to_simbody.hpp"

namespace redmax::simbody {

/// The contact forces of a core system, as data (copied from its contact terms).
struct ContactForces {
  std::vector<HuntCrossleyForceTerm::Force> hunt_crossley;
  std::vector<SmoothSphereHalfSpaceForceTerm::Contact> smooth;
  bool empty() const { return hunt_crossley.empty() && smooth.empty(); }
};

/// The contact subsystem the forces use (Simbody's force elements keep a reference to it: it must
/// live as long as the system).
struct SimbodyContacts {
  std::unique_ptr<SimTK::GeneralContactSubsystem> subsystem;
};

/// Add `forces` to sm's system (bodies by core index, -1 ground) and realize its topology again
/// (sm.default_state is rebuilt, Euler angles on). Throws SimbodyBuildError for a body index outside
/// the model or a surface Simbody cannot take.
SimbodyContacts addSimbodyContacts(SimbodyModel& sm, const Model& model, const ContactForces& forces);

}  // namespace redmax::simbody
