#pragma once
// OpenSim ForwardTool setup files (docs/forward.md §2), with paths resolved relative to the setup
// file's folder as OpenSim does. Files are not opened here.
#include <string>
#include <vector>

#include "converter/controls.hpp"
#include "converter/error.hpp"
#include "converter/model_description.hpp"

namespace redmax::osim {

struct ForwardSetup {
  std::string name;                 ///< the tool's name: DIR/<name>_states.sto
  std::string source_file;
  std::string directory;            ///< the setup file's folder
  std::string model_file;           ///< resolved ("" when absent)
  bool replace_force_set = false;
  std::vector<std::string> force_set_files;  ///< resolved
  std::string results_directory;    ///< resolved; the setup's folder when absent
  int output_precision = 8;
  double initial_time = 0.0, final_time = 1.0;
  bool solve_for_equilibrium = false;
  int maximum_number_of_integrator_steps = 20000;
  double maximum_integrator_step_size = 1.0;
  double minimum_integrator_step_size = 1e-8;
  double integrator_error_tolerance = 1e-5;
  std::vector<ControllerSetupDesc> controllers;
  std::string controls_file;        ///< the tool's own (3.x) controls_file, resolved
  std::string external_loads_file;  ///< resolved
  std::string states_file;          ///< resolved
  bool use_specified_dt = false;
  std::vector<std::string> warnings;  ///< what is read but not modelled
};

/// Read a ForwardTool setup (root ForwardTool or OpenSimDocument/ForwardTool). Throws
/// ConvertError ("FILE:LINE: what") on malformed input: bad numbers, final_time before
/// initial_time, non-positive tolerances or step sizes, unknown controller classes.
ForwardSetup readForwardSetup(const std::string& path);

}  // namespace redmax::osim
