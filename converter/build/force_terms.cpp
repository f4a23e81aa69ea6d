#include "converter/build/force_terms.hpp"

#include <cmath>

namespace redmax::osim {

std::vector<std::shared_ptr<const ForceTerm>> ForceTermSet::actuatorTerms() const {
  std::vector<std::shared_ptr<const ForceTerm>> out;
  if (coordinate_actuators) out.push_back(coordinate_actuators);
  if (point_actuators) out.push_back(point_actuators);
  if (torque_actuators) out.push_back(torque_actuators);
  return out;
}

std::vector<std::shared_ptr<const ForceTerm>> ForceTermSet::passiveTerms() const {
  std::vector<std::shared_ptr<const ForceTerm>> out;
  if (limit_forces) out.push_back(limit_forces);
  if (generalized_springs) out.push_back(generalized_springs);
  if (point_springs) out.push_back(point_springs);
  if (bushings) out.push_back(bushings);
  if (hunt_crossley) out.push_back(hunt_crossley);
  if (smooth_contacts) out.push_back(smooth_contacts);
  return out;
}

CoordinateLimitForceTerm::Limit coordinateLimitInSI(const ForceDesc& f, MotionType motion, int core_coordinate) {
  const double w = motion == MotionType::Rotational ? M_PI / 180.0 : 1.0;
  CoordinateLimitForceTerm::Limit l;
  l.name = f.name;
  l.coordinate = core_coordinate;
  l.upper_limit = w * f.upper_limit;
  l.lower_limit = w * f.lower_limit;
  l.upper_stiffness = f.upper_stiffness / w;
  l.lower_stiffness = f.lower_stiffness / w;
  l.damping = f.damping / w;
  l.transition = w * f.transition;
  return l;
}

ForceTermSet buildForceTerms(const ModelDescription& d, const BuildResult& b, std::vector<std::string>& warnings,
                             const std::function<bool(const ForceDesc&)>& include) {
  const Model& skel = b.model.skeleton();
  const std::string model_file = d.source_file;
  auto where = [&](const ForceDesc& f) {
    return (f.source_file.empty() ? model_file : f.source_file) + ":" + std::to_string(f.line) + ": " +
           f.class_name + " '" + f.name + "'";
  };
  // core coordinate / body, or -2 (with a warning) when the core model lacks it
  auto coordinate = [&](const ForceDesc& f) {
    const int ci = d.findCoordinate(f.coordinate);
    const int k = ci >= 0 && ci < static_cast<int>(b.coordinate_index.size()) ? b.coordinate_index[ci] : -1;
    if (k < 0) warnings.push_back(where(f) + ": coordinate '" + f.coordinate + "' is not in the built model; ignored");
    return k < 0 ? -2 : k;
  };
  auto body = [&](const ForceDesc& f, const std::string& name) {
    if (name == d.ground_name) return -1;
    const int bi = d.findBody(name);
    const int k = bi >= 0 && bi < static_cast<int>(b.body_index.size()) ? b.body_index[bi] : -1;
    if (k < 0) warnings.push_back(where(f) + ": body '" + name + "' is not in the built model; ignored");
    return k < 0 ? -2 : k;
  };
  ForceTermSet set;
  std::vector<CoordinateActuatorTerm::Actuator> ca;
  std::vector<PointActuatorTerm::Actuator> pa;
  std::vector<TorqueActuatorTerm::Actuator> ta;
  std::vector<CoordinateLimitForceTerm::Limit> cl;
  std::vector<SpringGeneralizedForceTerm::Spring> gs;
  std::vector<PointToPointSpringTerm::Spring> ps;
  std::vector<BushingForceTerm::Bushing> bu;
  std::vector<HuntCrossleyForceTerm::Force> hc;
  std::vector<SmoothSphereHalfSpaceForceTerm::Contact> sc;
  // a ContactGeometrySet member as a core surface; false (with a warning) when it cannot be one
  auto surface = [&](const ForceDesc& f, const std::string& name, ContactSurface& out) {
    const int gi = d.findContactGeometry(name);
    if (gi < 0) return false;  // the reader refused unknown names
    const ContactGeometryDesc& g = d.contact_geometry[static_cast<size_t>(gi)];
    if (!g.modelled) {
      warnings.push_back(where(f) + ": contact geometry '" + name + "' (" + g.class_name +
                         ") is not modelled; its contacts are ignored");
      return false;
    }
    const int bb = body(f, g.body);
    if (bb < -1) return false;
    out.name = g.name;
    out.shape = g.class_name == "ContactSphere" ? ContactShape::Sphere : ContactShape::HalfSpace;
    out.body = bb;
    out.X_body = g.X_body;
    out.radius = g.radius;
    return true;
  };
  for (size_t i = 0; i < d.forces.size(); ++i) {
    const ForceDesc& f = d.forces[i];
    if (!f.modelled || !(include ? include(f) : f.applies_force)) continue;
    const std::string& cls = f.class_name;
    const int fi = static_cast<int>(i);
    if (cls == "CoordinateActuator") {
      const int c = coordinate(f);
      if (c < 0) continue;
      ca.push_back({f.name, c, f.optimal_force});
      set.coordinate_actuator_source.push_back(fi);
    } else if (cls == "PointActuator") {
      const int bb = body(f, f.body1);
      if (bb < 0) continue;  // never ground (the reader refuses it)
      pa.push_back({f.name, bb, f.point1, f.point_is_global, f.direction, f.force_is_global, f.optimal_force});
      set.point_actuator_source.push_back(fi);
    } else if (cls == "TorqueActuator") {
      const int ba = body(f, f.body1), bb = body(f, f.body2);
      if (ba < -1 || bb < -1) continue;
      ta.push_back({f.name, ba, bb, f.direction, f.force_is_global, f.optimal_force});
      set.torque_actuator_source.push_back(fi);
    } else if (cls == "CoordinateLimitForce") {
      const int c = coordinate(f);
      if (c < 0) continue;
      cl.push_back(coordinateLimitInSI(f, d.coordinates[d.findCoordinate(f.coordinate)].motion_type, c));
    } else if (cls == "SpringGeneralizedForce") {
      const int c = coordinate(f);
      if (c < 0) continue;
      gs.push_back({f.name, c, f.stiffness, f.rest_length, f.viscosity});
    } else if (cls == "PointToPointSpring") {
      const int b1 = body(f, f.body1), b2 = body(f, f.body2);
      if (b1 < -1 || b2 < -1) continue;
      ps.push_back({f.name, b1, b2, f.point1, f.point2, f.stiffness, f.rest_length});
    } else if (cls == "BushingForce") {
      const int b1 = body(f, f.body1), b2 = body(f, f.body2);
      if (b1 < -1 || b2 < -1) continue;
      bu.push_back({f.name, b1, b2, f.X_body1, f.X_body2, f.bushing_stiffness, f.bushing_damping});
    } else if (cls == "HuntCrossleyForce") {
      // every geometry of every ContactParameters joins one contact set with that material
      HuntCrossleyForceTerm::Force F;
      F.name = f.name;
      F.transition_velocity = f.transition_velocity;
      for (const ContactParametersDesc& cp : f.contact_parameters)
        for (const std::string& g : cp.geometry) {
          ContactSurface cs;
          if (!surface(f, g, cs)) continue;
          F.surfaces.push_back(cs);
          F.materials.push_back({cp.stiffness, cp.dissipation, cp.static_friction, cp.dynamic_friction,
                                 cp.viscous_friction});
        }
      hc.push_back(std::move(F));
    } else if (cls == "SmoothSphereHalfSpaceForce") {
      SmoothSphereHalfSpaceForceTerm::Contact c;
      if (f.contact_parameters.empty() || !surface(f, f.sphere, c.sphere) || !surface(f, f.half_space, c.half_space))
        continue;
      if (c.sphere.body == c.half_space.body) {
        warnings.push_back(where(f) + ": the sphere and the half-space are on one body; it applies no force");
        continue;
      }
      const ContactParametersDesc& cp = f.contact_parameters.front();
      c.name = f.name;
      c.stiffness = cp.stiffness;
      c.dissipation = cp.dissipation;
      c.static_friction = cp.static_friction;
      c.dynamic_friction = cp.dynamic_friction;
      c.viscous_friction = cp.viscous_friction;
      c.transition_velocity = f.transition_velocity;
      c.constant_contact_force = f.constant_contact_force;
      c.hertz_smoothing = f.hertz_smoothing;
      c.hunt_crossley_smoothing = f.hunt_crossley_smoothing;
      sc.push_back(std::move(c));
    }
  }
  if (!ca.empty()) set.coordinate_actuators = std::make_shared<CoordinateActuatorTerm>(skel, std::move(ca));
  if (!pa.empty()) set.point_actuators = std::make_shared<PointActuatorTerm>(skel, std::move(pa));
  if (!ta.empty()) set.torque_actuators = std::make_shared<TorqueActuatorTerm>(skel, std::move(ta));
  if (!cl.empty()) set.limit_forces = std::make_shared<CoordinateLimitForceTerm>(skel, std::move(cl));
  if (!gs.empty()) set.generalized_springs = std::make_shared<SpringGeneralizedForceTerm>(skel, std::move(gs));
  if (!ps.empty()) set.point_springs = std::make_shared<PointToPointSpringTerm>(skel, std::move(ps));
  if (!bu.empty()) set.bushings = std::make_shared<BushingForceTerm>(skel, std::move(bu));
  if (!hc.empty()) set.hunt_crossley = std::make_shared<HuntCrossleyForceTerm>(skel, std::move(hc));
  if (!sc.empty()) set.smooth_contacts = std::make_shared<SmoothSphereHalfSpaceForceTerm>(skel, std::move(sc));
  return set;
}

}  // namespace redmax::osim
