#pragma once
// The ForceSet's actuators and passive forces as core ForceTerms (docs/forward.md §3), for the
// forward tool, `simulate --controls` and static optimization:
//   CoordinateActuator    CoordinateActuatorTerm          PointActuator   PointActuatorTerm
//   TorqueActuator        TorqueActuatorTerm              CoordinateLimitForce  CoordinateLimitForceTerm
//   SpringGeneralizedForce  SpringGeneralizedForceTerm    PointToPointSpring    PointToPointSpringTerm
//   BushingForce          BushingForceTerm
//   HuntCrossleyForce     HuntCrossleyForceTerm           SmoothSphereHalfSpaceForce  SmoothSphereHalfSpaceForceTerm
//   (ContactSphere and ContactHalfSpace geometry; docs/contact.md)
// CoordinateLimitForce's properties are in degrees for a Rotational coordinate (OpenSim's
// extendConnectToModel): limits and transition times pi/180, stiffness and damping times 180/pi.
// The reader (converter/osim_forces.cpp) has already refused unknown bodies and coordinates,
// zero directions and negative stiffness at their lines; what is left here is a coordinate or
// body that the core model lacks (a joint redmax does not build), which is a warning.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/model_description.hpp"
#include "core/dynamics/actuator_terms.hpp"
#include "core/dynamics/contact_force_terms.hpp"
#include "core/dynamics/coordinate_actuator_term.hpp"
#include "core/dynamics/passive_force_terms.hpp"

namespace redmax::osim {

struct ForceTermSet {
  std::shared_ptr<const CoordinateActuatorTerm> coordinate_actuators;  ///< null when none
  std::shared_ptr<const PointActuatorTerm> point_actuators;
  std::shared_ptr<const TorqueActuatorTerm> torque_actuators;
  std::shared_ptr<const CoordinateLimitForceTerm> limit_forces;
  std::shared_ptr<const SpringGeneralizedForceTerm> generalized_springs;
  std::shared_ptr<const PointToPointSpringTerm> point_springs;
  std::shared_ptr<const BushingForceTerm> bushings;
  std::shared_ptr<const HuntCrossleyForceTerm> hunt_crossley;
  std::shared_ptr<const SmoothSphereHalfSpaceForceTerm> smooth_contacts;
  /// index into ModelDescription::forces of each actuator of the three actuator terms, in the
  /// terms' order
  std::vector<int> coordinate_actuator_source, point_actuator_source, torque_actuator_source;
  /// the actuator terms (controls), then the passive ones; nulls left out
  std::vector<std::shared_ptr<const ForceTerm>> actuatorTerms() const;
  std::vector<std::shared_ptr<const ForceTerm>> passiveTerms() const;
};

/// The forces of d for which include(force) holds (default: applies_force), built on b's core
/// model. Forces whose class is not modelled are skipped (the reader lists them as
/// unsupported); ones the core model cannot hold go to warnings.
ForceTermSet buildForceTerms(const ModelDescription& d, const BuildResult& b, std::vector<std::string>& warnings,
                             const std::function<bool(const ForceDesc&)>& include = {});

/// CoordinateLimitForce in SI units (radians for a Rotational coordinate)
CoordinateLimitForceTerm::Limit coordinateLimitInSI(const ForceDesc& f, MotionType motion, int core_coordinate);

}  // namespace redmax::osim
