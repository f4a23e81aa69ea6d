#pragma once
// Scenes for the speed comparisons with Simbody (validation/bench/, `redmax bench`): a
// humanoid-sized tree and well-conditioned serial chains; every joint has an exact Simbody
// counterpart (plugin/simbody/model_to_simbody.hpp).
#include "core/skeleton/model.hpp"

namespace redmax::scenes {

/// Standing humanoid: 17 bodies, 37 coordinates, 77.3 kg; y up, x forward, z to the right;
/// gravity (0, -9.80665, 0).
/// Bodies and joints (coordinates):
///   pelvis   Free3D::opensim() on the world (6: rx ry rz tx ty tz, default ty = 0.94 m)
///   torso    lumbar SphericalEuler XYZ (3)          head   neck Universal (2)
///   upper_arm_{r,l} shoulder SphericalEuler XYZ (3) forearm_{r,l} elbow Revolute z (1)
///   hand_{r,l} wrist Universal (2)
///   thigh_{r,l} hip SphericalEuler XYZ (3)           shank_{r,l} knee Revolute z (1)
///   foot_{r,l} ankle Universal, flexion first (2)   toes_{r,l} mtp Revolute z (1)
/// Segment masses follow usual anthropometric fractions; inertias are those of solid cylinders
/// along each segment's long axis (about the COM, body axes). No joint springs or dampers.
Model humanoid();

/// Serial chain of n links (1 kg solid cylinders, 0.3 m long, radius 0.03 m, hanging along -y),
/// hinged about z and x alternately so that no link spins about its own long axis. Unlike
/// revoluteChain (whose thin rods also turn about their axis, a very stiff mode), explicit
/// integrators take ordinary steps on it, so integrator timings compare cost per step.
/// Gravity (0, -9.80665, 0); coordinates default to 0.
Model limbChain(int n);

}  // namespace redmax::scenes
