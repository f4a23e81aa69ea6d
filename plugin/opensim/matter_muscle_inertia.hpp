#pragma once
// The OpenSim plugin's mass points on OpenSim's own Simbody system: plugin/simbody's
// MatterMuscleInertia (one implementation, compiled into libredmax_opensim against OpenSim's
// Simbody by plugin/opensim/CMakeLists.txt), under the names this plugin has always used.
#include "plugin/simbody/matter_muscle_inertia.hpp"

namespace redmax::opensim {

using simbody::MatterMap;
using simbody::MatterMuscleInertia;

}  // namespace redmax::opensim
