#pragma once
// A tool setup's <ControllerSet> (ForwardTool, AnalyzeTool: AbstractTool's controllers), read by
// the setup readers of converter/forward_setup.cpp and converter/analyze/analyze_tool.cpp.
#include <string>
#include <vector>

#include "converter/controls.hpp"
#include "converter/detail/xml_util.hpp"

namespace redmax::osim::detail {

/// The ControlSetControllers and PrescribedControllers under `tool`'s <ControllerSet> (files
/// resolved against dir); another controller class fails at its line.
std::vector<ControllerSetupDesc> readControllerSet(const XmlDocument& doc, const XMLElement* tool,
                                                   const std::string& dir);

}  // namespace redmax::osim::detail
