#pragma once
// A ForwardTool setup that holds every muscle of a model at one excitation from equilibrium: the
// speed and side-by-side runs (validation/bench/, tests/opensim/) on models without a setup of
// their own. The controls are a ControlSet file of two-node ControlLinears in a
// ControlSetController (OpenSim 4 ignores a tool-level controls_file in a version-40000 document).
#include <string>

namespace redmax::validation {

/// Write DIR/controls.xml and DIR/NAME_Setup_Forward.xml (results_directory ".", from t = 0 to t1,
/// equilibrium on, integrator_error_tolerance `tolerance`), each atomically; returns the setup's
/// path. Throws what readOsimModel throws.
std::string writeConstantExcitationSetup(const std::string& model, const std::string& dir, const std::string& name,
                                         double t1, double excitation, double tolerance);

}  // namespace redmax::validation
