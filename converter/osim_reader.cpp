// .osim reader: model layout, frames, bodies, joints, coordinates, constraints and markers.
// Wrap objects and forces are in osim_forces.cpp; the multibody tree in multibody_tree.cpp.
// Each legacy upgrade below restates OpenSim's updateFromXMLNode rules (docs/opensim_compatibility.md §1.4).
#include "converter/osim_reader.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "converter/detail/osim_functions.hpp"
#include "converter/detail/osim_reader_impl.hpp"

namespace redmax::osim {

ModelDescription readOsimModel(const std::string& path) { return readOsimModel(path, ""); }

ModelDescription readOsimModel(const std::string& path, const std::string& muscle_class) {
  detail::OsimReader reader(path);
  reader.setMuscleClass(muscle_class);
  return reader.read();
}

namespace detail {
namespace {

constexpr int kOldestVersion = 10901;
constexpr int kLatestVersion = 40600;

// the name a Set component gets: its name attribute, else its lowercased class
std::string setName(const XMLElement* set, const char* cls) {
  if (!set) return toLower(cls);
  const std::string n = attribute(set, "name");
  return n.empty() ? toLower(cls) : n;
}

const XMLElement* setObjects(const XMLElement* set) { return firstChild(set, "objects"); }

std::string lastPathElement(const std::string& p) {
  const auto s = p.rfind('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}

// joint classes OpenSim registers, with the motion type of each mobility ("" = CustomJoint)
struct JointTypeInfo {
  const char* type;
  JointKind kind;
  const char* motions;  // R rotational, T translational; one letter per coordinate
};
const JointTypeInfo kJointTypes[] = {
    {"WeldJoint", JointKind::Weld, ""},
    {"PinJoint", JointKind::Pin, "R"},
    {"SliderJoint", JointKind::Slider, "T"},
    {"BallJoint", JointKind::Ball, "RRR"},
    {"GimbalJoint", JointKind::Gimbal, "RRR"},
    {"UniversalJoint", JointKind::Universal, "RR"},
    {"FreeJoint", JointKind::Free, "RRRTTT"},
    {"PlanarJoint", JointKind::Planar, "RTT"},
    {"EllipsoidJoint", JointKind::Ellipsoid, "RRR"},
    {"ScapulothoracicJoint", JointKind::Scapulothoracic, "RRRR"},
    {"CustomJoint", JointKind::Custom, nullptr},
    // registered by OpenSim but not modelled here
    {"ConstantCurvatureJoint", JointKind::Unsupported, nullptr},
    {"CantileverFreeBeamJoint", JointKind::Unsupported, nullptr},
};

const JointTypeInfo* findJointType(const std::string& type) {
  for (const auto& j : kJointTypes)
    if (type == j.type) return &j;
  return nullptr;
}

const char* kAxisNames[6] = {"rotation1",    "rotation2",    "rotation3",
                             "translation1", "translation2", "translation3"};

}  // namespace

OsimReader::OsimReader(const std::string& path) : doc_(path) { d_.source_file = path; }

const XMLElement* OsimReader::modelChild(const char* tag) const {
  const XMLElement* e = firstChild(model_, tag);
  return e ? e : firstChild(engine_, tag);
}

void OsimReader::addUnsupported(const XMLElement* e, const std::string& what) {
  d_.unsupported.push_back({lineOf(e), what});
}

void OsimReader::warn(const XMLElement* e, const std::string& what) {
  const int line = lineOf(e);
  d_.warnings.push_back((line > 0 ? "line " + std::to_string(line) + ": " : std::string()) + what);
}

std::string OsimReader::componentName(const XMLElement* e, std::set<std::string>& siblings) const {
  std::string name = attribute(e, "name");
  if (version_ < 30500) {
    // 3.3 tolerated white space in names; OpenSim removes it on upgrade
    name.erase(std::remove_if(name.begin(), name.end(),
                              [](unsigned char c) { return std::isspace(c); }),
               name.end());
  }
  if (name.empty()) name = toLower(e->Name());
  std::string unique = name;
  for (int count = 0; siblings.count(unique); ++count) unique = name + "_" + std::to_string(count);
  siblings.insert(unique);
  return unique;
}

std::string OsimReader::socketValue(const XMLElement* e, const std::string& name,
                                    const XMLElement** where) const {
  auto give = [&](const XMLElement* c) {
    if (where) *where = c;
    return textOf(c);
  };
  if (const XMLElement* c = firstChild(e, ("socket_" + name).c_str())) return give(c);
  // 4.0 development formats: <connector_NAME_connectee_name> and <connectors>
  if (const XMLElement* c = firstChild(e, ("connector_" + name + "_connectee_name").c_str()))
    return give(c);
  if (const XMLElement* cs = firstChild(e, "connectors")) {
    for (const XMLElement* c : childElements(cs))
      if (attribute(c, "name") == name)
        if (const XMLElement* n = firstChild(c, "connectee_name")) return give(n);
  }
  if (where) *where = e;
  return {};
}

std::string OsimReader::resolvePath(const std::string& owner, const std::string& path) {
  if (path.empty()) return {};
  std::vector<std::string> parts;
  auto split = [](const std::string& s, std::vector<std::string>& out) -> bool {
    size_t i = 0;
    while (i <= s.size()) {
      const size_t j = std::min(s.find('/', i), s.size());
      const std::string tok = s.substr(i, j - i);
      if (tok == "..") {
        if (out.empty()) return false;
        out.pop_back();
      } else if (!tok.empty() && tok != ".") {
        out.push_back(tok);
      }
      i = j + 1;
    }
    return true;
  };
  if (path[0] != '/' && !split(owner, parts)) return {};
  if (!split(path, parts)) return {};
  std::string out;
  for (const auto& p : parts) out += "/" + p;
  return out.empty() ? "/" : out;
}

FrameNode& OsimReader::frameForSocket(const std::string& owner, const std::string& socket,
                                      const XMLElement* where, const std::string& what) {
  if (socket.empty()) fail(where, what + ": the socket is empty");
  const std::string p = resolvePath(owner, socket);
  auto it = frames_.find(p);
  if (!p.empty() && it == frames_.end() && unsupported_frames_.count(p))
    fail(where, what + ": '" + socket + "' is a StationDefinedFrame, which is not supported");
  if (p.empty() || it == frames_.end())
    fail(where, what + ": '" + socket + "' does not name a frame of the model" +
                    (p.empty() ? std::string(" (the path leaves the model)")
                               : " (looked for " + p + ")"));
  return it->second;
}

std::string OsimReader::legacyBodyPath(const std::string& body) const {
  // XMLDocument::updateConnecteePath30517: ground is /ground, bodies live in /bodyset
  return body == "ground" ? "/ground" : "/bodyset/" + body;
}

std::string OsimReader::frameReference(const XMLElement* e, const std::string& socket,
                                       const char* legacy_tag, const XMLElement** where) const {
  const std::string v = socketValue(e, socket, where);
  if (!v.empty()) return v;
  if (const XMLElement* l = legacy_tag ? firstChild(e, legacy_tag) : nullptr; l && !textOf(l).empty()) {
    if (where) *where = l;
    return legacyBodyPath(textOf(l));
  }
  return {};
}

std::string OsimReader::coordinateReference(const XMLElement* e, const std::string& socket,
                                            const char* legacy_tag,
                                            const XMLElement** where) const {
  const std::string v = socketValue(e, socket, where);
  if (!v.empty()) return v;
  if (const XMLElement* l = legacy_tag ? firstChild(e, legacy_tag) : nullptr) {
    if (where) *where = l;
    return textOf(l);
  }
  return {};
}

std::string OsimReader::coordinateForSocket(const std::string& owner, const std::string& value,
                                            const XMLElement* where) {
  if (value.empty()) return {};
  if (value.find('/') == std::string::npos) {
    // legacy bare coordinate name (pre-4.0 files), looked up model-wide
    for (const auto& c : d_.coordinates)
      if (c.name == value) return value;
    fail(where, "coordinate '" + value + "' does not exist in the model");
  }
  const std::string p = resolvePath(owner, value);
  auto it = coordinate_paths_.find(p);
  if (it == coordinate_paths_.end())
    fail(where, "'" + value + "' does not name a coordinate of the model" +
                    (p.empty() ? std::string() : " (looked for " + p + ")"));
  return it->second;
}

// ---------------------------------------------------------------------------------------------

ModelDescription OsimReader::read() {
  readHeader();
  if (legacy()) {
    readLegacyBodies();
    registerComponents(modelChild("components"), "");
  } else {
    // the Model's own components list precedes ground, BodySet and JointSet in OpenSim's
    // component order (Component's properties are constructed before Model's), so bodies and
    // joints found there come first
    registerComponents(modelChild("components"), "");
    readGroundAndBodies();
    readModernJoints();
  }
  // the 3.x ComponentSet may hold frames
  if (const XMLElement* cs = modelChild("ComponentSet"))
    registerComponents(setObjects(cs), "/" + setName(cs, "ComponentSet"));
  collectConstraintFrames();
  resolveFrames();
  for (const auto& path : frame_order_) {
    const FrameNode& f = frames_.at(path);
    if (f.kind != FrameNode::Kind::Offset) continue;
    FrameDesc fd;
    fd.path = f.path;
    fd.name = f.name;
    fd.parent_path = f.parent_path;
    fd.base_body = f.base_body;
    fd.translation = f.translation;
    fd.orientation = f.orientation;
    fd.X_base = f.X_base;
    fd.line = lineOf(f.elem);
    d_.frames.push_back(fd);
  }
  buildJoints();
  readConstraints();
  readWrapObjects();
  readContactGeometry();
  readForces();
  readMarkers();
  noteIgnoredSets();
  buildMultibodyTree(d_);
  return std::move(d_);
}

void OsimReader::readHeader() {
  const XMLElement* root = doc_.root();
  if (std::string(root->Name()) != "OpenSimDocument") {
    // OpenSim takes any other root as version 10500, which it no longer reads
    fail(root, "root element is <" + std::string(root->Name()) +
                   ">, not <OpenSimDocument Version=\"...\">; OpenSim reads such files as "
                   "version 10500, older than the oldest readable version 10901");
  }
  const char* v = root->Attribute("Version");
  if (!v) fail(root, "<OpenSimDocument> has no Version attribute");
  {
    const std::string s = trim(v);
    char* end = nullptr;
    const long x = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || x < 0 || x > 1000000)
      fail(root, "Version=\"" + std::string(v) + "\" is not a file version number");
    version_ = static_cast<int>(x);
  }
  if (version_ < kOldestVersion)
    fail(root, "file version " + std::to_string(version_) +
                   " is older than 10901, the oldest version OpenSim can read");
  if (version_ > kLatestVersion)
    warn(root, "file version " + std::to_string(version_) + " is newer than " +
                   std::to_string(kLatestVersion) + ", the newest this reader knows");
  d_.osim_version = version_;
  model_ = firstChild(root, "Model");
  if (!model_) fail(root, "no <Model> element in <OpenSimDocument>");
  d_.name = attribute(model_, "name");
  // early 1.x files keep the bodies inside <DynamicsEngine><SimbodyEngine>
  if (!firstChild(model_, "BodySet"))
    if (const XMLElement* de = firstChild(model_, "DynamicsEngine")) {
      engine_ = firstChild(de, "SimbodyEngine");
      if (!engine_)
        fail(de, "<DynamicsEngine> without a <SimbodyEngine> (e.g. SD/FAST models) is not supported");
    }
  const XMLElement* g = firstChild(model_, "gravity") ? model_ : engine_;
  d_.gravity = childVec3(doc_, g, "gravity", Vec3(0.0, -9.80665, 0.0));
}

void OsimReader::registerFrame(FrameNode node) {
  if (frames_.count(node.path)) fail(node.elem, "two components have the path " + node.path);
  frame_order_.push_back(node.path);
  const std::string path = node.path;
  frames_.emplace(path, std::move(node));
}

void OsimReader::registerComponents(const XMLElement* list, const std::string& owner_path) {
  if (!list) return;
  std::set<std::string> names;
  for (const XMLElement* c : childElements(list)) {
    const std::string tag = c->Name();
    const std::string name = componentName(c, names);
    if (tag == "PhysicalOffsetFrame") {
      FrameNode f;
      f.kind = FrameNode::Kind::Offset;
      f.name = name;
      f.path = owner_path + "/" + name;
      f.elem = c;
      f.socket = socketValue(c, "parent", &f.socket_elem);
      f.translation = childVec3(doc_, c, "translation", Vec3::Zero());
      f.orientation = childVec3(doc_, c, "orientation", Vec3::Zero());
      const std::string path = f.path;
      registerFrame(std::move(f));
      registerComponents(firstChild(c, "components"), path);
    } else if (tag == "StationDefinedFrame") {
      unsupported_frames_.insert(owner_path + "/" + name);
      addUnsupported(c, "frame '" + name + "' (StationDefinedFrame) is not modelled");
    } else if (tag == "Body" && !legacy()) {
      readBody(c, name, owner_path + "/" + name);
    } else if (findJointType(tag) && !legacy()) {
      readModernJoint(c, name, owner_path + "/" + name);
    } else {
      addUnsupported(c, "component '" + name + "' (" + tag + ") in a components list is not read");
    }
  }
}

void OsimReader::readGroundAndBodies() {
  // ground
  const XMLElement* ground = modelChild("Ground");
  {
    FrameNode g;
    g.kind = FrameNode::Kind::Ground;
    g.name = ground && !attribute(ground, "name").empty() ? attribute(ground, "name") : "ground";
    g.path = "/" + g.name;
    g.elem = ground ? ground : model_;
    d_.ground_name = g.name;
    registerFrame(g);
    if (ground) registerComponents(firstChild(ground, "components"), "/" + g.name);
  }
  const XMLElement* set = modelChild("BodySet");
  const std::string set_path = "/" + setName(set, "BodySet");
  std::set<std::string> names = {d_.ground_name};
  for (const XMLElement* b : childElements(setObjects(set))) {
    if (std::string(b->Name()) != "Body")
      fail(b, "<" + std::string(b->Name()) + "> in BodySet: only <Body> is a body type");
    const std::string name = componentName(b, names);
    readBody(b, name, set_path + "/" + name);
  }
}

void OsimReader::readBody(const XMLElement* b, const std::string& name, const std::string& path) {
  BodyDesc body;
  body.name = name;
  body.line = lineOf(b);
  if (d_.findBody(name) >= 0 || name == d_.ground_name)
    fail(b, "two bodies are named '" + name + "'; body names must be unique");
  const XMLElement* m = firstChild(b, "mass");
  if (!m || textOf(m).empty()) fail(b, "body '" + body.name + "' has no <mass>");
  body.mass = parseNumbersExactly(doc_, m, 1)[0];
  if (!(body.mass >= 0) || !std::isfinite(body.mass))
    fail(m, "body '" + body.name + "' has an invalid mass " + textOf(m));
  body.mass_center = childVec3(doc_, b, "mass_center", Vec3::Zero());
  if (const XMLElement* in = firstChild(b, "inertia"); in && !textOf(in).empty()) {
    const auto v = parseNumbersExactly(doc_, in, 6);
    for (int i = 0; i < 6; ++i) body.inertia[i] = v[i];
  }
  d_.bodies.push_back(body);
  FrameNode f;
  f.kind = FrameNode::Kind::Body;
  f.name = body.name;
  f.path = path;
  f.elem = b;
  registerFrame(f);
  registerComponents(firstChild(b, "components"), f.path);
}

void OsimReader::readLegacyBodies() {
  const XMLElement* set = modelChild("BodySet");
  if (!set) fail(model_, "no <BodySet> in the model");
  std::set<std::string> body_names, joint_names;
  bool have_ground = false;
  // pass 1: bodies (ground first becomes Ground, §1.4 row <30501)
  struct LegacyJoint {
    const XMLElement* elem;
    std::string child;
  };
  std::vector<LegacyJoint> legacy_joints;
  for (const XMLElement* b : childElements(setObjects(set))) {
    if (std::string(b->Name()) != "Body")
      fail(b, "<" + std::string(b->Name()) + "> in BodySet: only <Body> is a body type");
    std::string name = componentName(b, body_names);
    if (name == "ground" && !have_ground) {
      have_ground = true;
      FrameNode g;
      g.kind = FrameNode::Kind::Ground;
      g.name = "ground";
      g.path = "/ground";
      g.elem = b;
      registerFrame(g);
      continue;
    }
    BodyDesc body;
    body.name = name;
    body.line = lineOf(b);
    const XMLElement* m = firstChild(b, "mass");
    if (!m || textOf(m).empty()) fail(b, "body '" + name + "' has no <mass>");
    body.mass = parseNumbersExactly(doc_, m, 1)[0];
    if (!(body.mass >= 0) || !std::isfinite(body.mass))
      fail(m, "body '" + name + "' has an invalid mass " + textOf(m));
    body.mass_center = childVec3(doc_, b, "mass_center", Vec3::Zero());
    if (version_ < 30500) {
      // six scalars become one <inertia>: a missing diagonal is 1, a missing product 0, and the
      // values pass through a 6-significant-digit stream (Body::updateFromXMLNode)
      static const char* names[6] = {"inertia_xx", "inertia_yy", "inertia_zz",
                                     "inertia_xy", "inertia_xz", "inertia_yz"};
      for (int i = 0; i < 6; ++i) {
        double v = i < 3 ? 1.0 : 0.0;
        if (const XMLElement* c = firstChild(b, names[i]))
          v = textOf(c).empty() ? v : parseNumbersExactly(doc_, c, 1)[0];
        body.inertia[i] = roundLikeOstream(v);
      }
    } else if (const XMLElement* in = firstChild(b, "inertia"); in && !textOf(in).empty()) {
      const auto v = parseNumbersExactly(doc_, in, 6);
      for (int i = 0; i < 6; ++i) body.inertia[i] = v[i];
    }
    d_.bodies.push_back(body);
    FrameNode f;
    f.kind = FrameNode::Kind::Body;
    f.name = name;
    f.path = "/bodyset/" + name;
    f.elem = b;
    registerFrame(f);
    if (const XMLElement* j = firstChild(b, "Joint"))
      if (const XMLElement* concrete = j->FirstChildElement())
        legacy_joints.push_back({concrete, name});
  }
  if (!have_ground) {
    // a model always has ground; a legacy file without a ground body still gets one
    FrameNode g;
    g.kind = FrameNode::Kind::Ground;
    g.name = "ground";
    g.path = "/ground";
    g.elem = model_;
    registerFrame(g);
  }
  // pass 2: joints move out of bodies into a JointSet, in BodySet order (§1.4 row <30501)
  for (const auto& lj : legacy_joints) {
    const XMLElement* e = lj.elem;
    RawJoint rj;
    rj.elem = e;
    rj.desc.type = e->Name();
    rj.desc.line = lineOf(e);
    rj.desc.name = componentName(e, joint_names);
    rj.path = "/jointset/" + rj.desc.name;
    const XMLElement* pb = firstChild(e, "parent_body");
    if (!pb || textOf(pb).empty())
      fail(e, "joint '" + rj.desc.name + "' of body '" + lj.child + "' has no <parent_body>");
    const std::string parent = lastPathElement(textOf(pb));
    if (parent == lj.child) fail(pb, "joint '" + rj.desc.name + "' connects body '" + parent +
                                         "' to itself");
    // location/orientation become two PhysicalOffsetFrames "<body>_offset", written through a
    // 6-digit stream (XMLDocument::addPhysicalOffsetFrame30505_30517, §1.4 rounding trap)
    auto rounded = [&](const char* a, const char* b) {
      const XMLElement* c = firstChild(e, a);
      if (!c && b) c = firstChild(e, b);
      Vec3 v = Vec3::Zero();
      if (c && !textOf(c).empty()) {
        const auto x = parseNumbersExactly(doc_, c, 3);
        v = Vec3(x[0], x[1], x[2]);
      }
      return Vec3(roundLikeOstream(v[0]), roundLikeOstream(v[1]), roundLikeOstream(v[2]));
    };
    FrameNode pf, cf;
    pf.kind = cf.kind = FrameNode::Kind::Offset;
    pf.name = parent + "_offset";
    cf.name = lj.child + "_offset";
    pf.path = rj.path + "/" + pf.name;
    cf.path = rj.path + "/" + cf.name;
    pf.elem = e;
    cf.elem = e;
    pf.socket = legacyBodyPath(parent);
    cf.socket = legacyBodyPath(lj.child);
    pf.socket_elem = pb;
    cf.socket_elem = e;
    pf.translation = rounded("location_in_parent", nullptr);
    pf.orientation = rounded("orientation_in_parent", nullptr);
    cf.translation = rounded("location_in_child", "location");
    cf.orientation = rounded("orientation_in_child", "orientation");
    rj.parent_socket = pf.name;
    rj.child_socket = cf.name;
    rj.parent_socket_elem = pb;
    rj.child_socket_elem = e;
    registerFrame(pf);
    registerFrame(cf);
    // reverse=true swaps the joint's frames (Joint::updateFromXMLNode, <30514)
    if (childBool(doc_, e, "reverse", false)) {
      std::swap(rj.parent_socket, rj.child_socket);
      rj.desc.reversed_in_file = true;
    }
    const XMLElement* cs = firstChild(e, "CoordinateSet");
    rj.coordinate_elems = childElements(setObjects(cs), "Coordinate");
    if (const XMLElement* cl = firstChild(e, "coordinates"))
      for (const XMLElement* c : childElements(cl, "Coordinate")) rj.coordinate_elems.push_back(c);
    raw_joints_.push_back(std::move(rj));
  }
}

void OsimReader::readModernJoints() {
  const XMLElement* set = modelChild("JointSet");
  const std::string set_path = "/" + setName(set, "JointSet");
  std::set<std::string> names;
  for (const XMLElement* e : childElements(setObjects(set))) {
    const std::string name = componentName(e, names);
    readModernJoint(e, name, set_path + "/" + name);
  }
}

void OsimReader::readModernJoint(const XMLElement* e, const std::string& name,
                                 const std::string& path) {
  RawJoint rj;
  rj.elem = e;
  rj.desc.type = e->Name();
  rj.desc.line = lineOf(e);
  rj.desc.name = name;
  rj.path = path;
  for (const auto& other : raw_joints_)
    if (other.desc.name == name) fail(e, "two joints are named '" + name + "'");
  rj.parent_socket = socketValue(e, "parent_frame", &rj.parent_socket_elem);
  rj.child_socket = socketValue(e, "child_frame", &rj.child_socket_elem);
  if (rj.parent_socket.empty())
    fail(rj.parent_socket_elem, "joint '" + rj.desc.name + "' has no parent_frame socket");
  if (rj.child_socket.empty())
    fail(rj.child_socket_elem, "joint '" + rj.desc.name + "' has no child_frame socket");
  if (version_ < 30514 && childBool(doc_, e, "reverse", false)) {
    std::swap(rj.parent_socket, rj.child_socket);
    rj.desc.reversed_in_file = true;
  }
  registerComponents(firstChild(e, "frames"), rj.path);
  if (const XMLElement* cl = firstChild(e, "coordinates"))
    rj.coordinate_elems = childElements(cl, "Coordinate");
  else if (const XMLElement* cs = firstChild(e, "CoordinateSet"))
    rj.coordinate_elems = childElements(setObjects(cs), "Coordinate");
  raw_joints_.push_back(std::move(rj));
}

void OsimReader::collectConstraintFrames() {
  const XMLElement* set = modelChild("ConstraintSet");
  const std::string set_path = "/" + setName(set, "ConstraintSet");
  std::set<std::string> names;
  for (const XMLElement* e : childElements(setObjects(set))) {
    const std::string tag = e->Name();
    const std::string name = componentName(e, names);
    const std::string owner = set_path + "/" + name;
    if (tag != "WeldConstraint") continue;
    if (socketValue(e, "frame1").empty() && firstChild(e, "body_1")) {
      // body_1/body_2 with location/orientation: an offset frame only when not identity
      // (TwoFrameLinker::updateFromXMLNode, values through a 6-digit stream)
      for (int k = 1; k <= 2; ++k) {
        const std::string sk = std::to_string(k);
        const XMLElement* be = firstChild(e, ("body_" + sk).c_str());
        const std::string body = textOf(be);
        const Vec3 loc = childVec3(doc_, e, ("location_body_" + sk).c_str(), Vec3::Zero());
        const Vec3 ori = childVec3(doc_, e, ("orientation_body_" + sk).c_str(), Vec3::Zero());
        if (loc.norm() > 0.0 || ori.norm() > 0.0) {
          FrameNode f;
          f.kind = FrameNode::Kind::Offset;
          f.name = body + "_offset";
          f.path = owner + "/" + f.name;
          if (frames_.count(f.path)) f.path += "_" + sk;
          f.elem = e;
          f.socket = legacyBodyPath(body);
          f.socket_elem = be ? be : e;
          for (int i = 0; i < 3; ++i) {
            f.translation[i] = roundLikeOstream(loc[i]);
            f.orientation[i] = roundLikeOstream(ori[i]);
          }
          registerFrame(f);
        }
      }
    } else {
      registerComponents(firstChild(e, "frames"), owner);
    }
  }
}

void OsimReader::resolveFrames() {
  for (const auto& path : frame_order_) resolveFrame(frames_.at(path));
}

void OsimReader::resolveFrame(FrameNode& f) {
  if (f.state == 2) return;
  if (f.state == 1) fail(f.elem, "offset frame '" + f.path + "' is part of a cycle of frames");
  if (f.kind == FrameNode::Kind::Ground || f.kind == FrameNode::Kind::Body) {
    f.base_body = f.name;
    f.parent_path.clear();
    f.X_base.setIdentity();
    f.state = 2;
    return;
  }
  f.state = 1;
  FrameNode& parent =
      frameForSocket(f.path, f.socket, f.socket_elem ? f.socket_elem : f.elem,
                     "parent of frame '" + f.path + "'");
  resolveFrame(parent);
  f.parent_path = parent.path;
  f.base_body = parent.base_body;
  // an offset composes onto its parent: X_base,f = X_base,parent * X_parent,f [semantics §2]
  f.X_base = parent.X_base * makePose(f.translation, f.orientation);
  f.state = 2;
}

// ---------------------------------------------------------------------------------------------
// joints and coordinates

CoordinateDesc OsimReader::readCoordinate(const XMLElement* e) {
  CoordinateDesc c;
  c.line = lineOf(e);
  c.default_value = childDouble(doc_, e, "default_value", 0.0);
  c.default_speed_value = childDouble(doc_, e, "default_speed_value", 0.0);
  if (const XMLElement* r = firstChild(e, "range"); r && !textOf(r).empty()) {
    const auto v = parseNumbersExactly(doc_, r, 2);
    c.range_min = v[0];
    c.range_max = v[1];
  }
  c.clamped = childBool(doc_, e, "clamped", false);
  c.locked = childBool(doc_, e, "locked", false);
  c.prescribed = childBool(doc_, e, "prescribed", false);
  c.is_free_to_satisfy_constraints = childBool(doc_, e, "is_free_to_satisfy_constraints", false);
  c.prescribed_function = findFunctionProperty(doc_, e, "prescribed_function");
  c.legacy_motion_type = childText(e, "motion_type");
  return c;
}

void OsimReader::buildJoints() {
  for (auto& rj : raw_joints_) buildJoint(rj);
  // coordinate socket paths: <joint path>/<coordinate>; pre-4.0 conversions write /jointset
  for (size_t k = 0; k < raw_joints_.size(); ++k) {
    const auto& j = d_.joints[k];
    for (int ci : j.coordinates) {
      const std::string& cn = d_.coordinates[ci].name;
      coordinate_paths_[raw_joints_[k].path + "/" + cn] = cn;
      coordinate_paths_["/jointset/" + j.name + "/" + cn] = cn;
    }
  }
  // coordinate names are how files (storage columns, couplers, legacy paths) refer to them
  std::set<std::string> seen;
  for (const auto& c : d_.coordinates)
    if (!seen.insert(c.name).second)
      warn(nullptr, "two coordinates are named '" + c.name +
                        "': references by name use the first in file order");
}

void OsimReader::buildJoint(RawJoint& rj) {
  JointDesc& j = rj.desc;
  const JointTypeInfo* info = findJointType(j.type);
  if (!info) fail(rj.elem, "unknown joint type <" + j.type + "> (joint '" + j.name + "')");
  j.kind = info->kind;
  // sockets: through offset frames down to the base bodies (§2)
  const FrameNode& pf =
      frameForSocket(rj.path, rj.parent_socket, rj.parent_socket_elem ? rj.parent_socket_elem : rj.elem,
                     "parent_frame of joint '" + j.name + "'");
  const FrameNode& cf =
      frameForSocket(rj.path, rj.child_socket, rj.child_socket_elem ? rj.child_socket_elem : rj.elem,
                     "child_frame of joint '" + j.name + "'");
  if (pf.base_body == cf.base_body)
    fail(rj.elem, "joint '" + j.name + "': parent and child frames are both fixed to '" +
                      pf.base_body + "'");
  j.parent_frame = pf.path;
  j.child_frame = cf.path;
  j.parent_body = pf.base_body;
  j.child_body = cf.base_body;
  j.X_PF = pf.X_base;
  j.X_BM = cf.X_base;

  // coordinates in file order, names unique within the joint
  std::vector<CoordinateDesc> coords;
  std::set<std::string> cnames;
  for (const XMLElement* ce : rj.coordinate_elems) {
    CoordinateDesc c = readCoordinate(ce);
    c.name = componentName(ce, cnames);
    coords.push_back(c);
  }

  if (j.kind == JointKind::Custom) {
    buildCustomJoint(rj, coords);
  } else if (j.kind == JointKind::Unsupported) {
    addUnsupported(rj.elem, "joint '" + j.name + "' (" + j.type +
                                ") is not modelled; its coordinates are kept as Undefined");
  } else {
    const std::string motions = info->motions;
    const size_t n = motions.size();
    if (coords.empty() && n > 0) {
      // OpenSim keeps the joint's default-constructed coordinates when the file lists none
      for (size_t i = 0; i < n; ++i) {
        CoordinateDesc c;
        c.name = j.name + "_coord_" + std::to_string(i);
        c.line = j.line;
        coords.push_back(c);
      }
      warn(rj.elem, "joint '" + j.name + "' lists no coordinates; defaults " + j.name +
                        "_coord_0.." + std::to_string(n - 1) + " are used");
    }
    if (coords.size() != n)
      fail(rj.elem, j.type + " '" + j.name + "' has " + std::to_string(coords.size()) +
                        " coordinates; a " + j.type + " has " + std::to_string(n));
    for (size_t i = 0; i < n; ++i)
      coords[i].motion_type = motions[i] == 'R' ? MotionType::Rotational : MotionType::Translational;
  }
  if (j.kind == JointKind::Ellipsoid) j.radii = childVec3(doc_, rj.elem, "radii_x_y_z", Vec3::Zero());
  if (j.kind == JointKind::Scapulothoracic) {
    j.radii = childVec3(doc_, rj.elem, "thoracic_ellipsoid_radii_x_y_z", Vec3::Zero());
    if (const XMLElement* o = firstChild(rj.elem, "scapula_winging_axis_origin");
        o && !textOf(o).empty()) {
      const auto v = parseNumbersExactly(doc_, o, 2);
      j.winging_origin = Vec2(v[0], v[1]);
    }
    j.winging_direction = childDouble(doc_, rj.elem, "scapula_winging_axis_direction", 0.0);
  }

  // a clamped coordinate must start inside its range (Coordinate::extendFinalizeFromProperties)
  const double tol = std::sqrt(std::numeric_limits<double>::epsilon());
  for (const auto& c : coords) {
    if (c.clamped && (c.default_value < c.range_min - tol || c.default_value > c.range_max + tol))
      throw ConvertError(doc_.path(), c.line,
                         "coordinate '" + c.name + "' is clamped but its default_value " +
                             std::to_string(c.default_value) + " is outside its range");
    if (c.prescribed_function && c.prescribed_function->kind == FunctionKind::ExpressionBased)
      addUnsupported(nullptr, "coordinate '" + c.name +
                                  "': ExpressionBasedFunction prescribed_function is not evaluated");
  }

  const int joint_index = static_cast<int>(d_.joints.size());
  for (size_t i = 0; i < coords.size(); ++i) {
    coords[i].joint = j.name;
    coords[i].joint_index = joint_index;
    coords[i].mobility = static_cast<int>(i);
    coords[i].declared_index = static_cast<int>(d_.coordinates.size());
    j.coordinates.push_back(static_cast<int>(d_.coordinates.size()));
    d_.coordinates.push_back(coords[i]);
  }
  d_.joints.push_back(j);
}

void OsimReader::buildCustomJoint(RawJoint& rj, std::vector<CoordinateDesc>& coords) {
  JointDesc& j = rj.desc;
  const XMLElement* st = firstChild(rj.elem, "SpatialTransform");
  if (!st) fail(rj.elem, "CustomJoint '" + j.name + "' has no <SpatialTransform>");
  const Vec3 default_axes[6] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(),
                                Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  bool has_function[6] = {false, false, false, false, false, false};
  for (int k = 0; k < 6; ++k) {
    j.spatial_transform[k].name = kAxisNames[k];
    j.spatial_transform[k].axis = default_axes[k];
    j.spatial_transform[k].line = lineOf(st);
  }
  bool seen[6] = {false, false, false, false, false, false};
  for (const XMLElement* ta : childElements(st, "TransformAxis")) {
    const std::string an = attribute(ta, "name");
    int k = -1;
    for (int i = 0; i < 6; ++i)
      if (an == kAxisNames[i]) k = i;
    if (k < 0)
      fail(ta, "TransformAxis name '" + an + "' is not rotation1..3 or translation1..3");
    if (seen[k]) fail(ta, "TransformAxis '" + an + "' appears twice");
    seen[k] = true;
    TransformAxisDesc& ax = j.spatial_transform[k];
    ax.line = lineOf(ta);
    ax.coordinates = splitWords(childText(ta, "coordinates"));
    ax.axis = childVec3(doc_, ta, "axis", default_axes[k]);
    if (!(ax.axis.norm() > 0)) fail(firstChild(ta, "axis"), "TransformAxis '" + an + "' has a zero axis");
    if (auto f = findFunctionProperty(doc_, ta, "function")) {
      ax.function = *f;
      has_function[k] = true;
    }
  }
  // motion type per coordinate, scanning axes 0..5 (CustomJoint::constructCoordinates, §3.4)
  std::vector<std::string> order;  // mobility order: first appearance in rotation1..translation3
  for (int k = 0; k < 6; ++k)
    for (const auto& cn : j.spatial_transform[k].coordinates)
      if (std::find(order.begin(), order.end(), cn) == order.end()) order.push_back(cn);
  std::vector<CoordinateDesc> ordered;
  for (const auto& cn : order) {
    auto it = std::find_if(coords.begin(), coords.end(), [&](auto& c) { return c.name == cn; });
    CoordinateDesc c;
    if (it != coords.end()) {
      c = *it;
    } else {
      // OpenSim constructs a default coordinate for a name only the transform mentions
      c.name = cn;
      c.line = j.line;
      warn(rj.elem, "CustomJoint '" + j.name + "': coordinate '" + cn +
                        "' is used by the SpatialTransform but not listed; defaults are used");
    }
    MotionType mt = MotionType::Undefined;
    for (int k = 0; k < 6; ++k) {
      const auto& ax = j.spatial_transform[k];
      if (std::find(ax.coordinates.begin(), ax.coordinates.end(), cn) == ax.coordinates.end())
        continue;
      if (!has_function[k]) continue;
      if (ax.function.isUnitSlopeLinear())
        mt = k < 3 ? MotionType::Rotational : MotionType::Translational;  // last such axis wins
      else if (mt == MotionType::Undefined)
        mt = MotionType::Coupled;
    }
    c.motion_type = mt;
    ordered.push_back(c);
  }
  for (const auto& c : coords)
    if (std::find(order.begin(), order.end(), c.name) == order.end())
      fail(rj.elem, "CustomJoint '" + j.name + "': coordinate '" + c.name +
                        "' is not used by any TransformAxis");
  coords = ordered;
  // default functions: one coordinate -> LinearFunction(1, 0); none -> Constant(0) (§3.3)
  for (int k = 0; k < 6; ++k) {
    auto& ax = j.spatial_transform[k];
    if (!has_function[k]) {
      if (ax.coordinates.size() > 1)
        fail(st, "CustomJoint '" + j.name + "' " + ax.name +
                     " has several coordinates but no function");
      FunctionDesc f;
      if (ax.coordinates.size() == 1) {
        f.kind = FunctionKind::Linear;
        f.type = f.written_type = "LinearFunction";
        f.coefficients = {1.0, 0.0};
      } else {
        f.written_type = "Constant";
      }
      f.line = ax.line;
      ax.function = f;
    }
    const int nargs = ax.function.numArguments();
    const int ncoord = static_cast<int>(ax.coordinates.size());
    if (nargs != 0 && nargs != ncoord)
      throw ConvertError(doc_.path(), ax.function.line ? ax.function.line : ax.line,
                         "CustomJoint '" + j.name + "' " + ax.name + ": the " +
                             ax.function.type + " takes " + std::to_string(nargs) +
                             " arguments but " + std::to_string(ncoord) +
                             " coordinates are listed");
    ax.mobilities.clear();
    for (const auto& cn : ax.coordinates)
      ax.mobilities.push_back(static_cast<int>(
          std::find(order.begin(), order.end(), cn) - order.begin()));
    if (ax.function.kind == FunctionKind::ExpressionBased)
      addUnsupported(nullptr, "CustomJoint '" + j.name + "' " + ax.name +
                                  ": ExpressionBasedFunction is not evaluated");
  }
  // axes must be independent (CustomJoint::extendFinalizeFromProperties, raw axes, tol 1e-5)
  for (int s = 0; s <= 3; s += 3) {
    const Vec3& a0 = j.spatial_transform[s].axis;
    const Vec3& a1 = j.spatial_transform[s + 1].axis;
    const Vec3& a2 = j.spatial_transform[s + 2].axis;
    if (a0.cross(a1).norm() < 1e-5 || a0.cross(a2).norm() < 1e-5 || a1.cross(a2).norm() < 1e-5)
      throw ConvertError(doc_.path(), lineOf(st),
                         "CustomJoint '" + j.name + "' has collinear " +
                             (s == 0 ? "rotation" : "translation") + " axes");
  }
}

// ---------------------------------------------------------------------------------------------
// constraints

void OsimReader::readConstraints() {
  const XMLElement* set = modelChild("ConstraintSet");
  const std::string set_path = "/" + setName(set, "ConstraintSet");
  std::set<std::string> names;
  for (const XMLElement* e : childElements(setObjects(set))) {
    ConstraintDesc c;
    c.type = e->Name();
    c.name = componentName(e, names);
    c.line = lineOf(e);
    const std::string owner = set_path + "/" + c.name;
    if (const XMLElement* d = firstChild(e, "isDisabled"); d && version_ < 30509)
      c.enforced = !parseBool(doc_, d);
    c.enforced = childBool(doc_, e, "isEnforced", c.enforced);
    if (c.type == "CoordinateCouplerConstraint") {
      c.kind = ConstraintKind::CoordinateCoupler;
      c.function = findFunctionProperty(doc_, e, "coupled_coordinates_function");
      if (!c.function) fail(e, "CoordinateCouplerConstraint '" + c.name + "' has no coupled_coordinates_function");
      c.independent_coordinates = splitWords(childText(e, "independent_coordinate_names"));
      c.dependent_coordinate = childText(e, "dependent_coordinate_name");
      c.scale_factor = childDouble(doc_, e, "scale_factor", 1.0);
      for (const auto& n : c.independent_coordinates)
        if (d_.findCoordinate(n) < 0)
          fail(firstChild(e, "independent_coordinate_names"),
               "CoordinateCouplerConstraint '" + c.name + "': coordinate '" + n + "' does not exist");
      if (c.independent_coordinates.empty())
        fail(e, "CoordinateCouplerConstraint '" + c.name + "' has no independent coordinates");
      if (d_.findCoordinate(c.dependent_coordinate) < 0)
        fail(firstChild(e, "dependent_coordinate_name") ? firstChild(e, "dependent_coordinate_name") : e,
             "CoordinateCouplerConstraint '" + c.name + "': dependent coordinate '" +
                 c.dependent_coordinate + "' does not exist");
      const int nargs = c.function->numArguments();
      if (nargs != 0 && nargs != static_cast<int>(c.independent_coordinates.size()))
        throw ConvertError(doc_.path(), c.function->line,
                           "CoordinateCouplerConstraint '" + c.name + "': the function takes " +
                               std::to_string(nargs) + " arguments but " +
                               std::to_string(c.independent_coordinates.size()) +
                               " independent coordinates are listed");
      if (c.function->kind == FunctionKind::ExpressionBased)
        addUnsupported(e, "CoordinateCouplerConstraint '" + c.name +
                              "': ExpressionBasedFunction is not evaluated");
    } else if (c.type == "WeldConstraint") {
      c.kind = ConstraintKind::Weld;
      std::string s1, s2;
      const XMLElement *w1 = nullptr, *w2 = nullptr;
      if (socketValue(e, "frame1").empty() && firstChild(e, "body_1")) {
        for (int k = 1; k <= 2; ++k) {
          const std::string sk = std::to_string(k);
          const XMLElement* be = firstChild(e, ("body_" + sk).c_str());
          const std::string body = textOf(be);
          if (body.empty()) fail(be ? be : e, "WeldConstraint '" + c.name + "' has no body_" + sk);
          const Vec3 loc = childVec3(doc_, e, ("location_body_" + sk).c_str(), Vec3::Zero());
          const Vec3 ori = childVec3(doc_, e, ("orientation_body_" + sk).c_str(), Vec3::Zero());
          std::string path = legacyBodyPath(body);
          if (loc.norm() > 0.0 || ori.norm() > 0.0) {
            path = owner + "/" + body + "_offset";
            if (k == 2 && s1 == path) path += "_2";
          }
          (k == 1 ? s1 : s2) = path;
          (k == 1 ? w1 : w2) = be;
        }
      } else {
        s1 = socketValue(e, "frame1", &w1);
        s2 = socketValue(e, "frame2", &w2);
      }
      const FrameNode& f1 = frameForSocket(owner, s1, w1, "frame1 of WeldConstraint '" + c.name + "'");
      const FrameNode& f2 = frameForSocket(owner, s2, w2, "frame2 of WeldConstraint '" + c.name + "'");
      c.frame1 = f1.path;
      c.frame2 = f2.path;
      c.body1 = f1.base_body;
      c.body2 = f2.base_body;
      c.X_B1F1 = f1.X_base;
      c.X_B2F2 = f2.X_base;
    } else if (c.type == "PointConstraint") {
      c.kind = ConstraintKind::Point;
      std::string s1, s2;
      const XMLElement *w1 = nullptr, *w2 = nullptr;
      s1 = frameReference(e, "body_1", "body_1", &w1);
      s2 = frameReference(e, "body_2", "body_2", &w2);
      const FrameNode& f1 = frameForSocket(owner, s1, w1, "body_1 of PointConstraint '" + c.name + "'");
      const FrameNode& f2 = frameForSocket(owner, s2, w2, "body_2 of PointConstraint '" + c.name + "'");
      c.frame1 = f1.path;
      c.frame2 = f2.path;
      c.body1 = f1.base_body;
      c.body2 = f2.base_body;
      // stations are given in the socket frames; store them in the base bodies
      const Vec3 p1 = childVec3(doc_, e, "location_body_1", Vec3::Zero());
      const Vec3 p2 = childVec3(doc_, e, "location_body_2", Vec3::Zero());
      c.location1 = (f1.X_base * p1.homogeneous()).head<3>();
      c.location2 = (f2.X_base * p2.homogeneous()).head<3>();
    } else {
      c.kind = ConstraintKind::Unsupported;
      addUnsupported(e, "constraint '" + c.name + "' (" + c.type + ") is not modelled");
    }
    d_.constraints.push_back(std::move(c));
  }
}

// ---------------------------------------------------------------------------------------------
// markers and sets that are read only to be reported

void OsimReader::readMarkers() {
  const XMLElement* set = modelChild("MarkerSet");
  const std::string set_path = "/" + setName(set, "MarkerSet");
  std::set<std::string> names;
  for (const XMLElement* e : childElements(setObjects(set))) {
    MarkerDesc m;
    m.name = componentName(e, names);
    m.line = lineOf(e);
    const std::string owner = set_path + "/" + m.name;
    std::string socket;
    const XMLElement* where = nullptr;
    socket = frameReference(e, "parent_frame", "body", &where);
    const FrameNode& f = frameForSocket(owner, socket, where ? where : e,
                                        "parent_frame of marker '" + m.name + "'");
    m.frame = f.path;
    m.body = f.base_body;
    m.X_body_frame = f.X_base;
    m.location = childVec3(doc_, e, "location", Vec3::Zero());
    d_.markers.push_back(m);
  }
}

void OsimReader::noteIgnoredSets() {
  struct SetInfo {
    const char* tag;
    const char* why;
  };
  const SetInfo sets[] = {
      {"ProbeSet", "probes are not evaluated"},
      {"ControllerSet", "controllers are not run (excitations are zero)"},
  };
  for (const auto& s : sets) {
    const XMLElement* set = modelChild(s.tag);
    for (const XMLElement* e : childElements(setObjects(set)))
      addUnsupported(e, std::string(e->Name()) + " '" + attribute(e, "name") + "' in " + s.tag +
                            ": " + s.why);
  }
}

}  // namespace detail
}  // namespace redmax::osim
