// ExternalLoads and InverseDynamicsTool setup files (docs/opensim_compatibility.md §7).
#include "converter/external_loads.hpp"

#include <filesystem>
#include <set>

#include "converter/detail/xml_util.hpp"
#include "converter/id_setup.hpp"
#include "converter/signal/signal_error.hpp"

namespace redmax::osim {
namespace fs = std::filesystem;
using namespace detail;


std::string resolveRelativeTo(const std::string& dir, const std::string& path) {
  if (path.empty()) return {};
  const fs::path p(path);
  if (p.is_absolute() || dir.empty()) return p.lexically_normal().string();
  return (fs::path(dir) / p).lexically_normal().string();
}

ExternalLoads readExternalLoads(const std::string& xml_path, const std::string& working_dir) {
  XmlDocument doc(xml_path);
  const XMLElement* el = toolRoot(doc, "ExternalLoads");
  ExternalLoads loads;
  loads.source_file = xml_path;
  loads.name = attribute(el, "name");
  int version = 40000;
  if (const char* v = doc.root()->Attribute("Version")) version = std::atoi(v);

  // the data file: first relative to the working directory, then to the XML's folder
  const XMLElement* df = firstChild(el, "datafile");
  loads.datafile = textOf(df);
  if (loads.datafile.empty())
    doc.fail(df ? df : el, "ExternalLoads has no <datafile> with the force data");
  const std::string cand1 = resolveRelativeTo(working_dir.empty() ? "." : working_dir, loads.datafile);
  const std::string cand2 = resolveRelativeTo(folderOf(xml_path), loads.datafile);
  std::error_code ec;
  if (fs::is_regular_file(cand1, ec)) loads.datafile_path = cand1;
  else if (fs::is_regular_file(cand2, ec)) loads.datafile_path = cand2;
  else
    doc.fail(df, "data file '" + loads.datafile + "' not found (looked for " + cand1 + " and " +
                     cand2 + ")");
  loads.data = readStorage(loads.datafile_path);

  const std::string kin = childText(el, "external_loads_model_kinematics_file");
  if (!kin.empty())
    loads.warnings.push_back("external_loads_model_kinematics_file '" + kin +
                             "' is an OpenSim 3.x setting that OpenSim 4.x ignores");
  if (childDouble(doc, el, "lowpass_cutoff_frequency_for_load_kinematics", -1.0) >= 0.0)
    loads.warnings.push_back(
        "lowpass_cutoff_frequency_for_load_kinematics is ignored by OpenSim 4.x");

  std::set<std::string> names;
  for (const XMLElement* e : childElements(firstChild(el, "objects"))) {
    if (std::string(e->Name()) != "ExternalForce")
      doc.fail(e, "<" + std::string(e->Name()) + "> in ExternalLoads: only ExternalForce is read");
    ExternalForceDesc f;
    f.line = lineOf(e);
    f.name = attribute(e, "name");
    if (f.name.empty()) f.name = "externalforce";
    for (int k = 0; names.count(f.name); ++k) f.name = attribute(e, "name") + "_" + std::to_string(k);
    names.insert(f.name);
    if (const XMLElement* d = firstChild(e, "isDisabled"); d && version < 30509)
      f.applies_force = !parseBool(doc, d);
    f.applies_force = childBool(doc, e, "appliesForce", f.applies_force);
    f.applied_to_body = childText(e, "applied_to_body");
    if (f.applied_to_body.empty())
      doc.fail(e, "ExternalForce '" + f.name + "' has no applied_to_body");
    const std::string fe = childText(e, "force_expressed_in_body");
    const std::string pe = childText(e, "point_expressed_in_body");
    if (!fe.empty()) f.force_expressed_in_body = fe;
    if (!pe.empty()) f.point_expressed_in_body = pe;
    f.force_identifier = childText(e, "force_identifier");
    f.point_identifier = childText(e, "point_identifier");
    f.torque_identifier = childText(e, "torque_identifier");
    f.data_source_name = childText(e, "data_source_name");
    // identifiers: exactly three columns by case-sensitive prefix, in file column order
    auto match = [&](const std::string& id, const char* what, std::array<int, 3>& cols) {
      if (id.empty()) return;
      const auto c = loads.data.findColumnsWithPrefix(id);
      if (c.size() != 3)
        doc.fail(firstChild(e, (std::string(what) + "_identifier").c_str()),
                 "ExternalForce '" + f.name + "': " + what + "_identifier '" + id + "' matches " +
                     std::to_string(c.size()) + " columns of " + loads.datafile_path +
                     " (needs exactly 3)");
      for (int k = 0; k < 3; ++k) cols[k] = c[k];
    };
    match(f.force_identifier, "force", f.force_columns);
    match(f.point_identifier, "point", f.point_columns);
    match(f.torque_identifier, "torque", f.torque_columns);
    if (f.hasPoint() && !f.hasForce())
      doc.fail(e, "ExternalForce '" + f.name + "' has a point but no force");
    if (!f.hasForce() && !f.hasTorque())
      doc.fail(e, "ExternalForce '" + f.name + "' has neither a force nor a torque identifier");
    loads.forces.push_back(f);
  }
  return loads;
}

void checkExternalLoads(ExternalLoads& loads, const ModelDescription& model) {
  auto known = [&](std::string n) {
    // a component path or a body name (OpenSim tries the path, then ./bodyset/<name>)
    if (n.rfind("/bodyset/", 0) == 0) n = n.substr(9);
    if (!n.empty() && n[0] == '/') n = n.substr(1);
    return n == model.ground_name || model.findBody(n) >= 0;
  };
  for (auto& f : loads.forces) {
    if (!known(f.applied_to_body))
      throw ConvertError(loads.source_file, f.line,
                         "ExternalForce '" + f.name + "' is applied to body '" + f.applied_to_body +
                             "', which the model does not have");
    for (std::string* frame : {&f.force_expressed_in_body, &f.point_expressed_in_body})
      if (!known(*frame)) {
        loads.warnings.push_back("ExternalForce '" + f.name + "': unknown frame '" + *frame +
                                 "' replaced by ground, as OpenSim does");
        *frame = model.ground_name;
      }
  }
}

// ---------------------------------------------------------------------------------------------

InverseDynamicsSetup readInverseDynamicsSetup(const std::string& path) {
  XmlDocument doc(path);
  const XMLElement* el = toolRoot(doc, "InverseDynamicsTool");
  InverseDynamicsSetup s;
  s.source_file = path;
  s.name = attribute(el, "name");
  s.directory = folderOf(path);
  auto file = [&](const char* tag) { return resolveRelativeTo(s.directory, childText(el, tag)); };
  s.model_file = file("model_file");
  s.coordinates_file = file("coordinates_file");
  s.external_loads_file = file("external_loads_file");
  const std::string rd = childText(el, "results_directory");
  s.results_directory = rd.empty() ? s.directory : resolveRelativeTo(s.directory, rd);
  std::string out = childText(el, "output_gen_force_file");
  if (out.empty()) out = "inverse_dynamics.sto";
  s.output_gen_force_file = resolveRelativeTo(s.results_directory, out);
  const std::string bf = childText(el, "output_body_forces_file");
  if (!bf.empty()) s.output_body_forces_file = resolveRelativeTo(s.results_directory, bf);
  s.lowpass_cutoff_frequency_for_coordinates =
      childDouble(doc, el, "lowpass_cutoff_frequency_for_coordinates", -1.0);
  if (const XMLElement* tr = firstChild(el, "time_range"); tr && !textOf(tr).empty()) {
    const auto v = parseNumbersExactly(doc, tr, 2);
    s.time_start = v[0];
    s.time_end = v[1];
    if (!(s.time_start <= s.time_end))
      doc.fail(tr, "time_range start " + std::to_string(v[0]) + " is after its end " +
                       std::to_string(v[1]));
  }
  s.forces_to_exclude = splitWords(childText(el, "forces_to_exclude"));
  s.joints_to_report_body_forces = splitWords(childText(el, "joints_to_report_body_forces"));
  if (firstChild(el, "coordinates_in_degrees"))
    s.warnings.push_back("coordinates_in_degrees does not exist in OpenSim 4.x and is ignored; the "
                         "coordinates file's header decides degrees or radians");
  if (!childText(el, "input_directory").empty())
    s.warnings.push_back("input_directory is ignored; paths are relative to the setup file");
  if (s.model_file.empty()) s.warnings.push_back("the setup names no model_file");
  if (s.coordinates_file.empty()) s.warnings.push_back("the setup names no coordinates_file");
  return s;
}

// ---------------------------------------------------------------------------------------------
// sources on a built model, sampled in time

namespace {

// a body name as ExternalLoads write it: "name", "/bodyset/name" or "/name"
std::string loadBodyName(std::string n) {
  if (n.rfind("/bodyset/", 0) == 0) n = n.substr(9);
  if (!n.empty() && n[0] == '/') n = n.substr(1);
  return n;
}

std::vector<double> columnOf(const MatX& data, int c) {
  std::vector<double> v(static_cast<size_t>(data.rows()));
  for (Eigen::Index r = 0; r < data.rows(); ++r) v[static_cast<size_t>(r)] = data(r, c);
  return v;
}

}  // namespace

std::vector<LoadSource> makeLoadSources(const ExternalLoads& el, const ModelDescription& d,
                                        const std::vector<int>& body_index, std::vector<std::string>& warnings) {
  auto coreBody = [&](const std::string& name, int line) -> int {
    const std::string n = loadBodyName(name);
    if (n == d.ground_name) return -1;
    const int bi = d.findBody(n);
    const int core = bi >= 0 && bi < static_cast<int>(body_index.size()) ? body_index[bi] : -1;
    if (core < 0) throw ConvertError(el.source_file, line, "body '" + name + "' is not part of the core model");
    return core;
  };
  std::vector<LoadSource> out;
  const Storage& data = el.data;
  for (const ExternalForceDesc& f : el.forces) {
    if (!f.applies_force) continue;
    LoadSource src;
    src.name = f.name;
    src.frame.body = coreBody(f.applied_to_body, f.line);
    if (src.frame.body < 0) {
      warnings.push_back("ExternalForce '" + f.name + "' is applied to ground: it has no effect");
      continue;
    }
    src.frame.force_frame = coreBody(f.force_expressed_in_body, f.line);
    src.frame.point_frame = coreBody(f.point_expressed_in_body, f.line);
    src.frame.has_force = f.hasForce();
    src.frame.has_point = f.hasForce() && f.hasPoint();
    src.frame.has_torque = f.hasTorque();
    try {
      for (int k = 0; k < 3; ++k) {
        if (f.hasForce()) src.force[k] = signal::LoadInterpolant(data.time, columnOf(data.data, f.force_columns[k]));
        if (f.hasPoint()) src.point[k] = signal::LoadInterpolant(data.time, columnOf(data.data, f.point_columns[k]));
        if (f.hasTorque())
          src.torque[k] = signal::LoadInterpolant(data.time, columnOf(data.data, f.torque_columns[k]));
      }
    } catch (const signal::SignalError& e) {
      throw ConvertError(el.datafile_path, 0, "ExternalForce '" + f.name + "': " + e.what());
    }
    out.push_back(std::move(src));
  }
  return out;
}

void sampleLoads(const std::vector<LoadSource>& sources, double t, std::vector<IdLoadSample>& out) {
  out.clear();
  for (const LoadSource& src : sources) {
    IdLoadSample l = src.frame;
    for (int k = 0; k < 3; ++k) {
      if (l.has_force) l.force[k] = src.force[k].calcValue(t);
      if (l.has_point) l.point[k] = src.point[k].calcValue(t);
      if (l.has_torque) l.torque[k] = src.torque[k].calcValue(t);
    }
    out.push_back(l);
  }
}

}  // namespace redmax::osim
