#include "plugin/simbody/contact_forces.hpp"

#include <string>

#include "plugin/simbody/simbody_include.hpp"

namespace redmax::simbody {

namespace {

SimTK::MobilizedBody mobodOf(SimbodyModel& sm, const Model& model, int body, const std::string& what) {
  if (body < -1 || body >= model.nb())
    throw SimbodyBuildError(what + ": body index " + std::to_string(body) + " outside the model");
  return body < 0 ? sm.matter.Ground() : sm.mobods[static_cast<size_t>(body)];
}

}  // namespace

SimbodyContacts addSimbodyContacts(SimbodyModel& sm, const Model& model, const ContactForces& forces) {
  SimbodyContacts out;
  if (forces.empty()) return out;
  if (!forces.hunt_crossley.empty()) out.subsystem = std::make_unique<SimTK::GeneralContactSubsystem>(sm.system);
  for (const HuntCrossleyForceTerm::Force& f : forces.hunt_crossley) {
    const SimTK::ContactSetIndex set = out.subsystem->createContactSet();
    for (const ContactSurface& s : f.surfaces) {
      const SimTK::MobilizedBody mb = mobodOf(sm, model, s.body, "HuntCrossleyForce '" + f.name + "'");
      if (s.shape == ContactShape::Sphere)
        out.subsystem->addBody(set, mb, SimTK::ContactGeometry::Sphere(s.radius), toTransform(s.X_body));
      else
        out.subsystem->addBody(set, mb, SimTK::ContactGeometry::HalfSpace(), toTransform(s.X_body));
    }
    SimTK::HuntCrossleyForce hc(sm.forces, *out.subsystem, set);
    for (size_t k = 0; k < f.surfaces.size(); ++k) {
      const HuntCrossleyForceTerm::Material& m = f.materials[k];
      hc.setBodyParameters(SimTK::ContactSurfaceIndex(static_cast<int>(k)), m.stiffness, m.dissipation,
                           m.static_friction, m.dynamic_friction, m.viscous_friction);
    }
    hc.setTransitionVelocity(f.transition_velocity);
  }
  for (const SmoothSphereHalfSpaceForceTerm::Contact& c : forces.smooth) {
    SimTK::SmoothSphereHalfSpaceForce f(sm.forces);
    f.setContactSphereBody(mobodOf(sm, model, c.sphere.body, "SmoothSphereHalfSpaceForce '" + c.name + "'"));
    f.setContactSphereLocationInBody(toSimTKVec3(c.sphere.X_body.topRightCorner<3, 1>()));
    f.setContactSphereRadius(c.sphere.radius);
    f.setContactHalfSpaceBody(mobodOf(sm, model, c.half_space.body, "SmoothSphereHalfSpaceForce '" + c.name + "'"));
    f.setContactHalfSpaceFrame(toTransform(c.half_space.X_body));
    f.setParameters(c.stiffness, c.dissipation, c.static_friction, c.dynamic_friction, c.viscous_friction,
                    c.transition_velocity, c.constant_contact_force, c.hertz_smoothing, c.hunt_crossley_smoothing);
  }
  try {
    sm.default_state = sm.system.realizeTopology();
    sm.matter.setUseEulerAngles(sm.default_state, true);
    sm.system.realizeModel(sm.default_state);
  } catch (const std::exception& e) {
    throw SimbodyBuildError(std::string("Simbody could not realize the model with contact forces: ") + e.what());
  }
  return out;
}

}  // namespace redmax::simbody
