#include "converter/forward_setup.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "converter/detail/controller_set.hpp"
#include "converter/detail/osim_functions.hpp"
#include "converter/detail/xml_util.hpp"
#include "converter/id_setup.hpp"

namespace redmax::osim {

namespace {
namespace fs = std::filesystem;
using namespace detail;

ControllerSetupDesc readController(const XmlDocument& doc, const XMLElement* e, const std::string& dir) {
  ControllerSetupDesc c;
  c.type = e->Name();
  c.name = attribute(e, "name");
  c.line = lineOf(e);
  if (c.type != "ControlSetController" && c.type != "PrescribedController" && c.type != "CorrectionController")
    doc.fail(e, "unsupported controller class " + c.type +
                    " (ControlSetController, PrescribedController and CorrectionController are read)");
  if (c.type == "CorrectionController") {
    c.kp = childDouble(doc, e, "kp", 100.0);
    c.kv = childDouble(doc, e, "kv", 20.0);
    if (!std::isfinite(c.kp) || !std::isfinite(c.kv)) doc.fail(e, "CorrectionController: kp and kv must be finite");
  }
  c.actuator_list = splitWords(childText(e, "actuator_list"));
  if (const XMLElement* s = firstChild(e, "socket_actuators")) {
    // OpenSim 4.6: a list socket of actuator paths; the last path element names the actuator
    for (std::string p : splitWords(textOf(s))) {
      const auto slash = p.find_last_of('/');
      c.actuator_list.push_back(slash == std::string::npos ? p : p.substr(slash + 1));
    }
  }
  c.disabled = childBool(doc, e, "isDisabled", false) || !childBool(doc, e, "enabled", true);
  c.controls_file = resolveRelativeTo(dir, childText(e, "controls_file"));
  if (c.type == "PrescribedController") {
    const XMLElement* fset = firstChild(e, "FunctionSet");
    if (!fset) fset = firstChild(e, "ControlFunctions");
    if (fset) {
      const XMLElement* objects = firstChild(fset, "objects");
      for (const XMLElement* f : childElements(objects ? objects : fset)) {
        if (!isFunctionTag(f->Name())) {
          if (std::string(f->Name()) == "groups") continue;
          doc.fail(f, std::string("PrescribedController: ") + f->Name() + " is not a Function");
        }
        c.functions.emplace_back(attribute(f, "name"), parseFunction(doc, f));
      }
    }
  }
  return c;
}

}  // namespace

std::vector<ControllerSetupDesc> detail::readControllerSet(const XmlDocument& doc, const XMLElement* tool,
                                                           const std::string& dir) {
  std::vector<ControllerSetupDesc> out;
  if (const XMLElement* cs = firstChild(tool, "ControllerSet")) {
    const XMLElement* objects = firstChild(cs, "objects");
    for (const XMLElement* c : childElements(objects ? objects : cs)) {
      if (std::string(c->Name()) == "groups") continue;
      out.push_back(readController(doc, c, dir));
    }
  }
  return out;
}

std::string detail::readToolControlsFile(const XmlDocument& doc, const XMLElement* tool, const std::string& dir,
                                         std::vector<std::string>& warnings) {
  const XMLElement* e = firstChild(tool, "controls_file");
  const std::string file = childText(tool, "controls_file");
  if (!e || file.empty()) return "";
  const int version = documentVersion(doc);
  if (version < 10904) return resolveRelativeTo(dir, file);
  warnings.push_back(doc.path() + ":" + std::to_string(lineOf(e)) + ": the tool's own controls_file '" + file +
                     "' is ignored, as OpenSim ignores it in a document of version " + std::to_string(version) +
                     " (it reads one only before version 10904): give it to a ControlSetController in the "
                     "ControllerSet");
  return "";
}

ForwardSetup readForwardSetup(const std::string& path) {
  XmlDocument doc(path);
  const XMLElement* root = doc.root();
  if (!root) doc.fail(nullptr, "empty file");
  const XMLElement* el = root;
  if (std::string(root->Name()) == "OpenSimDocument") {
    el = firstChild(root, "ForwardTool");
    if (!el) doc.fail(root, "no <ForwardTool> element in <OpenSimDocument>");
  } else if (std::string(root->Name()) != "ForwardTool") {
    doc.fail(root, "root element is <" + std::string(root->Name()) + ">, expected <ForwardTool> or <OpenSimDocument>");
  }
  ForwardSetup s;
  s.source_file = path;
  s.name = attribute(el, "name");
  s.directory = folderOf(path);
  auto file = [&](const char* tag) { return resolveRelativeTo(s.directory, childText(el, tag)); };
  s.model_file = file("model_file");
  s.replace_force_set = childBool(doc, el, "replace_force_set", false);
  for (const std::string& f : splitWords(childText(el, "force_set_files")))
    s.force_set_files.push_back(resolveRelativeTo(s.directory, f));
  const std::string rd = childText(el, "results_directory");
  s.results_directory = rd.empty() ? s.directory : resolveRelativeTo(s.directory, rd);
  if (const XMLElement* e = firstChild(el, "output_precision"); e && !textOf(e).empty()) {
    s.output_precision = parseInt(doc, e);
    if (s.output_precision < 1 || s.output_precision > 20) doc.fail(e, "output_precision must be 1..20");
  }
  s.initial_time = childDouble(doc, el, "initial_time", 0.0);
  s.final_time = childDouble(doc, el, "final_time", 1.0);
  if (!std::isfinite(s.initial_time) || !std::isfinite(s.final_time))
    doc.fail(firstChild(el, "final_time"), "initial_time and final_time must be finite");
  if (s.final_time < s.initial_time)
    doc.fail(firstChild(el, "final_time"), "final_time " + std::to_string(s.final_time) + " is before initial_time " +
                                               std::to_string(s.initial_time));
  s.solve_for_equilibrium = childBool(doc, el, "solve_for_equilibrium_for_auxiliary_states", false);
  if (const XMLElement* e = firstChild(el, "maximum_number_of_integrator_steps"); e && !textOf(e).empty()) {
    s.maximum_number_of_integrator_steps = parseInt(doc, e);
    if (s.maximum_number_of_integrator_steps <= 0) doc.fail(e, "maximum_number_of_integrator_steps must be positive");
  }
  auto positive = [&](const char* tag, double fallback) {
    const double v = childDouble(doc, el, tag, fallback);
    if (!(v > 0.0) || !std::isfinite(v)) doc.fail(firstChild(el, tag), std::string(tag) + " must be positive and finite");
    return v;
  };
  s.maximum_integrator_step_size = positive("maximum_integrator_step_size", 1.0);
  s.minimum_integrator_step_size = positive("minimum_integrator_step_size", 1e-8);
  s.integrator_error_tolerance = positive("integrator_error_tolerance", 1e-5);
  s.controllers = readControllerSet(doc, el, s.directory);
  s.controls_file = readToolControlsFile(doc, el, s.directory, s.warnings);
  s.external_loads_file = file("external_loads_file");
  s.states_file = file("states_file");
  s.use_specified_dt = childBool(doc, el, "use_specified_dt", false);
  if (s.use_specified_dt) s.warnings.push_back("use_specified_dt is ignored: the integrator chooses its own steps");
  if (const XMLElement* as = firstChild(el, "AnalysisSet"))
    if (const XMLElement* o = firstChild(as, "objects"); o && o->FirstChildElement())
      s.warnings.push_back("the AnalysisSet is ignored (only the states and controls are written)");
  if (s.model_file.empty()) s.warnings.push_back("the setup names no model_file");
  return s;
}

}  // namespace redmax::osim
