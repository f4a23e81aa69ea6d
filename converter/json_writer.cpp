#include "converter/json_writer.hpp"

#include <algorithm>

#include "core/muscles/hill/factory.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace redmax::osim {

// ---------------------------------------------------------------------------------------------
// writer

std::string JsonWriter::escape(const std::string& s) {
  std::string o = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\b': o += "\\b"; break;
      case '\f': o += "\\f"; break;
      case '\n': o += "\\n"; break;
      case '\r': o += "\\r"; break;
      case '\t': o += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          o += buf;
        } else {
          o += static_cast<char>(c);  // UTF-8 passes through unchanged
        }
    }
  }
  return o + "\"";
}

void JsonWriter::newline() {
  out_ += "\n";
  out_.append(2 * stack_.size(), ' ');
}

void JsonWriter::beforeValue() {
  if (done_) throw std::logic_error("JsonWriter: value after the document ended");
  if (stack_.empty()) return;
  Level& l = stack_.back();
  if (l.object) {
    if (!l.key_pending) throw std::logic_error("JsonWriter: value without a key in an object");
    l.key_pending = false;
  } else {
    if (l.count++ > 0) out_ += ",";
    newline();
  }
}

JsonWriter& JsonWriter::key(const std::string& k) {
  if (stack_.empty() || !stack_.back().object || stack_.back().key_pending)
    throw std::logic_error("JsonWriter: key outside an object");
  Level& l = stack_.back();
  if (l.count++ > 0) out_ += ",";
  newline();
  out_ += escape(k) + ": ";
  l.key_pending = true;
  return *this;
}

JsonWriter& JsonWriter::beginObject() {
  beforeValue();
  out_ += "{";
  stack_.push_back({true, 0, false});
  return *this;
}

JsonWriter& JsonWriter::beginArray() {
  beforeValue();
  out_ += "[";
  stack_.push_back({false, 0, false});
  return *this;
}

JsonWriter& JsonWriter::endObject() {
  if (stack_.empty() || !stack_.back().object || stack_.back().key_pending)
    throw std::logic_error("JsonWriter: unbalanced endObject");
  const bool empty = stack_.back().count == 0;
  stack_.pop_back();
  if (!empty) newline();
  out_ += "}";
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::endArray() {
  if (stack_.empty() || stack_.back().object) throw std::logic_error("JsonWriter: unbalanced endArray");
  const bool empty = stack_.back().count == 0;
  stack_.pop_back();
  if (!empty) newline();
  out_ += "]";
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::value(const std::string& s) {
  beforeValue();
  out_ += escape(s);
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::value(double x) {
  beforeValue();
  if (!std::isfinite(x)) {
    out_ += "null";
  } else {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", x);
    out_ += buf;
  }
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::value(int x) {
  beforeValue();
  out_ += std::to_string(x);
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::value(bool b) {
  beforeValue();
  out_ += b ? "true" : "false";
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::null() {
  beforeValue();
  out_ += "null";
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::numbers(const double* x, int n) {
  beginArray();
  for (int i = 0; i < n; ++i) value(x[i]);
  return endArray();
}

JsonWriter& JsonWriter::compactNumbers(const double* x, int n, int digits) {
  beforeValue();
  out_ += "[";
  char buf[40];
  for (int i = 0; i < n; ++i) {
    if (std::isfinite(x[i]))
      std::snprintf(buf, sizeof buf, "%s%.*g", i ? "," : "", digits, x[i]);
    else
      std::snprintf(buf, sizeof buf, "%snull", i ? "," : "");
    out_ += buf;
  }
  out_ += "]";
  if (stack_.empty()) done_ = true;
  return *this;
}

JsonWriter& JsonWriter::compactIntegers(const int* x, int n) {
  beforeValue();
  out_ += "[";
  for (int i = 0; i < n; ++i) out_ += (i ? "," : "") + std::to_string(x[i]);
  out_ += "]";
  if (stack_.empty()) done_ = true;
  return *this;
}

const std::string& JsonWriter::str() const {
  if (!stack_.empty()) throw std::logic_error("JsonWriter: unclosed containers");
  return out_;
}

// ---------------------------------------------------------------------------------------------
// description

namespace {

void writeFunction(JsonWriter& w, const FunctionDesc& f) {
  w.beginObject().key("type").value(f.type);
  if (f.written_type != f.type && !f.written_type.empty()) w.key("written_type").value(f.written_type);
  switch (f.kind) {
    case FunctionKind::Constant: w.key("value").value(f.value); break;
    case FunctionKind::Linear:
    case FunctionKind::Polynomial:
      w.key("coefficients").numbers(f.coefficients.data(), static_cast<int>(f.coefficients.size()));
      break;
    case FunctionKind::GCVSpline:
      w.key("half_order").value(f.half_order).key("error_variance").value(f.error_variance);
      [[fallthrough]];
    case FunctionKind::SimmSpline:
    case FunctionKind::PiecewiseLinear:
    case FunctionKind::PiecewiseConstant:
      w.key("x").numbers(f.x.data(), static_cast<int>(f.x.size()));
      w.key("y").numbers(f.y.data(), static_cast<int>(f.y.size()));
      break;
    case FunctionKind::Multiplier:
      w.key("scale").value(f.scale).key("function");
      writeFunction(w, f.inner.at(0));
      break;
    case FunctionKind::Sine:
      w.key("amplitude").value(f.amplitude).key("omega").value(f.omega);
      w.key("phase").value(f.phase).key("offset").value(f.offset);
      break;
    case FunctionKind::Step:
      w.key("transition_start_time").value(f.start_time).key("transition_end_time").value(f.end_time);
      w.key("start_value").value(f.start_value).key("end_value").value(f.end_value);
      break;
    case FunctionKind::MultivariatePolynomial:
      w.key("dimension").value(f.dimension).key("order").value(f.order);
      w.key("coefficients").numbers(f.coefficients.data(), static_cast<int>(f.coefficients.size()));
      break;
    case FunctionKind::ExpressionBased: w.key("expression").value(f.expression); break;
  }
  w.endObject();
}

void writePose(JsonWriter& w, const Mat4& X) {
  // row-major 4x4
  w.beginArray();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) w.value(X(r, c));
  w.endArray();
}

const char* kindName(PathPointKind k) {
  switch (k) {
    case PathPointKind::Fixed: return "PathPoint";
    case PathPointKind::Conditional: return "ConditionalPathPoint";
    case PathPointKind::Moving: break;
  }
  return "MovingPathPoint";
}

std::string unsupportedText(const UnsupportedItem& u) {
  return (u.line > 0 ? "line " + std::to_string(u.line) + ": " : std::string()) + u.what;
}

}  // namespace

std::string describeAsJson(const ModelDescription& d) {
  JsonWriter w;
  w.beginObject();
  w.key("name").value(d.name);
  w.key("osim_version").value(d.osim_version);
  w.key("source_file").value(d.source_file);
  w.key("gravity").numbers(d.gravity.data(), 3);
  w.key("ground").value(d.ground_name);
  w.key("dof").value(d.numDofs());

  w.key("bodies").beginArray();
  for (const auto& b : d.bodies) {
    w.beginObject().key("name").value(b.name).key("mass").value(b.mass);
    w.key("mass_center").numbers(b.mass_center.data(), 3);
    w.key("inertia").numbers(b.inertia.data(), 6);
    w.endObject();
  }
  w.endArray();

  // mobilizer direction by joint
  std::vector<int> reversed(d.joints.size(), -1);
  for (const auto& m : d.tree.mobilizers)
    if (m.joint >= 0) reversed[m.joint] = m.reversed ? 1 : 0;
  w.key("joints").beginArray();
  for (size_t i = 0; i < d.joints.size(); ++i) {
    const auto& j = d.joints[i];
    w.beginObject().key("name").value(j.name).key("type").value(j.type);
    w.key("parent").value(j.parent_body).key("child").value(j.child_body);
    w.key("parent_frame").value(j.parent_frame).key("child_frame").value(j.child_frame);
    w.key("X_PF");
    writePose(w, j.X_PF);
    w.key("X_BM");
    writePose(w, j.X_BM);
    w.key("coordinates").beginArray();
    for (int c : j.coordinates) w.value(d.coordinates[c].name);
    w.endArray();
    w.key("reversed_in_tree").value(reversed[i] == 1);
    if (reversed[i] < 0) w.key("loop_closing").value(true);
    if (j.added) w.key("added").value(true);
    if (j.reversed_in_file) w.key("reversed_in_file").value(true);
    if (j.kind == JointKind::Custom) {
      w.key("spatial_transform").beginArray();
      for (const auto& ax : j.spatial_transform) {
        w.beginObject().key("name").value(ax.name);
        w.key("coordinates").beginArray();
        for (const auto& c : ax.coordinates) w.value(c);
        w.endArray();
        w.key("axis").numbers(ax.axis.data(), 3);
        w.key("function");
        writeFunction(w, ax.function);
        w.endObject();
      }
      w.endArray();
    }
    if (j.kind == JointKind::Ellipsoid || j.kind == JointKind::Scapulothoracic)
      w.key("radii").numbers(j.radii.data(), 3);
    if (j.kind == JointKind::Scapulothoracic) {
      w.key("winging_origin").numbers(j.winging_origin.data(), 2);
      w.key("winging_direction").value(j.winging_direction);
    }
    w.endObject();
  }
  w.endArray();

  w.key("coordinates").beginArray();
  for (const auto& c : d.coordinates) {
    w.beginObject().key("name").value(c.name).key("motion_type").value(toString(c.motion_type));
    w.key("locked").value(c.locked).key("joint").value(c.joint).key("mobility").value(c.mobility);
    w.key("default_value").value(c.default_value);
    w.key("default_speed_value").value(c.default_speed_value);
    const double r[2] = {c.range_min, c.range_max};
    w.key("range").numbers(r, 2);
    w.key("clamped").value(c.clamped).key("prescribed").value(c.prescribed);
    if (c.prescribed_function) {
      w.key("prescribed_function");
      writeFunction(w, *c.prescribed_function);
    }
    w.endObject();
  }
  w.endArray();

  w.key("constraints").beginArray();
  for (const auto& c : d.constraints) {
    w.beginObject().key("name").value(c.name).key("type").value(c.type);
    w.key("enforced").value(c.enforced);
    if (!c.generated_by.empty()) w.key("generated_by").value(c.generated_by);
    if (c.kind == ConstraintKind::CoordinateCoupler) {
      w.key("independent_coordinates").beginArray();
      for (const auto& n : c.independent_coordinates) w.value(n);
      w.endArray();
      w.key("dependent_coordinate").value(c.dependent_coordinate);
      w.key("scale_factor").value(c.scale_factor);
      w.key("function");
      writeFunction(w, *c.function);
    } else if (c.kind == ConstraintKind::Weld) {
      w.key("body1").value(c.body1).key("body2").value(c.body2);
      w.key("X_B1F1");
      writePose(w, c.X_B1F1);
      w.key("X_B2F2");
      writePose(w, c.X_B2F2);
    } else if (c.kind == ConstraintKind::Point) {
      w.key("body1").value(c.body1).key("body2").value(c.body2);
      w.key("location1").numbers(c.location1.data(), 3);
      w.key("location2").numbers(c.location2.data(), 3);
    }
    w.endObject();
  }
  w.endArray();

  w.key("muscles").beginArray();
  for (const auto& m : d.muscles) {
    int cond = 0, moving = 0;
    for (const auto& p : m.points) {
      cond += p.kind == PathPointKind::Conditional;
      moving += p.kind == PathPointKind::Moving;
    }
    w.beginObject().key("name").value(m.name).key("class").value(m.class_name);
    w.key("path_type").value(toString(m.path_type));
    w.key("path_points").value(static_cast<int>(m.points.size()));
    w.key("wraps").value(static_cast<int>(m.wraps.size()));
    w.key("conditional_points").value(cond).key("moving_points").value(moving);
    w.key("is_muscle").value(m.is_muscle).key("applies_force").value(m.applies_force);
    if (m.is_muscle) {
      w.key("max_isometric_force").value(m.max_isometric_force);
      w.key("optimal_fiber_length").value(m.optimal_fiber_length);
      w.key("tendon_slack_length").value(m.tendon_slack_length);
      w.key("pennation_angle_at_optimal").value(m.pennation_angle_at_optimal);
      // the force model: its class and every parameter it computes with (OpenSim's defaults for
      // the absent ones); a class redmax does not model lists the properties as read
      const auto& known = hill::muscleModelClasses();
      const bool modelled = std::find(known.begin(), known.end(), m.class_name) != known.end();
      hill::ParameterList params;
      std::vector<std::string> states;
      if (modelled) {
        const auto model = hill::makeMuscleModel(m.class_name, m.parameters);  // validated on reading
        params = model->parameterList();
        states = model->stateNames();
      } else {
        params.assign(m.parameters.values.begin(), m.parameters.values.end());
      }
      if (modelled)
        w.key("force_model").value(m.class_name);
      else
        w.key("force_model").null();
      w.key("states").beginArray();
      for (const auto& sn : states) w.value("/forceset/" + m.name + "/" + sn);
      w.endArray();
      w.key("parameters").beginObject();
      for (const auto& [k, v] : params) w.key(k).value(v);
      w.endObject();
    }
    w.key("points").beginArray();
    for (const auto& p : m.points) {
      w.beginObject().key("name").value(p.name).key("type").value(kindName(p.kind));
      w.key("body").value(p.body);
      if (p.kind != PathPointKind::Moving) w.key("location").numbers(p.location.data(), 3);
      if (p.kind == PathPointKind::Conditional) {
        const double r[2] = {p.range_min, p.range_max};
        w.key("coordinate").value(p.coordinate).key("range").numbers(r, 2);
      }
      if (p.kind == PathPointKind::Moving) {
        w.key("coordinates").beginArray();
        for (const auto& c : p.location_coordinates) w.value(c);
        w.endArray();
      }
      w.endObject();
    }
    w.endArray();
    w.key("wrap_objects").beginArray();
    for (const auto& pw : m.wraps) w.value(pw.wrap_object);
    w.endArray();
    w.endObject();
  }
  w.endArray();

  w.key("forces").beginArray();
  for (const auto& f : d.forces) {
    w.beginObject().key("name").value(f.name).key("class").value(f.class_name);
    w.key("applies_force").value(f.applies_force);
    if (!f.coordinate.empty()) w.key("coordinate").value(f.coordinate);
    w.endObject();
  }
  w.endArray();

  w.key("wrap_objects").beginArray();
  for (const auto& o : d.wrap_objects) {
    w.beginObject().key("name").value(o.name).key("type").value(o.type).key("body").value(o.body);
    w.key("active").value(o.active).key("quadrant").value(o.quadrant);
    w.endObject();
  }
  w.endArray();

  w.key("markers").beginArray();
  for (const auto& m : d.markers) {
    w.beginObject().key("name").value(m.name).key("body").value(m.body);
    w.key("location").numbers(m.location.data(), 3);
    w.endObject();
  }
  w.endArray();

  w.key("tree").beginArray();
  for (const auto& m : d.tree.mobilizers) {
    w.beginObject().key("joint").value(d.joints[m.joint].name);
    w.key("inboard").value(m.inboard_body).key("outboard").value(m.outboard_body);
    w.key("reversed").value(m.reversed).key("level").value(m.level);
    w.endObject();
  }
  w.endArray();

  w.key("unsupported").beginArray();
  for (const auto& u : d.unsupported) w.value(unsupportedText(u));
  w.endArray();
  w.key("warnings").beginArray();
  for (const auto& s : d.warnings) w.value(s);
  w.endArray();
  w.endObject();
  return w.str() + "\n";
}

std::string formatSummary(const ModelDescription& d) {
  std::string o;
  char buf[256];
  std::snprintf(buf, sizeof buf, "model '%s' (%s, file version %d)\n", d.name.c_str(),
                d.source_file.c_str(), d.osim_version);
  o += buf;
  double mass = 0.0;
  int massless = 0;
  for (const auto& b : d.bodies) mass += b.mass, massless += b.mass == 0.0;
  std::snprintf(buf, sizeof buf, "  bodies       %zu (total mass %.6g kg%s)\n", d.bodies.size(), mass,
                massless ? (", " + std::to_string(massless) + " massless").c_str() : "");
  o += buf;
  int locked = 0;
  std::map<std::string, int> by_motion;
  for (const auto& c : d.coordinates) locked += c.locked, by_motion[toString(c.motion_type)]++;
  std::snprintf(buf, sizeof buf, "  DoF          %d (%d locked)", d.numDofs(), locked);
  o += buf;
  std::string sep = ": ";
  for (const auto& [k, n] : by_motion) o += sep + std::to_string(n) + " " + k, sep = ", ";
  o += "\n";
  std::map<std::string, int> by_type;
  for (const auto& j : d.joints) by_type[j.type + (j.added ? " (added)" : "")]++;
  o += "  joints       " + std::to_string(d.joints.size());
  sep = ": ";
  for (const auto& [k, n] : by_type) o += sep + std::to_string(n) + " " + k, sep = ", ";
  o += "\n";
  int reversed = 0;
  for (const auto& m : d.tree.mobilizers) reversed += m.reversed;
  std::snprintf(buf, sizeof buf, "  tree         %zu mobilizers, %d reversed, %zu slave bodies\n",
                d.tree.mobilizers.size(), reversed, d.tree.slaves.size());
  o += buf;
  int types[3] = {0, 0, 0}, muscles = 0, cond = 0, moving = 0, wraps = 0, with_model = 0;
  std::map<std::string, int> by_class;
  for (const auto& m : d.muscles) {
    types[static_cast<int>(m.path_type)]++;
    muscles += m.is_muscle;
    const auto& known = hill::muscleModelClasses();
    with_model += m.is_muscle && std::find(known.begin(), known.end(), m.class_name) != known.end();
    by_class[m.class_name]++;
    wraps += static_cast<int>(m.wraps.size());
    for (const auto& p : m.points) {
      cond += p.kind == PathPointKind::Conditional;
      moving += p.kind == PathPointKind::Moving;
    }
  }
  std::snprintf(buf, sizeof buf,
                "  muscles      %zu path forces (%d muscles): Type I %d, Type II %d, Type III %d\n",
                d.muscles.size(), muscles, types[0], types[1], types[2]);
  o += buf;
  if (!by_class.empty()) {
    o += "               ";
    sep = "";
    for (const auto& [k, n] : by_class) o += sep + std::to_string(n) + " " + k, sep = ", ";
    o += "\n";
    std::snprintf(buf, sizeof buf, "               force models for %d of %d muscles (core/muscles/hill)\n",
                  with_model, muscles);
    o += buf;
  }
  std::snprintf(buf, sizeof buf,
                "  paths        %d conditional points, %d moving points, %d wraps on %zu wrap "
                "objects\n",
                cond, moving, wraps, d.wrap_objects.size());
  o += buf;
  std::map<std::string, int> by_con;
  for (const auto& c : d.constraints) by_con[c.type + (c.generated_by.empty() ? "" : " (loop)")]++;
  o += "  constraints  " + std::to_string(d.constraints.size());
  sep = ": ";
  for (const auto& [k, n] : by_con) o += sep + std::to_string(n) + " " + k, sep = ", ";
  o += "\n";
  o += "  other forces " + std::to_string(d.forces.size()) + ", markers " +
       std::to_string(d.markers.size()) + "\n";
  o += "  unsupported  " + std::to_string(d.unsupported.size()) + "\n";
  for (const auto& u : d.unsupported) o += "    " + unsupportedText(u) + "\n";
  if (!d.warnings.empty()) {
    o += "  warnings     " + std::to_string(d.warnings.size()) + "\n";
    for (const auto& s : d.warnings) o += "    " + s + "\n";
  }
  return o;
}

}  // namespace redmax::osim
