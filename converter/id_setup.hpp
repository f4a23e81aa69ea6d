#pragma once
// OpenSim InverseDynamicsTool setup files, with paths resolved relative to the setup file's
// folder as OpenSim does (docs/opensim_compatibility.md §7).
#include <limits>
#include <string>
#include <vector>

#include "converter/error.hpp"

namespace redmax::osim {

struct InverseDynamicsSetup {
  std::string name;
  std::string source_file;
  std::string directory;  ///< the setup file's folder; relative paths are resolved from it
  // resolved paths ("" when the element is empty or absent)
  std::string model_file;
  std::string coordinates_file;
  std::string external_loads_file;
  std::string results_directory;      ///< defaults to the setup folder
  std::string output_gen_force_file;  ///< results_directory / name (default inverse_dynamics.sto)
  std::string output_body_forces_file;
  double lowpass_cutoff_frequency_for_coordinates = -1.0;  ///< < 0: no filtering
  double time_start = -std::numeric_limits<double>::infinity();
  double time_end = std::numeric_limits<double>::infinity();
  std::vector<std::string> forces_to_exclude;
  std::vector<std::string> joints_to_report_body_forces;
  std::vector<std::string> warnings;  ///< settings 4.x ignores (coordinates_in_degrees, ...)
};

/// Read an InverseDynamicsTool setup. Files are not opened here; their paths are resolved.
/// Throws ConvertError ("FILE:LINE: what") on malformed input.
InverseDynamicsSetup readInverseDynamicsSetup(const std::string& path);

/// path resolved against dir as OpenSim does for tool files: absolute paths are kept
std::string resolveRelativeTo(const std::string& dir, const std::string& path);

}  // namespace redmax::osim
