#pragma once
// Simulation state: time and reduced coordinates, nothing derived (docs/design.md).
#include "core/spatial/types.hpp"

namespace redmax {

struct State {
  double t = 0.0;
  VecX q;      // reduced coordinates (nr, or the system's ndof when extra coordinates are added)
  VecX qdot;   // their time derivatives
};

}  // namespace redmax
