#pragma once
// Reference scenes built in code: the double pendulum of the demo, serial chains and random
// trees for tests and benchmarks. (Scenes authored as OpenSim files live in osim_models/.)
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "core/skeleton/model.hpp"

namespace redmax::scenes {

/// Planar double pendulum: two 1 m rods (mass 1 kg, uniform, thin) hinged about z, hanging
/// along -y under gravity (0, -9.81, 0). Coordinates q1, q2.
Model doublePendulum(double length = 1.0, double mass = 1.0);

/// Serial chain of n identical links hinged about alternating axes (z, x, y, ...).
Model revoluteChain(int n);

/// Which joint types a random tree may use.
enum class TreeJoints { SimbodyComparable, All };

/// Random tree with n bodies and random parents, joint frames, masses, COMs and full inertia
/// tensors. All: every JointVariant alternative (random axes, Euler sequences, free-joint layouts,
/// spline control frames, CustomJoint functions; exact kinematics). SimbodyComparable: only
/// Revolute (random axis), Prismatic (random axis), Fixed, SphericalEuler XYZ (Simbody Gimbal,
/// and Ball with Euler angles), Universal, and Free3D::opensim() (q = (rx,ry,rz,tx,ty,tz),
/// X_FM = (R_XYZ, p in F)).
Model randomTree(int n, std::uint32_t seed, TreeJoints kinds = TreeJoints::All);

/// A random instance of JointVariant alternative `index` (std::variant index), with parameters
/// chosen so that S keeps full rank for coordinates in [-1, 1] (except at the gimbal lock of
/// proper Euler sequences, q2 = 0). Throws std::out_of_range for an index with no generator, so a
/// new alternative must be added here (and thereby to the random trees and joint tests).
Joint randomJoint(std::size_t index, std::mt19937& rng);

}  // namespace redmax::scenes
