#pragma once
// OpenSim controls (docs/forward.md §3): ControlSet XML files (ControlLinear, ControlConstant),
// controls .sto files, and their evaluation as OpenSim's ControlLinear::getControlValue does:
//   no nodes                          the control's default (ControlConstant: its value; else 0)
//   t before the first node           extrapolate: the line through the first two nodes (one node:
//                                     its value); otherwise the first node's value
//   t at or after the last node       the same with the last two nodes / the last value
//   between nodes i, i+1              use_steps: node i+1's value (a node holds the value of the
//                                     interval that ends at it); otherwise linear interpolation
// min/max (default_min/max, min_nodes/max_nodes) are read and evaluated alike; OpenSim's
// ControlSetController does not clamp with them (the muscle clamps its excitation), nor do we.
// Names: `<actuator>.excitation` and bare actuator names both name the actuator.
// A controls .sto (or .mot) gives one ControlLinear per column (linear, extrapolated), nodes at the
// rows, as OpenSim's ControlSet(Storage) builds them.
#include <string>
#include <vector>

#include "converter/error.hpp"
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

}  // namespace redmax::osim
