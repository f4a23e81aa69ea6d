#pragma once
// Simulation state: time, reduced coordinates and the auxiliary first-order states of the force
// terms (muscle activations, fibre lengths), nothing derived (docs/design.md, docs/forward.md).
#include "core/spatial/types.hpp"

namespace redmax {

struct State {
  double t = 0.0;
  VecX q;      // reduced coordinates (nr, or the system's ndof when extra coordinates are added)
  VecX qdot;   // their time derivatives
  VecX z;      // auxiliary first-order states, in System::stateNames() order (nz; empty: none)
};

}  // namespace redmax
