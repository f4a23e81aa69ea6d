#pragma once
// Reference scenes built in code: the double pendulum of the demo, serial chains and random
// trees for tests and benchmarks. (Scenes authored as OpenSim files live in osim_models/.)
#include <cstdint>
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
/// tensors. SimbodyComparable uses joints with an exact Simbody mobilizer counterpart.
Model randomTree(int n, std::uint32_t seed, TreeJoints kinds = TreeJoints::All);

}  // namespace redmax::scenes
