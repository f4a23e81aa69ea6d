#pragma once
// The .osim reader's internal state, shared by osim_reader.cpp (model, frames, joints,
// constraints, markers) and osim_forces.cpp (wrap objects, forces and their paths).
#include <map>
#include <set>
#include <string>
#include <vector>

#include "converter/detail/xml_util.hpp"
#include "converter/model_description.hpp"

namespace redmax::osim::detail {

/// a physical frame of the component tree: ground, a body, or an offset frame
struct FrameNode {
  enum class Kind { Ground, Body, Offset };
  Kind kind = Kind::Offset;
  std::string name, path;
  std::string socket;  ///< Offset: parent socket as written (relative to path) or absolute
  const XMLElement* socket_elem = nullptr;
  Vec3 translation = Vec3::Zero(), orientation = Vec3::Zero();
  const XMLElement* elem = nullptr;
  // filled by resolution
  int state = 0;  ///< 0 unresolved, 1 resolving (cycle check), 2 done
  std::string parent_path, base_body;
  Mat4 X_base = Mat4::Identity();
};

/// a joint as read, before its sockets are resolved
struct RawJoint {
  JointDesc desc;
  const XMLElement* elem = nullptr;
  std::string path;  ///< /jointset/<name>: owner for relative socket paths
  std::string parent_socket, child_socket;
  const XMLElement* parent_socket_elem = nullptr;
  const XMLElement* child_socket_elem = nullptr;
  std::vector<const XMLElement*> coordinate_elems;  ///< file order
};

class OsimReader {
 public:
  explicit OsimReader(const std::string& path);
  ModelDescription read();
  /// append the ForceSet of this reader's file (a force_set_files file) to `model`'s forces
  void appendForceSetTo(ModelDescription& model, bool model_forces_replaced);
  /// read every muscle as this class (renameType); "" = as written
  void setMuscleClass(std::string cls) { muscle_class_ = std::move(cls); }

  // ---- shared helpers ----
  const XmlDocument& doc() const { return doc_; }
  [[noreturn]] void fail(const XMLElement* e, const std::string& what) const { doc_.fail(e, what); }
  void addUnsupported(const XMLElement* e, const std::string& what);
  void warn(const XMLElement* e, const std::string& what);
  bool legacy() const { return version_ < 30501; }
  /// OpenSim gives nameless components their lowercased class name and renames duplicates
  /// among siblings name_0, name_1, ... ; pre-3.5 names lose their white space
  std::string componentName(const XMLElement* e, std::set<std::string>& siblings) const;
  /// value of a socket of e (socket_<name>, or the 3.x/dev connector forms); "" if absent
  std::string socketValue(const XMLElement* e, const std::string& name,
                          const XMLElement** where = nullptr) const;
  /// resolve a component path relative to owner ('..' and '.' handled); "" if it leaves root
  static std::string resolvePath(const std::string& owner, const std::string& path);
  /// the frame a socket names (resolved from owner); fails with the socket's line if none
  FrameNode& frameForSocket(const std::string& owner, const std::string& socket,
                            const XMLElement* where, const std::string& what);
  /// legacy body name -> frame path ("/ground" or "/bodyset/<name>"), OpenSim 3.x rule
  std::string legacyBodyPath(const std::string& body) const;
  /// a frame reference: the socket if written (OpenSim reads properties by tag whatever the
  /// file version), else the pre-4.0 body-name element as a body path; "" if neither
  std::string frameReference(const XMLElement* e, const std::string& socket,
                             const char* legacy_tag, const XMLElement** where) const;
  /// a coordinate reference: the socket if written, else the pre-4.0 element (a bare name)
  std::string coordinateReference(const XMLElement* e, const std::string& socket,
                                  const char* legacy_tag, const XMLElement** where) const;
  /// coordinate by socket path (modern) or bare name (legacy); "" if empty; fails if unknown
  std::string coordinateForSocket(const std::string& owner, const std::string& value,
                                  const XMLElement* where);

 private:
  // model.cpp
  /// a child of <Model>, or of the 1.x <SimbodyEngine> that held the model's sets
  const XMLElement* modelChild(const char* tag) const;
  void readHeader();
  void readGroundAndBodies();
  void readBody(const XMLElement* b, const std::string& name, const std::string& path);
  void readModernJoint(const XMLElement* e, const std::string& name, const std::string& path);
  void readLegacyBodies();
  void readModernJoints();
  void registerFrame(FrameNode node);
  void registerComponents(const XMLElement* list, const std::string& owner_path);
  void collectConstraintFrames();
  void resolveFrames();
  void resolveFrame(FrameNode& f);
  void buildJoints();
  void buildJoint(RawJoint& rj);
  void buildCustomJoint(RawJoint& rj, std::vector<CoordinateDesc>& coords);
  CoordinateDesc readCoordinate(const XMLElement* e);
  void readConstraints();
  void readMarkers();
  void noteIgnoredSets();
  // forces.cpp
  void readWrapObjects();
  void readWrapObjectSet(const XMLElement* set, const FrameNode& frame);
  void readForces();
  /// ContactGeometrySet: spheres and half-spaces modelled, the rest listed (docs/contact.md)
  void readContactGeometry();
  void readContactForce(const XMLElement* e, ForceDesc& f);
  /// the forces of a ForceSet element (the model's, or a force_set_files file's: source)
  void readForceSet(const XMLElement* set, const std::string& source);
  void readModelledForce(const XMLElement* e, ForceDesc& f);
  void readBushing(const XMLElement* e, ForceDesc& f);
  const FrameNode& forceFrame(const XMLElement* e, const std::string& value, const std::string& what);
  void readPathForce(const XMLElement* e, const std::string& name, const std::string& cls,
                     bool is_muscle, bool applies);
  void readMuscleParameters(const XMLElement* e, PathForceDesc& m);
  PathPointDesc readPathPoint(const XMLElement* e, const std::string& owner,
                              std::set<std::string>& names);

  XmlDocument doc_;
  ModelDescription d_;
  int version_ = 0;
  std::string muscle_class_;
  const XMLElement* model_ = nullptr;
  const XMLElement* engine_ = nullptr;  ///< 1.x <DynamicsEngine><SimbodyEngine>, if any
  std::set<std::string> unsupported_frames_;  ///< paths of frames we cannot place
  std::map<std::string, FrameNode> frames_;  ///< by absolute path
  std::vector<std::string> frame_order_;     ///< registration (component-list) order
  std::vector<RawJoint> raw_joints_;
  std::map<std::string, std::string> coordinate_paths_;  ///< /jointset/J/C -> coordinate name
};

}  // namespace redmax::osim::detail
