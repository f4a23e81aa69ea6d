#pragma once
// OpenSim controls (docs/forward.md §3): ControlSet XML files (ControlLinear, ControlConstant),
// controls .sto files, and their evaluation as OpenSim's ControlLinear::getControlValue does:
//   no nodes                          ControlConstant: its value; a ControlLinear without x_nodes
//                                     that drives an actuator is refused (OpenSim's value is NaN)
//   t before the first node           extrapolate (and not use_steps): the line through the first
//                                     two nodes (one node: its value); otherwise the first node's value
//   t at or after the last node       the same with the last two nodes / the last value
//   from node i to node i+1           use_steps: node i+1's value on (t_i, t_i+1], node i's at t_i
//                                     itself (a node holds the value of the interval that ends at
//                                     it); otherwise linear interpolation
// min/max (default_min/max, min_nodes/max_nodes) are read and evaluated alike; OpenSim's
// ControlSetController does not clamp with them (the muscle clamps its excitation), nor do we.
// Names: `<actuator>.excitation` and bare actuator names both name the actuator.
// A controls .sto (or .mot) gives one ControlLinear per column (linear, extrapolated), nodes at the
// rows, as OpenSim's ControlSet(Storage) builds them.
#include <string>
#include <vector>

#include "converter/error.hpp"
#include "converter/model_description.hpp"
#include "core/joints/functions.hpp"

namespace redmax::osim {

struct ControlNodeDesc {
  double t = 0.0;
  double value = 0.0;
};

struct ControlLinearDesc {
  std::string name;                ///< as written, e.g. "BIClong.excitation"
  std::string type = "ControlLinear";  ///< or "ControlConstant"
  int line = 0;
  bool is_model_control = true;
  bool extrapolate = true;
  bool use_steps = false;
  double default_min = 0.0, default_max = 1.0;
  double default_value = 0.0;      ///< ControlConstant's value; the value without nodes
  std::vector<ControlNodeDesc> x_nodes, min_nodes, max_nodes;  ///< ascending t

  /// the actuator this control drives: the name without a trailing ".excitation"
  std::string actuator() const;
  double value(double t) const;
  double minValue(double t) const;
  double maxValue(double t) const;
};

struct ControlSetDesc {
  std::string file;
  std::vector<ControlLinearDesc> controls;
  /// the model control for actuator `name` (exact name first, then name + ".excitation"), or null
  const ControlLinearDesc* findForActuator(const std::string& name) const;
};

/// Read a ControlSet: an .xml ControlSet (root ControlSet or OpenSimDocument/ControlSet), or a
/// .sto/.mot table. Throws ConvertError ("FILE:LINE: what") on unreadable or malformed files:
/// unknown control classes, non-numeric or non-finite values, nodes out of time order, duplicate
/// names.
ControlSetDesc readControlSet(const std::string& path);

/// the control as a core function of time (one argument)
AxisFunctionPtr makeControlFunction(const ControlLinearDesc& c);

/// One controller of a tool setup's ControllerSet (ForwardTool, AnalyzeTool).
struct ControllerSetupDesc {
  std::string type;                 ///< ControlSetController, PrescribedController or CorrectionController
  std::string name;
  int line = 0;
  std::vector<std::string> actuator_list;  ///< empty or ALL: every actuator with a control
  bool disabled = false;            ///< isDisabled / enabled = false
  std::string controls_file;        ///< ControlSetController (resolved); PrescribedController's optional file
  /// PrescribedController: its FunctionSet, each with the name it was given ("" when unnamed)
  std::vector<std::pair<std::string, FunctionDesc>> functions;
  /// CorrectionController (forward runs): gains on the errors from the tool's states_file
  double kp = 100.0, kv = 20.0;
};

/// A controller resolved against a list of actuator names: control k of the list is driven by
/// `function` (one argument: time). As OpenSim's ControllerSet, controllers add up.
struct ResolvedController {
  struct Entry {
    int actuator = -1;        ///< index into the names the controller was resolved against
    AxisFunctionPtr function;
  };
  std::string name;           ///< "ControlSetController FILE", "PrescribedController NAME"
  std::vector<Entry> entries;
};

/// A controls file (ControlSetController) for the actuators `names` it names (bare actuator name
/// or <actuator>.excitation), only those of actuator_list unless it is empty or ALL; actuators
/// without a control and controls that name no actuator go to warnings. Throws ConvertError for
/// unreadable or malformed files.
ResolvedController resolveControlsFile(const std::string& file, const std::vector<std::string>& names,
                                       std::vector<std::string>& warnings,
                                       const std::vector<std::string>& actuator_list = {});

/// A setup's controllers (disabled ones skipped) against `names`: a ControlSetController's
/// controls file; a PrescribedController's functions (a function named after an actuator drives
/// it, otherwise the k-th function the k-th actuator of actuator_list) and its optional controls
/// file. Throws ConvertError naming setup_file and the controller's line for a controller that
/// cannot be built (no controls file, an unnamed function beyond actuator_list, a function that
/// cannot be evaluated); an actuator that is not among `names` is a warning.
std::vector<ResolvedController> resolveSetupControllers(const std::vector<ControllerSetupDesc>& controllers,
                                                        const std::string& setup_file,
                                                        const std::vector<std::string>& names,
                                                        std::vector<std::string>& warnings);

}  // namespace redmax::osim
