// .osim reader: wrap objects on frames, the ForceSet, and the GeometryPath of every path force
// (points, conditional and moving points, wraps), docs/opensim_compatibility.md §6.
#include <algorithm>
#include <cmath>
#include <map>

#include "converter/detail/osim_functions.hpp"
#include "converter/build/muscle_curves.hpp"
#include "converter/detail/osim_reader_impl.hpp"
#include "core/muscles/hill/factory.hpp"

namespace redmax::osim::detail {
namespace {

const std::set<std::string>& muscleClasses() {
  static const std::set<std::string> s = {
      "Thelen2003Muscle",          "Thelen2003Muscle_Deprecated", "Millard2012EquilibriumMuscle",
      "Millard2012AccelerationMuscle", "DeGrooteFregly2016Muscle", "RigidTendonMuscle",
      "Schutte1993Muscle_Deprecated",  "Schutte1993Muscle",       "Delp1990Muscle_Deprecated",
      "Delp1990Muscle"};
  return s;
}

// forces that own a GeometryPath but are not muscles
const std::set<std::string>& pathForceClasses() {
  static const std::set<std::string> s = {"PathActuator", "PathSpring", "ClutchedPathSpring", "McKibbenActuator",
                                          "Ligament", "Blankevoort1991Ligament"};
  return s;
}

// actuators: listed; they apply no force without a control signal
const std::set<std::string>& actuatorClasses() {
  static const std::set<std::string> s = {"CoordinateActuator", "ActivationCoordinateActuator",
                                          "PointActuator",      "TorqueActuator",
                                          "BodyActuator",       "PointToPointActuator",
                                          "GeneralizedForce",   "Force",
                                          "Torque"};
  return s;
}

// the muscle properties the Hill models read (core/muscles/hill): numbers, and booleans (flags)
const std::set<std::string>& muscleNumberProperties() {
  static const std::set<std::string> s = {
      "max_isometric_force", "optimal_fiber_length", "tendon_slack_length",
      "pennation_angle_at_optimal", "max_contraction_velocity", "min_control", "max_control",
      "default_activation", "default_fiber_length", "activation_time_constant",
      "deactivation_time_constant", "minimum_activation", "maximum_pennation_angle", "fiber_damping",
      // Thelen2003Muscle(_Deprecated)
      "Vmax", "Vmax0", "FmaxTendonStrain", "FmaxMuscleStrain", "KshapeActive", "KshapePassive",
      "damping", "Af", "Flen", "fv_linear_extrap_threshold",
      // DeGrooteFregly2016Muscle
      "active_force_width_scale", "passive_fiber_strain_at_one_norm_force",
      "tendon_strain_at_one_norm_force", "default_normalized_tendon_force", "activation_dynamics_smoothing",
      // Schutte1993Muscle_Deprecated
      "time_scale", "activation1", "activation2"};
  return s;
}
const std::set<std::string>& muscleFlagProperties() {
  static const std::set<std::string> s = {"ignore_tendon_compliance", "ignore_activation_dynamics",
                                          "ignore_passive_fiber_force"};
  return s;
}
// Millard2012EquilibriumMuscle's curve sub-objects and their properties
const std::map<std::string, std::set<std::string>>& muscleCurveProperties() {
  static const std::map<std::string, std::set<std::string>> s = {
      {"ActiveForceLengthCurve",
       {"min_norm_active_fiber_length", "transition_norm_fiber_length", "max_norm_active_fiber_length",
        "shallow_ascending_slope", "minimum_value"}},
      {"ForceVelocityCurve",
       {"concentric_slope_at_vmax", "concentric_slope_near_vmax", "isometric_slope",
        "eccentric_slope_at_vmax", "eccentric_slope_near_vmax", "max_eccentric_velocity_force_multiplier",
        "concentric_curviness", "eccentric_curviness"}},
      {"FiberForceLengthCurve",
       {"strain_at_zero_force", "strain_at_one_norm_force", "stiffness_at_low_force",
        "stiffness_at_one_norm_force", "curviness"}},
      {"TendonForceLengthCurve",
       {"strain_at_one_norm_force", "stiffness_at_one_norm_force", "norm_force_at_toe_end", "curviness"}}};
  return s;
}

int quadrantAxis(const std::string& q, int& sign) {
  // WrapObject::extendFinalizeFromProperties
  static const struct {
    const char* names[4];
    int axis, sign;
  } table[] = {
      {{"x", "+x", "X", "+X"}, 0, 1},  {{"-x", "-X", nullptr, nullptr}, 0, -1},
      {{"y", "+y", "Y", "+Y"}, 1, 1},  {{"-y", "-Y", nullptr, nullptr}, 1, -1},
      {{"z", "+z", "Z", "+Z"}, 2, 1},  {{"-z", "-Z", nullptr, nullptr}, 2, -1},
      {{"all", "All", "ALL", "Unassigned"}, -1, 0},
  };
  for (const auto& row : table)
    for (const char* n : row.names)
      if (n && q == n) {
        sign = row.sign;
        return row.axis;
      }
  sign = 0;
  return -2;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// wrap objects: on ground, bodies and offset frames, in component-list order

void OsimReader::readWrapObjects() {
  for (const auto& path : frame_order_) {
    const FrameNode& f = frames_.at(path);
    if (const XMLElement* set = firstChild(f.elem, "WrapObjectSet"))
      // legacy joint frames point at the joint element, which owns no wrap objects
      if (f.kind != FrameNode::Kind::Offset || std::string(f.elem->Name()) == "PhysicalOffsetFrame")
        readWrapObjectSet(set, f);
  }
}

void OsimReader::readWrapObjectSet(const XMLElement* set, const FrameNode& frame) {
  std::set<std::string> names;
  for (const XMLElement* e : childElements(firstChild(set, "objects"))) {
    WrapObjectDesc w;
    w.type = e->Name();
    w.name = componentName(e, names);
    w.line = lineOf(e);
    w.frame = frame.path;
    w.body = frame.base_body;
    if (w.type != "WrapCylinder" && w.type != "WrapSphere" && w.type != "WrapEllipsoid" &&
        w.type != "WrapTorus") {
      addUnsupported(e, "wrap object '" + w.name + "' (" + w.type + ") is not modelled");
      continue;
    }
    w.active = childBool(doc(), e, "active", true);
    w.xyz_body_rotation = childVec3(doc(), e, "xyz_body_rotation", Vec3::Zero());
    w.translation = childVec3(doc(), e, "translation", Vec3::Zero());
    w.X_body = frame.X_base * makePose(w.translation, w.xyz_body_rotation);
    w.quadrant = childText(e, "quadrant", "Unassigned");
    w.quadrant_axis = quadrantAxis(w.quadrant, w.quadrant_sign);
    if (w.quadrant_axis == -2)
      fail(firstChild(e, "quadrant"), "wrap object '" + w.name + "': quadrant '" + w.quadrant +
                                          "' is not one of x, -x, y, -y, z, -z, all");
    if (w.quadrant == "Unassigned") w.quadrant = "all";
    if (w.type == "WrapCylinder") {
      w.radius = childDouble(doc(), e, "radius", 1.0);
      w.length = childDouble(doc(), e, "length", 1.0);
    } else if (w.type == "WrapSphere") {
      w.radius = childDouble(doc(), e, "radius", 0.05);
    } else if (w.type == "WrapEllipsoid") {
      w.dimensions = childVec3(doc(), e, "dimensions", Vec3(0.05, 0.05, 0.05));
    } else {
      w.inner_radius = childDouble(doc(), e, "inner_radius", 0.01);
      w.outer_radius = childDouble(doc(), e, "outer_radius", 0.05);
    }
    d_.wrap_objects.push_back(w);
  }
}

// ---------------------------------------------------------------------------------------------
// forces

void OsimReader::readForces() {
  // pre-2.0 files call the ForceSet an ActuatorSet
  const XMLElement* set = modelChild("ForceSet");
  if (!set) set = modelChild("ActuatorSet");
  std::set<std::string> names;
  // old class names OpenSim registers as aliases (RegisterTypes_osimActuators)
  static const std::map<std::string, std::string> renamed = {
      {"Schutte1993Muscle", "Schutte1993Muscle_Deprecated"},
      {"Delp1990Muscle", "Delp1990Muscle_Deprecated"},
      {"GeneralizedForce", "CoordinateActuator"},
      {"Force", "PointActuator"},
      {"Torque", "TorqueActuator"}};
  for (const XMLElement* e : childElements(firstChild(set, "objects"))) {
    std::string cls = e->Name();
    if (auto it = renamed.find(cls); it != renamed.end()) cls = it->second;
    const std::string name = componentName(e, names);
    bool applies = true;
    if (const XMLElement* d = firstChild(e, "isDisabled"); d && version_ < 30509)
      applies = !parseBool(doc(), d);
    applies = childBool(doc(), e, "appliesForce", applies);
    if (muscleClasses().count(cls) || pathForceClasses().count(cls)) {
      readPathForce(e, name, cls, muscleClasses().count(cls) > 0, applies);
      continue;
    }
    ForceDesc f;
    f.name = name;
    f.class_name = cls;
    f.applies_force = applies;
    f.line = lineOf(e);
    if (actuatorClasses().count(cls)) {
      f.coordinate = childText(e, "coordinate");
      f.optimal_force = childDouble(doc(), e, "optimal_force", 1.0);
      f.min_control = childDouble(doc(), e, "min_control", f.min_control);
      f.max_control = childDouble(doc(), e, "max_control", f.max_control);
    } else if (applies) {
      addUnsupported(e, "force '" + name + "' (" + cls + ") is listed but its force is not modelled");
    }
    d_.forces.push_back(f);
  }
  // ForceSet groups, used by forces_to_exclude
  for (const XMLElement* g : childElements(firstChild(set, "groups"), "ObjectGroup")) {
    ForceGroupDesc fg;
    fg.name = attribute(g, "name");
    fg.members = splitWords(childText(g, "members"));
    d_.force_groups.push_back(fg);
  }
}

void OsimReader::readPathForce(const XMLElement* e, const std::string& name,
                               const std::string& cls, bool is_muscle, bool applies) {
  PathForceDesc m;
  m.name = name;
  m.class_name = is_muscle && !muscle_class_.empty() ? muscle_class_ : cls;
  m.is_muscle = is_muscle;
  m.applies_force = applies;
  m.line = lineOf(e);
  m.max_isometric_force = childDouble(doc(), e, "max_isometric_force", m.max_isometric_force);
  m.optimal_fiber_length = childDouble(doc(), e, "optimal_fiber_length", m.optimal_fiber_length);
  m.tendon_slack_length = childDouble(doc(), e, "tendon_slack_length", m.tendon_slack_length);
  // pennation_angle was renamed at 20302
  m.pennation_angle_at_optimal = childDouble(doc(), e, "pennation_angle", 0.0);
  m.pennation_angle_at_optimal =
      childDouble(doc(), e, "pennation_angle_at_optimal", m.pennation_angle_at_optimal);
  m.max_contraction_velocity =
      childDouble(doc(), e, "max_contraction_velocity", m.max_contraction_velocity);
  m.optimal_force = childDouble(doc(), e, "optimal_force", m.optimal_force);
  m.resting_length = childDouble(doc(), e, "resting_length", 0.0);
  m.stiffness = childDouble(doc(), e, "stiffness", 0.0);
  m.dissipation = childDouble(doc(), e, "dissipation", 0.0);
  if (is_muscle) readMuscleParameters(e, m);

  // the path: a GeometryPath (any name), or a pre-2.0.3 MusclePointSet directly in the muscle
  const XMLElement* path = firstChild(e, "GeometryPath");
  const XMLElement* holder = path ? path : e;
  if (!path) {
    for (const char* other : {"FunctionBasedPath", "Scholz2015GeometryPath"})
      if (const XMLElement* p = firstChild(e, other)) {
        addUnsupported(p, cls + " '" + name + "': a " + other + " is not modelled");
        d_.muscles.push_back(m);
        return;
      }
    if (!firstChild(e, "MusclePointSet") && !firstChild(e, "PathPointSet"))
      fail(e, cls + " '" + name + "' has no GeometryPath");
  }
  const std::string path_name = path ? (attribute(path, "name").empty() ? "geometrypath"
                                                                        : attribute(path, "name"))
                                     : "geometrypath";
  const std::string owner = "/forceset/" + name + "/" + path_name + "/pathpointset";
  const XMLElement* pps = firstChild(holder, "PathPointSet");
  if (!pps) pps = firstChild(holder, "MusclePointSet");
  std::set<std::string> point_names;
  for (const XMLElement* p : childElements(firstChild(pps, "objects")))
    m.points.push_back(readPathPoint(p, owner, point_names));
  if (m.points.size() < 2)
    fail(pps ? pps : holder, cls + " '" + name + "' has " + std::to_string(m.points.size()) +
                                 " path points; a path needs at least 2");

  const XMLElement* pws = firstChild(holder, "PathWrapSet");
  if (!pws) pws = firstChild(holder, "MuscleWrapSet");
  for (const XMLElement* w : childElements(firstChild(pws, "objects"))) {
    const std::string tag = w->Name();
    if (tag != "PathWrap" && tag != "MuscleWrap")
      fail(w, "<" + tag + "> in a PathWrapSet: expected <PathWrap>");
    PathWrapDesc pw;
    pw.line = lineOf(w);
    pw.wrap_object = childText(w, "wrap_object");
    pw.method = childText(w, "method", "hybrid");
    if (pw.method.empty()) pw.method = "hybrid";
    if (pw.method != "hybrid" && pw.method != "midpoint" && pw.method != "axial")
      fail(firstChild(w, "method"), "PathWrap method '" + pw.method +
                                        "' is not hybrid, midpoint or axial");
    if (const XMLElement* r = firstChild(w, "range"); r && !textOf(r).empty()) {
      const auto v = parseNumbersExactly(doc(), r, 2);
      for (double x : v)
        if (!(std::abs(x) < 1e6) || x != std::floor(x))
          fail(r, "PathWrap range needs two path-point indices, found '" + textOf(r) + "'");
      pw.range_begin = static_cast<int>(v[0]);
      pw.range_end = static_cast<int>(v[1]);
    }
    // wrap objects are matched by name, first in component-list order (§1.2)
    pw.wrap_index = d_.findWrapObject(pw.wrap_object);
    if (pw.wrap_index < 0)
      fail(firstChild(w, "wrap_object") ? firstChild(w, "wrap_object") : w,
           cls + " '" + name + "': wrap object '" + pw.wrap_object + "' does not exist");
    m.wraps.push_back(pw);
  }

  // path type: any wrap -> III; via, conditional or moving points -> II; else I
  bool extra = m.points.size() > 2;
  for (const auto& p : m.points) extra = extra || p.kind != PathPointKind::Fixed;
  m.path_type = !m.wraps.empty() ? PathType::III : extra ? PathType::II : PathType::I;
  d_.muscles.push_back(std::move(m));
}

// every property a Hill model reads, as written (absent ones keep the model's OpenSim default),
// then the model is made once so that a value its class refuses is an error at its line
void OsimReader::readMuscleParameters(const XMLElement* e, PathForceDesc& m) {
  hill::MuscleParameters& p = m.parameters;
  p.name = m.name;
  const auto put = [&](const std::string& key, const XMLElement* c, bool flag) {
    if (textOf(c).empty()) return;  // an empty property keeps its default, as childDouble does
    p.set(key, flag ? (parseBool(doc(), c) ? 1.0 : 0.0) : parseNumber(doc(), c, textOf(c)));
    m.parameter_lines[key] = lineOf(c);
  };
  for (const XMLElement* c : childElements(e)) {
    const std::string tag = c->Name();
    if (muscleNumberProperties().count(tag)) {
      put(tag, c, false);
    } else if (muscleFlagProperties().count(tag)) {
      put(tag, c, true);
    } else if (tag == "tendon_compliance_dynamics_mode" && !textOf(c).empty()) {
      // DeGrooteFregly2016Muscle: a string property, 0 explicit, 1 implicit
      const std::string mode = textOf(c);
      if (mode != "explicit" && mode != "implicit")
        fail(c, "tendon_compliance_dynamics_mode '" + mode + "' is not explicit or implicit");
      p.set(tag, mode == "explicit" ? 0.0 : 1.0);
      m.parameter_lines[tag] = lineOf(c);
    } else if (auto it = muscleCurveProperties().find(tag); it != muscleCurveProperties().end()) {
      for (const XMLElement* cc : childElements(c))
        if (it->second.count(cc->Name())) put(tag + "/" + cc->Name(), cc, false);
      m.parameter_lines[tag] = lineOf(c);
    }
  }
  // Function-valued curves (RigidTendonMuscle, Schutte1993Muscle_Deprecated, read for every class
  // so that --muscle-class finds them); their absent ones are the class's default SimmSplines
  for (const char* key : {"active_force_length_curve", "passive_force_length_curve", "force_velocity_curve",
                          "tendon_force_length_curve"}) {
    if (auto f = findFunctionProperty(doc(), e, key)) {
      p.curves[key] = muscleCurve(*f, doc().path(), m.class_name + " '" + m.name + "' " + key);
      m.parameter_lines[key] = f->line;
    }
  }
  p.simm_spline = muscleSplineFactory();
  // pennation_angle: the <= 20301 spelling (Muscle::updateFromXMLNode)
  if (!p.has("pennation_angle_at_optimal"))
    if (const XMLElement* c = firstChild(e, "pennation_angle"); c && !textOf(c).empty()) {
      p.set("pennation_angle_at_optimal", parseNumber(doc(), c, textOf(c)));
      m.parameter_lines["pennation_angle_at_optimal"] = lineOf(c);
    }
  // before 30513 a min_control of 0 or a max_control of 1 was written by mistake and is dropped,
  // so that the class's default applies (Muscle::updateFromXMLNode)
  if (version_ < 30513) {
    if (p.has("min_control") && p.values.at("min_control") == 0.0) p.values.erase("min_control");
    if (p.has("max_control") && p.values.at("max_control") == 1.0) p.values.erase("max_control");
  }
  // check the values now, at the line that holds them
  if (std::find(hill::muscleModelClasses().begin(), hill::muscleModelClasses().end(), m.class_name) ==
      hill::muscleModelClasses().end())
    return;
  try {
    hill::makeMuscleModel(m.class_name, p);
  } catch (const hill::MuscleParameterError& err) {
    auto it = m.parameter_lines.find(err.property());
    if (it == m.parameter_lines.end()) {
      // a curve parameter: the line of its curve, else the muscle's
      const auto slash = err.property().find('/');
      if (slash != std::string::npos) it = m.parameter_lines.find(err.property().substr(0, slash));
    }
    const int line = it != m.parameter_lines.end() ? it->second : m.line;
    throw ConvertError(doc().path(), line, m.class_name + " " + err.what());
  }
}

PathPointDesc OsimReader::readPathPoint(const XMLElement* e, const std::string& owner,
                                        std::set<std::string>& names) {
  PathPointDesc p;
  const std::string tag = e->Name();
  p.name = componentName(e, names);
  p.line = lineOf(e);
  if (tag == "PathPoint" || tag == "MusclePoint") {
    p.kind = PathPointKind::Fixed;
  } else if (tag == "ConditionalPathPoint" || tag == "MuscleViaPoint") {
    p.kind = PathPointKind::Conditional;
  } else if (tag == "MovingPathPoint" || tag == "MovingMusclePoint") {
    p.kind = PathPointKind::Moving;
  } else {
    fail(e, "<" + tag + "> in a PathPointSet is not a path point type");
  }
  const std::string self = owner + "/" + p.name;
  // the frame: a socket (4.0) or a body name (legacy)
  const XMLElement* where = nullptr;
  const std::string socket = frameReference(e, "parent_frame", "body", &where);
  if (socket.empty()) fail(e, "path point '" + p.name + "' names no parent frame or body");
  const FrameNode& f = frameForSocket(self, socket, where ? where : e,
                                      "parent_frame of path point '" + p.name + "'");
  p.frame = f.path;
  p.body = f.base_body;
  p.X_body_frame = f.X_base;
  p.location = childVec3(doc(), e, "location", Vec3::Zero());

  if (p.kind == PathPointKind::Conditional) {
    const XMLElement* r = firstChild(e, "range");
    if (!r || textOf(r).empty()) fail(e, "conditional path point '" + p.name + "' has no <range>");
    const auto v = parseNumbersExactly(doc(), r, 2);
    p.range_min = v[0];
    p.range_max = v[1];
    const XMLElement* cw = nullptr;
    // <coordinates> is the <= 20001 spelling
    std::string cs = coordinateReference(e, "coordinate", firstChild(e, "coordinate") ? "coordinate" : "coordinates", &cw);
    p.coordinate = coordinateForSocket(self, cs, cw ? cw : e);
    if (p.coordinate.empty())
      warn(e, "conditional path point '" + p.name + "' names no coordinate: it is never active");
  } else if (p.kind == PathPointKind::Moving) {
    static const char* axes[3] = {"x", "y", "z"};
    static const char* legacy_names[3] = {"XAttachment", "YAttachment", "ZAttachment"};
    for (int k = 0; k < 3; ++k) {
      const std::string loc = std::string(axes[k]) + "_location";
      auto f = findFunctionProperty(doc(), e, loc.c_str());
      if (!f && version_ < 30000) f = findFunctionProperty(doc(), e, legacy_names[k]);
      if (f) {
        if (f->numArguments() > 1)
          throw ConvertError(doc().path(), f->line,
                             "moving path point '" + p.name + "': " + loc +
                                 " must be a function of one coordinate");
        p.location_functions[k] = *f;
      }
      const XMLElement* cw = nullptr;
      const std::string cname = std::string(axes[k]) + "_coordinate";
      const std::string cs = coordinateReference(e, cname, cname.c_str(), &cw);
      p.location_coordinates[k] = coordinateForSocket(self, cs, cw ? cw : e);
    }
    // all three must name the same coordinate, or none (MovingPathPoint)
    std::string common;
    for (const auto& c : p.location_coordinates) {
      if (c.empty()) continue;
      if (!common.empty() && c != common)
        fail(e, "moving path point '" + p.name + "' names different coordinates ('" + common +
                    "', '" + c + "') for x, y and z");
      common = c;
    }
  }
  return p;
}

}  // namespace redmax::osim::detail
