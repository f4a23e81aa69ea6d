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

/// The tool's own controls_file (resolved against dir), as OpenSim's AbstractTool::updateFromXMLNode
/// takes it: only from a document older than version 10904 (no <OpenSimDocument> counts as
/// 10500), where it becomes a ControlSetController. In a newer document OpenSim ignores it; so
/// does this, naming it in `warnings` with where a controls file belongs. "" when none applies.
std::string readToolControlsFile(const XmlDocument& doc, const XMLElement* tool, const std::string& dir,
                                 std::vector<std::string>& warnings);

}  // namespace redmax::osim::detail
