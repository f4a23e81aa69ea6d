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

// the forces whose properties readModelledForce reads and whose force redmax computes
const std::set<std::string>& modelledForceClasses() {
  static const std::set<std::string> s = {"CoordinateActuator",   "PointActuator",          "TorqueActuator",
                                          "CoordinateLimitForce", "SpringGeneralizedForce", "PointToPointSpring",
                                          "BushingForce",         "HuntCrossleyForce",      "SmoothSphereHalfSpaceForce"};
  return s;
}

// contact forces redmax does not model, and why (docs/contact.md §4)
const std::map<std::string, std::string>& unmodelledContactForces() {
  static const std::map<std::string, std::string> s = {
      {"ElasticFoundationForce",
       "triangle-mesh contact (a spring per mesh face of a ContactMesh) is not modelled: meshes are not read"},
      {"ExponentialContactForce", "Simbody's ExponentialSpringForce is not modelled"},
      {"MeyerFregly2016Force", "the Moco contact model is not modelled; use SmoothSphereHalfSpaceForce"},
      {"EspositoMiller2018Force", "the Moco contact model is not modelled; use SmoothSphereHalfSpaceForce"}};
  return s;
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
  readForceSet(set, "");
}

void OsimReader::readForceSet(const XMLElement* set, const std::string& source) {
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
      d_.muscles.back().source_file = source;
      continue;
    }
    ForceDesc f;
    f.name = name;
    f.class_name = cls;
    f.applies_force = applies;
    f.line = lineOf(e);
    f.source_file = source;
    if (actuatorClasses().count(cls)) {
      f.coordinate = childText(e, "coordinate");
      f.optimal_force = childDouble(doc(), e, "optimal_force", 1.0);
      f.min_control = childDouble(doc(), e, "min_control", f.min_control);
      f.max_control = childDouble(doc(), e, "max_control", f.max_control);
    }
    if (modelledForceClasses().count(cls)) {
      readModelledForce(e, f);
    } else if (auto it = unmodelledContactForces().find(cls); applies && it != unmodelledContactForces().end()) {
      const std::string where = source.empty() ? std::string() : source + ":" + std::to_string(lineOf(e)) + ": ";
      addUnsupported(e, where + "force '" + name + "' (" + cls + ") is listed but its force is not modelled: " + it->second);
    } else if (applies && !actuatorClasses().count(cls)) {
      // a force_set_files entry names its file and line (the list's lines are the model's)
      const std::string where = source.empty() ? std::string() : source + ":" + std::to_string(lineOf(e)) + ": ";
      addUnsupported(e, where + "force '" + name + "' (" + cls + ") is listed but its force is not modelled");
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

// a body frame reference as OpenSim's forces look it up: a component path (ground, /bodyset/b,
// an offset frame), else a BodySet name; its base body's name and the frame's pose in that body
const FrameNode& OsimReader::forceFrame(const XMLElement* e, const std::string& value, const std::string& what) {
  if (value.empty() || value == "Unassigned") fail(e, what + " names no body");
  for (const std::string& p : {resolvePath("/", value), "/bodyset/" + value})
    if (auto it = frames_.find(p); !p.empty() && it != frames_.end()) return it->second;
  fail(e, what + ": '" + value + "' is not a body or frame of the model");
}

void OsimReader::readModelledForce(const XMLElement* e, ForceDesc& f) {
  const std::string what = f.class_name + " '" + f.name + "'";
  auto nonNegative = [&](const char* tag, double fallback) {
    const double v = childDouble(doc(), e, tag, fallback);
    if (!(v >= 0.0) || !std::isfinite(v))
      fail(firstChild(e, tag) ? firstChild(e, tag) : e, what + ": " + tag + " must be finite and >= 0");
    return v;
  };
  auto nonZero = [&](const char* tag, const Vec3& fallback) {
    const Vec3 v = childVec3(doc(), e, tag, fallback);
    if (!(v.norm() > 0.0) || !v.allFinite())
      fail(firstChild(e, tag) ? firstChild(e, tag) : e, what + ": " + tag + " must be a non-zero vector");
    return v;
  };
  auto coordinate = [&]() {
    const XMLElement* c = firstChild(e, "coordinate");
    f.coordinate = textOf(c);
    if (f.coordinate.empty() || d_.findCoordinate(f.coordinate) < 0)
      fail(c ? c : e, what + ": coordinate '" + f.coordinate + "' is not a coordinate of the model");
  };
  const std::string& cls = f.class_name;
  if (cls == "CoordinateActuator") {
    coordinate();
  } else if (cls == "PointActuator") {
    // a document older than 10905 holds the old Force (PointActuator::updateFromXMLNode): body_B,
    // point_B, direction_A are body, point, direction, the force is global unless the element says
    // otherwise, and the direction read is negated (OpenSim does so even when the new names are used)
    const bool old_force = version_ < 10905;
    auto tag = [&](const char* now, const char* before) {
      return old_force && !firstChild(e, now) && firstChild(e, before) ? before : now;
    };
    // body: a BodySet name (PointActuator::extendConnectToModel), never ground
    const XMLElement* b = firstChild(e, tag("body", "body_B"));
    f.body1 = textOf(b);
    if (d_.findBody(f.body1) < 0)
      fail(b ? b : e, what + ": body '" + f.body1 + "' is not a body of the model's BodySet");
    f.point1 = childVec3(doc(), e, tag("point", "point_B"), Vec3::Zero());
    f.point_is_global = childBool(doc(), e, "point_is_global", false);
    f.direction = nonZero(tag("direction", "direction_A"), Vec3::UnitX());
    f.force_is_global = childBool(doc(), e, "force_is_global", old_force);
    if (old_force) f.direction = -f.direction;
  } else if (cls == "TorqueActuator") {
    // before 10905 (TorqueActuator::updateFromXMLNode): body_A is bodyB, body_B is bodyA, direction_A
    // is axis, and the axis read is negated (even when the new names are used)
    const bool old_torque = version_ < 10905;
    auto tag = [&](const char* now, const char* before) {
      return old_torque && !firstChild(e, now) && firstChild(e, before) ? before : now;
    };
    const XMLElement* a = firstChild(e, tag("bodyA", "body_B"));
    const XMLElement* b = firstChild(e, tag("bodyB", "body_A"));
    const FrameNode& fa = forceFrame(a ? a : e, textOf(a), what + " bodyA");
    const FrameNode& fb = forceFrame(b ? b : e, textOf(b), what + " bodyB");
    f.body1 = fa.base_body;
    f.body2 = fb.base_body;
    f.force_is_global = childBool(doc(), e, "torque_is_global", true);
    f.direction = nonZero(tag("axis", "direction_A"), Vec3::UnitZ());
    if (old_torque) f.direction = -f.direction;
    // an axis in an offset frame of bodyA, re-expressed in its base body
    if (!f.force_is_global) f.direction = fa.X_base.topLeftCorner<3, 3>() * f.direction;
  } else if (cls == "CoordinateLimitForce") {
    coordinate();
    f.upper_stiffness = nonNegative("upper_stiffness", 1.0);
    f.upper_limit = childDouble(doc(), e, "upper_limit", 0.0);
    f.lower_stiffness = nonNegative("lower_stiffness", 1.0);
    f.lower_limit = childDouble(doc(), e, "lower_limit", 0.0);
    f.damping = nonNegative("damping", 0.001);
    f.transition = childDouble(doc(), e, "transition", 0.1);
    if (!(f.transition > 0.0) || !std::isfinite(f.transition))
      fail(firstChild(e, "transition") ? firstChild(e, "transition") : e, what + ": transition must be positive");
  } else if (cls == "SpringGeneralizedForce") {
    coordinate();
    f.stiffness = nonNegative("stiffness", 0.0);
    f.rest_length = childDouble(doc(), e, "rest_length", 0.0);
    f.viscosity = nonNegative("viscosity", 0.0);
  } else if (cls == "PointToPointSpring") {
    const std::string self = "/forceset/" + f.name;
    const XMLElement* w1 = nullptr;
    const XMLElement* w2 = nullptr;
    const std::string s1 = frameReference(e, "body1", "body1", &w1);
    const std::string s2 = frameReference(e, "body2", "body2", &w2);
    const FrameNode& f1 = frameForSocket(self, s1, w1 ? w1 : e, what + " body1");
    const FrameNode& f2 = frameForSocket(self, s2, w2 ? w2 : e, what + " body2");
    if (f1.base_body == f2.base_body) fail(e, what + ": body1 and body2 are fixed to the same body '" + f1.base_body + "'");
    f.body1 = f1.base_body;
    f.body2 = f2.base_body;
    // SimTK::Force::TwoPointLinearSpring on the frames' mobilized bodies: the points are stations
    // of the base bodies, whatever offset the frames have
    f.point1 = childVec3(doc(), e, "point1", Vec3::Zero());
    f.point2 = childVec3(doc(), e, "point2", Vec3::Zero());
    f.stiffness = nonNegative("stiffness", 1.0);
    f.rest_length = nonNegative("rest_length", 0.0);
  } else if (cls == "HuntCrossleyForce" || cls == "SmoothSphereHalfSpaceForce") {
    readContactForce(e, f);
  } else if (cls == "BushingForce") {
    readBushing(e, f);
  }
  f.modelled = true;
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

// ---------------------------------------------------------------------------------------------
// contact geometry and contact forces (docs/contact.md)

void OsimReader::readContactGeometry() {
  const XMLElement* set = modelChild("ContactGeometrySet");
  if (!set) return;
  const std::string set_path = "/" + (attribute(set, "name").empty() ? std::string("contactgeometryset") : attribute(set, "name"));
  std::set<std::string> names;
  for (const XMLElement* e : childElements(firstChild(set, "objects"))) {
    ContactGeometryDesc g;
    g.class_name = e->Name();
    g.name = componentName(e, names);
    g.line = lineOf(e);
    const std::string what = g.class_name + " '" + g.name + "'";
    // the frame: socket_frame (4.0), else the 3.x body_name
    const XMLElement* where = nullptr;
    const std::string socket = frameReference(e, "frame", "body_name", &where);
    if (socket.empty()) fail(e, what + " names no frame or body");
    const FrameNode& fr = frameForSocket(set_path + "/" + g.name, socket, where ? where : e, what + " frame");
    g.frame = fr.path;
    g.body = fr.base_body;
    // ContactGeometry::getTransform: location, body-fixed x-y-z orientation, in the frame
    g.X_body = fr.X_base * makePose(childVec3(doc(), e, "location", Vec3::Zero()),
                                    childVec3(doc(), e, "orientation", Vec3::Zero()));
    if (g.class_name == "ContactSphere") {
      g.radius = childDouble(doc(), e, "radius", 0.0);
      if (!(g.radius > 0.0) || !std::isfinite(g.radius))
        fail(firstChild(e, "radius") ? firstChild(e, "radius") : e, what + ": radius must be positive and finite");
      g.modelled = true;
    } else if (g.class_name == "ContactHalfSpace") {
      g.modelled = true;
    } else if (g.class_name == "ContactMesh") {
      addUnsupported(e, what + " in ContactGeometrySet: mesh contact is not modelled (meshes are not read; "
                               "Simbody's HuntCrossleyForce ignores mesh contacts too)");
    } else {
      addUnsupported(e, what + " in ContactGeometrySet: this contact geometry is not modelled");
    }
    d_.contact_geometry.push_back(g);
  }
}

// HuntCrossleyForce (its ContactParametersSet) and SmoothSphereHalfSpaceForce (sockets sphere,
// half_space and one material), with OpenSim's defaults
void OsimReader::readContactForce(const XMLElement* e, ForceDesc& f) {
  const std::string what = f.class_name + " '" + f.name + "'";
  auto nonNegative = [&](const XMLElement* p, const char* tag, double fallback) {
    const double v = childDouble(doc(), p, tag, fallback);
    if (!(v >= 0.0) || !std::isfinite(v))
      fail(firstChild(p, tag) ? firstChild(p, tag) : p, what + ": " + tag + " must be finite and >= 0");
    return v;
  };
  auto positive = [&](const XMLElement* p, const char* tag, double fallback) {
    const double v = childDouble(doc(), p, tag, fallback);
    if (!(v > 0.0) || !std::isfinite(v))
      fail(firstChild(p, tag) ? firstChild(p, tag) : p, what + ": " + tag + " must be positive and finite");
    return v;
  };
  auto endsWith = [](const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
  };
  f.transition_velocity = positive(e, "transition_velocity", 0.01);
  if (f.class_name == "HuntCrossleyForce") {
    // <HuntCrossleyForce::ContactParametersSet name="contact_parameters"><objects>
    //   <HuntCrossleyForce::ContactParameters> ...
    for (const XMLElement* set : childElements(e)) {
      if (!endsWith(set->Name(), "ContactParametersSet")) continue;
      for (const XMLElement* p : childElements(firstChild(set, "objects"))) {
        if (!endsWith(p->Name(), "ContactParameters")) fail(p, what + ": <" + std::string(p->Name()) + "> is not ContactParameters");
        ContactParametersDesc cp;
        cp.line = lineOf(p);
        cp.geometry = splitWords(childText(p, "geometry"));
        for (const std::string& g : cp.geometry)
          if (d_.findContactGeometry(g) < 0)
            fail(firstChild(p, "geometry"), what + ": '" + g + "' is not in the model's ContactGeometrySet");
        // a zero stiffness makes Simbody's s1 = 0/0: refused here instead of a NaN there
        cp.stiffness = positive(p, "stiffness", 0.0);
        cp.dissipation = nonNegative(p, "dissipation", 0.0);
        cp.static_friction = nonNegative(p, "static_friction", 0.0);
        cp.dynamic_friction = nonNegative(p, "dynamic_friction", 0.0);
        cp.viscous_friction = nonNegative(p, "viscous_friction", 0.0);
        f.contact_parameters.push_back(cp);
      }
    }
    if (f.contact_parameters.empty()) warn(e, what + " has no contact parameters: it applies no force");
    return;
  }
  // SmoothSphereHalfSpaceForce
  auto geometry = [&](const char* socket, const char* cls) {
    const XMLElement* w = nullptr;
    std::string v = socketValue(e, socket, &w);
    const auto slash = v.rfind('/');
    const std::string name = slash == std::string::npos ? v : v.substr(slash + 1);
    const int gi = d_.findContactGeometry(name);
    if (name.empty() || gi < 0)
      fail(w ? w : e, what + ": socket " + socket + " '" + v + "' is not in the model's ContactGeometrySet");
    if (d_.contact_geometry[static_cast<size_t>(gi)].class_name != cls)
      fail(w ? w : e, what + ": socket " + socket + " '" + v + "' is a " +
                          d_.contact_geometry[static_cast<size_t>(gi)].class_name + ", not a " + cls);
    return name;
  };
  f.sphere = geometry("sphere", "ContactSphere");
  f.half_space = geometry("half_space", "ContactHalfSpace");
  ContactParametersDesc cp;
  cp.line = f.line;
  cp.geometry = {f.sphere, f.half_space};
  cp.stiffness = nonNegative(e, "stiffness", 1.0);
  cp.dissipation = nonNegative(e, "dissipation", 0.0);
  cp.static_friction = nonNegative(e, "static_friction", 0.0);
  cp.dynamic_friction = nonNegative(e, "dynamic_friction", 0.0);
  cp.viscous_friction = nonNegative(e, "viscous_friction", 0.0);
  f.contact_parameters = {cp};
  f.constant_contact_force = nonNegative(e, "constant_contact_force", 1e-5);
  f.hertz_smoothing = nonNegative(e, "hertz_smoothing", 300.0);
  f.hunt_crossley_smoothing = nonNegative(e, "hunt_crossley_smoothing", 50.0);
}

// BushingForce (a TwoFrameLinker): frame1, frame2 are sockets, usually to offset frames the force
// owns in its <frames>; before 30500 body_1/body_2 with location_ and orientation_body_1/2
void OsimReader::readBushing(const XMLElement* e, ForceDesc& f) {
  const std::string what = "BushingForce '" + f.name + "'";
  auto vec = [&](const char* tag) {
    const Vec3 v = childVec3(doc(), e, tag, Vec3::Zero());
    for (int i = 0; i < 3; ++i)
      if (!(v[i] >= 0.0) || !std::isfinite(v[i]))
        fail(firstChild(e, tag) ? firstChild(e, tag) : e, what + ": " + tag + " must be finite and >= 0");
    return v;
  };
  f.bushing_stiffness << vec("rotational_stiffness"), vec("translational_stiffness");
  f.bushing_damping << vec("rotational_damping"), vec("translational_damping");
  const std::string self = "/forceset/" + f.name;
  // the force's own offset frames
  for (const XMLElement* fr : childElements(firstChild(e, "frames"))) {
    if (std::string(fr->Name()) != "PhysicalOffsetFrame") fail(fr, what + ": <" + fr->Name() + "> is not a PhysicalOffsetFrame");
    std::set<std::string> none;
    const std::string name = componentName(fr, none);
    const XMLElement* w = nullptr;
    const std::string parent = socketValue(fr, "parent", &w);
    const FrameNode& p = frameForSocket(self + "/" + name, parent, w ? w : fr, what + " frame '" + name + "'");
    FrameNode n;
    n.kind = FrameNode::Kind::Offset;
    n.name = name;
    n.path = self + "/" + name;
    n.base_body = p.base_body;
    n.X_base = p.X_base * makePose(childVec3(doc(), fr, "translation", Vec3::Zero()),
                                   childVec3(doc(), fr, "orientation", Vec3::Zero()));
    n.state = 2;
    n.elem = fr;
    frames_[n.path] = n;
  }
  for (int k = 0; k < 2; ++k) {
    const std::string socket = k == 0 ? "frame1" : "frame2";
    const std::string legacy = k == 0 ? "body_1" : "body_2";
    std::string& body = k == 0 ? f.body1 : f.body2;
    Mat4& X = k == 0 ? f.X_body1 : f.X_body2;
    if (const XMLElement* l = firstChild(e, legacy.c_str()); l && socketValue(e, socket, nullptr).empty()) {
      const FrameNode& b = frameForSocket(self, legacyBodyPath(textOf(l)), l, what + " " + legacy);
      body = b.base_body;
      const std::string n = k == 0 ? "1" : "2";
      X = b.X_base * makePose(childVec3(doc(), e, ("location_body_" + n).c_str(), Vec3::Zero()),
                              childVec3(doc(), e, ("orientation_body_" + n).c_str(), Vec3::Zero()));
      continue;
    }
    const XMLElement* w = nullptr;
    const std::string v = socketValue(e, socket, &w);
    const FrameNode& fr = frameForSocket(self, v, w ? w : e, what + " " + socket);
    body = fr.base_body;
    X = fr.X_base;
  }
  if (f.body1 == f.body2) fail(e, what + ": frame1 and frame2 are fixed to the same body '" + f.body1 + "'");
}

// a force_set_files file: its ForceSet read against `model`'s frames and coordinates, as
// OpenSim's tools append it (ForceSet(file) then Model::updForceSet().append)
void OsimReader::appendForceSetTo(ModelDescription& model, bool model_forces_replaced) {
  const XMLElement* root = doc_.root();
  if (!root) fail(nullptr, "empty file");
  const XMLElement* set = root;
  // a file without <OpenSimDocument> is version 10500, and its objects get the conversions of older
  // documents (the PointActuator / TorqueActuator ones in readModelledForce)
  version_ = documentVersion(doc_);
  if (std::string(root->Name()) == "OpenSimDocument") {
    set = firstChild(root, "ForceSet");
    if (!set) fail(root, "no <ForceSet> in <OpenSimDocument>: a force_set_files file holds a ForceSet");
  } else if (std::string(root->Name()) != "ForceSet") {
    fail(root, "root element is <" + std::string(root->Name()) + ">, expected <ForceSet> or <OpenSimDocument>");
  }
  d_ = model;  // a copy: a file that fails leaves the model as it was
  // the model's frames and coordinate paths, resolved
  auto add = [&](FrameNode::Kind kind, const std::string& name, const std::string& path, const std::string& base,
                 const Mat4& X) {
    FrameNode f;
    f.kind = kind;
    f.name = name;
    f.path = path;
    f.base_body = base;
    f.X_base = X;
    f.state = 2;
    frames_[path] = f;
  };
  add(FrameNode::Kind::Ground, d_.ground_name, "/" + d_.ground_name, d_.ground_name, Mat4::Identity());
  for (const BodyDesc& b : d_.bodies) add(FrameNode::Kind::Body, b.name, "/bodyset/" + b.name, b.name, Mat4::Identity());
  for (const FrameDesc& f : d_.frames) add(FrameNode::Kind::Offset, f.name, f.path, f.base_body, f.X_base);
  for (const CoordinateDesc& c : d_.coordinates) coordinate_paths_["/jointset/" + c.joint + "/" + c.name] = c.name;
  const size_t nf = d_.forces.size(), nm = d_.muscles.size();
  readForceSet(set, doc_.path());
  // OpenSim's ForceSet::append (AbstractTool::updateModelForces) skips a force whose name the set
  // already holds: the model's forces (unless replace_force_set emptied the set) and the earlier
  // files' entries keep their place, the later one is dropped; named here
  std::set<std::string> held;
  for (size_t k = 0; k < nf; ++k)
    if (!model_forces_replaced || !d_.forces[k].source_file.empty()) held.insert(d_.forces[k].name);
  for (size_t k = 0; k < nm; ++k)
    if (!model_forces_replaced || !d_.muscles[k].source_file.empty()) held.insert(d_.muscles[k].name);
  auto dropped = [&](const std::string& name, int line) {
    if (!held.count(name)) {
      held.insert(name);
      return false;
    }
    d_.warnings.push_back(doc_.path() + ":" + std::to_string(line) + ": force '" + name +
                          "' is not appended: the force set already holds a force of that name (OpenSim's "
                          "ForceSet::append keeps the first)");
    return true;
  };
  std::vector<ForceDesc> forces(d_.forces.begin(), d_.forces.begin() + static_cast<std::ptrdiff_t>(nf));
  std::vector<PathForceDesc> muscles(d_.muscles.begin(), d_.muscles.begin() + static_cast<std::ptrdiff_t>(nm));
  for (size_t k = nf; k < d_.forces.size(); ++k)
    if (!dropped(d_.forces[k].name, d_.forces[k].line)) forces.push_back(d_.forces[k]);
  for (size_t k = nm; k < d_.muscles.size(); ++k)
    if (!dropped(d_.muscles[k].name, d_.muscles[k].line)) muscles.push_back(d_.muscles[k]);
  d_.forces = std::move(forces);
  d_.muscles = std::move(muscles);
  model = std::move(d_);
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

namespace redmax::osim {

void appendForceSetFile(ModelDescription& model, const std::string& path, bool model_forces_replaced) {
  detail::OsimReader reader(path);
  reader.appendForceSetTo(model, model_forces_replaced);
}

}  // namespace redmax::osim
