#pragma once
// The immutable skeleton model (docs/design.md §4): bodies, the joint tree, the
// reduced coordinates q_r and their index ranges. Built with ModelBuilder; algorithms in
// core/skeleton/kinematics.hpp and core/dynamics/ read it and write a Workspace.
//
// Frames (core/spatial/notation.md): w world, i body, p parent body, F joint frame on the parent
// (OpenSim's parent offset frame), M joint frame on the child. The pose of body i is
//   E_wi = E_wp * E_pf * Q(q_i) * E_mi,      E_mi = inverse of the child offset frame (X_BM^-1)
// Body i and joint i come in pairs [D Sec. 4.1]; parents always precede children.
#include <stdexcept>
#include <string>
#include <vector>

#include "core/joints/joint.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

/// Rigid-body mass properties in the body frame (the OpenSim body frame; origin need not be the COM).
struct Body {
  std::string name;
  double mass = 0.0;
  Vec3 com = Vec3::Zero();                // centre of mass, body frame
  Mat3 inertia_com = Mat3::Zero();        // inertia tensor about the COM, body axes
  Mat6 M = Mat6::Zero();                  // spatial inertia about the body origin (derived)
};

/// The joint that connects body `body` to its parent.
struct JointSlot {
  std::string name;
  int parent = -1;                 // parent body index, -1 = world
  int body = -1;                   // child body index (== slot index)
  Mat4 E_pf = Mat4::Identity();    // joint frame F in the parent body frame (constant)
  Mat4 E_mi = Mat4::Identity();    // child body frame in joint frame M (constant)
  Joint joint;
  int q_index = 0;                 // first reduced coordinate of this joint
  int nq = 0;                      // number of reduced coordinates
};

/// One reduced coordinate (one column of J_mr).
struct Coordinate {
  std::string name;
  int joint = -1;                  // owning joint slot
  double default_value = 0.0;
  double stiffness = 0.0;          // joint spring K  [D Eq. 4.75]
  double rest_value = 0.0;         // spring rest position
  double damping = 0.0;            // joint damping D [D Eq. 4.77]
};

/// Immutable after ModelBuilder::finalize(): every edit (a body's mass properties, a joint
/// spring, gravity) goes through a ModelBuilder, which re-derives everything that depends on it
/// (Body::M, the coordinate indices, the ancestor lists). Copyable.
class Model {
 public:
  const std::string& name() const { return name_; }
  const Vec3& gravity() const { return gravity_; }                       // world frame
  const std::vector<Body>& bodies() const { return bodies_; }            // (nb)
  const std::vector<JointSlot>& joints() const { return joints_; }       // (nb), joints()[i].body == i
  const std::vector<Coordinate>& coordinates() const { return coordinates_; }  // (nr)

  int nb() const { return static_cast<int>(bodies_.size()); }
  int nr() const { return nr_; }
  int nm() const { return 6 * nb(); }

  /// joints whose coordinates move body i: its own and all its ancestors', root first (Alg. 1 fill)
  const std::vector<int>& ancestors(int i) const { return ancestors_[i]; }
  /// true if joint a is body i's joint or an ancestor's
  bool isAncestor(int a, int i) const;

  int findBody(const std::string& name) const;        // -1 if absent
  int findCoordinate(const std::string& name) const;  // -1 if absent

  /// default configuration and zero velocity
  VecX defaultQ() const;

 private:
  friend class ModelBuilder;
  std::string name_;
  Vec3 gravity_ = Vec3(0.0, -9.80665, 0.0);
  std::vector<Body> bodies_;
  std::vector<JointSlot> joints_;
  std::vector<Coordinate> coordinates_;
  int nr_ = 0;
  std::vector<std::vector<int>> ancestors_;
};

/// Builds a Model. Bodies are added with the joint that attaches them to an existing body (or
/// the world), so the tree is ordered parents-first by construction. A builder made from an
/// existing Model edits a copy of it (the tree stays; mass properties, springs, names, gravity
/// may change); finalize() then re-derives everything, so no caller recomputes Body::M.
class ModelBuilder {
 public:
  explicit ModelBuilder(std::string name = "model");
  /// start from a finalized model (its bodies, joints and coordinates, in its order)
  explicit ModelBuilder(const Model& model);

  void setName(std::string name);
  void setGravity(const Vec3& g);

  /// Add a body attached to `parent` (-1 = world) by `joint`. E_pf: joint frame in the parent
  /// body; E_bm: joint frame in the child body (OpenSim's child offset frame). Returns the body index.
  int addBody(const std::string& body_name, double mass, const Vec3& com, const Mat3& inertia_com,
              int parent, const std::string& joint_name, Joint joint,
              const Mat4& E_pf = Mat4::Identity(), const Mat4& E_bm = Mat4::Identity());

  /// replace body i's mass, centre of mass (body frame) and inertia about the centre of mass
  /// (body axes); the spatial inertia is derived by finalize()
  void setBodyMassProperties(int i, double mass, const Vec3& com, const Mat3& inertia_com);

  int nb() const { return m_.nb(); }
  int nr() const { return m_.nr_; }
  /// the bodies as built so far (mass properties as last set; Body::M not derived yet)
  const std::vector<Body>& bodies() const { return m_.bodies_; }

  /// name the reduced coordinates of a joint (defaults: <joint>_<k>)
  void setCoordinateNames(int body, const std::vector<std::string>& names);
  /// coordinate k of body `body`'s joint: default value, spring and damper may be edited
  Coordinate& coordinate(int body, int k);
  /// reduced coordinate q_index (0 <= q_index < nr), for the same edits
  Coordinate& coordinateAt(int q_index);

  /// validate and derive (spatial inertias, coordinate indices, ancestor lists)
  Model finalize() const;

 private:
  Model m_;
};

/// Error in model construction or in user input that reaches the core.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace redmax
