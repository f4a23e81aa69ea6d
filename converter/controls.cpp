#include "converter/controls.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "converter/build/functions_to_core.hpp"
#include "converter/detail/xml_util.hpp"
#include "converter/storage.hpp"

namespace redmax::osim {

namespace {

using detail::XMLElement;
using detail::XmlDocument;

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// ControlLinear::getControlValue on one node list (docs: the header)
double evalNodes(const std::vector<ControlNodeDesc>& n, bool extrapolate, bool use_steps, double fallback,
                 double t) {
  const size_t size = n.size();
  if (size == 0) return fallback;
  auto line = [&](const ControlNodeDesc& a, const ControlNodeDesc& b) {
    const double dt = b.t - a.t;
    if (!(std::abs(dt) > 0.0)) return a.value;
    return a.value + (b.value - a.value) * (t - a.t) / dt;
  };
  // steps never extrapolate (getControlValue: `!_useSteps && getExtrapolate()`)
  const bool lines = extrapolate && !use_steps && size > 1;
  if (t < n[0].t) return lines ? line(n[0], n[1]) : n[0].value;
  if (t >= n[size - 1].t) return lines ? line(n[size - 2], n[size - 1]) : n[size - 1].value;
  // the largest i with n[i].t <= t (OpenSim's searchBinary)
  const auto it = std::upper_bound(n.begin(), n.end(), t, [](double x, const ControlNodeDesc& c) { return x < c.t; });
  const size_t i = static_cast<size_t>(it - n.begin()) - 1;
  // steps: node i+1's value holds on (t_i, t_i+1], so at t_i itself node i's
  if (use_steps) return t == n[i].t ? n[i].value : n[i + 1].value;
  return line(n[i], n[i + 1]);
}

class ControlFunction final : public UnivariateFunction {
 public:
  explicit ControlFunction(ControlLinearDesc c) : c_(std::move(c)) {}
  void evaluate1(double t, double& f, double& df, double& ddf) const override {
    f = c_.value(t);
    df = ddf = 0.0;  // controls enter as values only
  }
  std::string typeName() const override { return c_.type; }

 private:
  ControlLinearDesc c_;
};

std::vector<ControlNodeDesc> readNodes(const XmlDocument& doc, const XMLElement* control, const char* tag) {
  std::vector<ControlNodeDesc> nodes;
  const XMLElement* list = detail::firstChild(control, tag);
  if (!list) return nodes;
  for (const XMLElement* n : detail::childElements(list)) {
    if (std::string(n->Name()) != "ControlLinearNode") doc.fail(n, std::string(tag) + ": expected ControlLinearNode, found " + n->Name());
    const XMLElement* te = detail::firstChild(n, "t");
    const XMLElement* ve = detail::firstChild(n, "value");
    if (!te || !ve) doc.fail(n, "ControlLinearNode needs <t> and <value>");
    ControlNodeDesc d;
    d.t = detail::parseNumbersExactly(doc, te, 1)[0];
    d.value = detail::parseNumbersExactly(doc, ve, 1)[0];
    if (!std::isfinite(d.t) || !std::isfinite(d.value)) doc.fail(n, "non-finite control node");
    if (!nodes.empty() && d.t < nodes.back().t)
      doc.fail(n, std::string(tag) + ": node times must not decrease");
    nodes.push_back(d);
  }
  return nodes;
}

ControlSetDesc readXml(const std::string& path) {
  const XmlDocument doc(path);
  const XMLElement* root = doc.root();
  if (!root) doc.fail(nullptr, "empty file");
  const XMLElement* set = std::string(root->Name()) == "ControlSet" ? root : detail::firstChild(root, "ControlSet");
  if (!set) doc.fail(root, "no ControlSet element");
  ControlSetDesc out;
  out.file = path;
  const XMLElement* objects = detail::firstChild(set, "objects");
  std::set<std::string> names;
  if (!objects) return out;
  for (const XMLElement* e : detail::childElements(objects)) {
    const std::string type = e->Name();
    if (type != "ControlLinear" && type != "ControlConstant")
      doc.fail(e, "unsupported control class " + type + " (ControlLinear and ControlConstant are read)");
    ControlLinearDesc c;
    c.type = type;
    c.name = detail::attribute(e, "name");
    c.line = detail::lineOf(e);
    if (c.name.empty()) doc.fail(e, type + " without a name");
    if (!names.insert(c.name).second) doc.fail(e, "control '" + c.name + "' appears twice");
    c.is_model_control = detail::childBool(doc, e, "is_model_control", true);
    c.extrapolate = detail::childBool(doc, e, "extrapolate", true);
    c.use_steps = detail::childBool(doc, e, "use_steps", false);
    c.default_min = detail::childDouble(doc, e, "default_min", 0.0);
    c.default_max = detail::childDouble(doc, e, "default_max", 1.0);
    c.default_value = detail::childDouble(doc, e, "value", 0.0);
    for (double v : {c.default_min, c.default_max, c.default_value})
      if (!std::isfinite(v)) doc.fail(e, "control '" + c.name + "': non-finite default");
    if (type == "ControlLinear") {
      c.x_nodes = readNodes(doc, e, "x_nodes");
      c.min_nodes = readNodes(doc, e, "min_nodes");
      c.max_nodes = readNodes(doc, e, "max_nodes");
    }
    out.controls.push_back(std::move(c));
  }
  return out;
}

ControlSetDesc readTable(const std::string& path) {
  const Storage st = readStorage(path);
  ControlSetDesc out;
  out.file = path;
  std::set<std::string> names;
  for (int j = 0; j < st.numColumns(); ++j) {
    ControlLinearDesc c;
    c.name = st.labels[j];
    if (!names.insert(c.name).second) throw ConvertError(path, 0, "column '" + c.name + "' appears twice");
    for (int r = 0; r < st.numRows(); ++r) {
      const double t = st.time[r], v = st.data(r, j);
      if (!std::isfinite(t) || !std::isfinite(v))
        throw ConvertError(path, 0, "non-finite value in column '" + c.name + "' at row " + std::to_string(r + 1));
      if (r > 0 && t < st.time[r - 1]) throw ConvertError(path, 0, "time decreases at row " + std::to_string(r + 1));
      c.x_nodes.push_back({t, v});
    }
    out.controls.push_back(std::move(c));
  }
  return out;
}

}  // namespace

std::string ControlLinearDesc::actuator() const {
  static const std::string tail = ".excitation";
  return endsWith(name, tail) ? name.substr(0, name.size() - tail.size()) : name;
}

double ControlLinearDesc::value(double t) const { return evalNodes(x_nodes, extrapolate, use_steps, default_value, t); }
double ControlLinearDesc::minValue(double t) const { return evalNodes(min_nodes, extrapolate, use_steps, default_min, t); }
double ControlLinearDesc::maxValue(double t) const { return evalNodes(max_nodes, extrapolate, use_steps, default_max, t); }

const ControlLinearDesc* ControlSetDesc::findForActuator(const std::string& name) const {
  // OpenSim's ControlSetController: the actuator's name, then name + ".excitation"
  for (const std::string& key : {name, name + ".excitation"})
    for (const ControlLinearDesc& c : controls)
      if (c.is_model_control && c.name == key) return &c;
  return nullptr;
}

ControlSetDesc readControlSet(const std::string& path) {
  const std::string lower = detail::toLower(path);
  if (endsWith(lower, ".sto") || endsWith(lower, ".mot")) return readTable(path);
  return readXml(path);
}

AxisFunctionPtr makeControlFunction(const ControlLinearDesc& c) { return std::make_shared<ControlFunction>(c); }

namespace {
bool listsAll(const std::vector<std::string>& list) {
  return list.empty() || (list.size() == 1 && detail::toLower(list[0]) == "all");
}
}  // namespace

ResolvedController resolveControlsFile(const std::string& file, const std::vector<std::string>& names,
                                       std::vector<std::string>& warnings,
                                       const std::vector<std::string>& actuator_list) {
  const ControlSetDesc cs = readControlSet(file);
  std::set<std::string> allowed;
  if (!listsAll(actuator_list)) allowed.insert(actuator_list.begin(), actuator_list.end());
  ResolvedController out;
  out.name = "ControlSetController " + file;
  std::set<std::string> used;
  for (int k = 0; k < static_cast<int>(names.size()); ++k) {
    if (!allowed.empty() && !allowed.count(names[k])) continue;
    const ControlLinearDesc* c = cs.findForActuator(names[k]);
    if (!c) {
      warnings.push_back(file + ": no control for actuator '" + names[k] + "' (its control stays 0)");
      continue;
    }
    // OpenSim's ControlLinear::getControlValue returns NaN without nodes; refuse before a run does
    if (c->type == "ControlLinear" && c->x_nodes.empty())
      throw ConvertError(file, c->line, "ControlLinear '" + c->name + "' drives actuator '" + names[k] +
                                            "' but has no x_nodes (OpenSim evaluates it as NaN); give it nodes or "
                                            "use a ControlConstant");
    used.insert(c->name);
    out.entries.push_back({k, makeControlFunction(*c)});
  }
  for (const ControlLinearDesc& c : cs.controls)
    if (!used.count(c.name) && c.is_model_control)
      warnings.push_back(file + ": control '" + c.name + "' names no actuator of the model; ignored");
  return out;
}

std::vector<ResolvedController> resolveSetupControllers(const std::vector<ControllerSetupDesc>& controllers,
                                                        const std::string& setup_file,
                                                        const std::vector<std::string>& names,
                                                        std::vector<std::string>& warnings) {
  std::vector<ResolvedController> out;
  for (const ControllerSetupDesc& c : controllers) {
    if (c.disabled) continue;
    if (c.type == "CorrectionController") {
      // its own actuators and desired states: the forward tool's (validation/forward/forward_tool.cpp)
      warnings.push_back(setup_file + ":" + std::to_string(c.line) + ": CorrectionController '" + c.name +
                         "' acts in forward runs only; ignored here");
      continue;
    }
    if (c.type == "ControlSetController") {
      if (c.controls_file.empty())
        throw ConvertError(setup_file, c.line, "ControlSetController '" + c.name + "' has no controls_file");
      out.push_back(resolveControlsFile(c.controls_file, names, warnings, c.actuator_list));
      continue;
    }
    // PrescribedController: a function named after an actuator drives it; otherwise the k-th
    // function drives the k-th actuator of actuator_list (OpenSim's order)
    ResolvedController r;
    r.name = "PrescribedController " + c.name;
    for (size_t k = 0; k < c.functions.size(); ++k) {
      const auto& [fname, fdesc] = c.functions[k];
      std::string actuator;
      if (std::find(names.begin(), names.end(), fname) != names.end()) actuator = fname;
      else if (k < c.actuator_list.size() && !listsAll(c.actuator_list)) actuator = c.actuator_list[k];
      else
        throw ConvertError(setup_file, fdesc.line ? fdesc.line : c.line,
                           "PrescribedController '" + c.name + "': function " + std::to_string(k + 1) +
                               " names no actuator (name it after one, or list the actuators in actuator_list)");
      const auto it = std::find(names.begin(), names.end(), actuator);
      if (it == names.end()) {
        warnings.push_back(setup_file + ": PrescribedController '" + c.name + "': actuator '" + actuator +
                           "' is not an actuator the model simulates; ignored");
        continue;
      }
      r.entries.push_back({static_cast<int>(it - names.begin()),
                           makeCoreFunction(fdesc, 1, setup_file, "PrescribedController '" + c.name + "'")});
    }
    if (!r.entries.empty()) out.push_back(std::move(r));
    if (!c.controls_file.empty()) out.push_back(resolveControlsFile(c.controls_file, names, warnings, c.actuator_list));
  }
  return out;
}

}  // namespace redmax::osim
