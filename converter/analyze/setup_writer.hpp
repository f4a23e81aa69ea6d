#pragma once
// Write an AnalyzeTool setup for static optimization of an inverse-dynamics trial, with a force set
// of generated reserves, in OpenSim's format: what `redmax gait-study` runs and what the OpenSim
// side-by-side benchmark hands to both AnalyzeTools. OpenSim's StaticOptimization defaults
// (activation exponent 2, muscle physiology on, criterion 1e-4, 100 iterations).
#include <string>
#include <vector>

#include "converter/id/inverse_dynamics_tool.hpp"

namespace redmax::osim {

struct StaticOptimizationSetupOptions {
  double reserve_optimal_force = 1.0;   ///< N m or N per unit control, every non-root coordinate
  double residual_optimal_force = 1.0;  ///< the root joint's coordinates
  int step_interval = 1;                ///< StaticOptimization's step_interval
};

struct StaticOptimizationSetupFiles {
  std::string setup_file, reserves_file;
  std::vector<std::string> reserves;  ///< the generated CoordinateActuators' names
};

/// Write DIR/<model name>_reserves.xml (one CoordinateActuator per coordinate that is neither
/// locked nor prescribed: `<coord>_residual` on the root joint, `<coord>_reserve` elsewhere,
/// controls unbounded) and DIR/<model name>_Setup_Analyze.xml (the trial's files by absolute path,
/// results_directory "."), each atomically. Throws what readOsimModel throws.
StaticOptimizationSetupFiles writeStaticOptimizationSetup(const IdToolConfig& trial,
                                                          const StaticOptimizationSetupOptions& options,
                                                          const std::string& dir);

}  // namespace redmax::osim
