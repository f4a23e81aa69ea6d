#pragma once
// The engine interface of inverse dynamics at one instant. The OpenSim inverse-dynamics tool
// (converter/id/inverse_dynamics_tool.hpp) does OpenSim's input processing once (coordinates,
// splines, external loads) and hands every output frame to an engine: the core
// (converter/id/core_id_engine.hpp) or Simbody (plugin/simbody/id_engine.hpp). Both get exactly
// the same numbers, so differences between their torques are the engines' alone.
//
// Velocity convention. Every core joint has qdot = dq/dt. OpenSim's ID puts the coordinate
// splines' first and second derivatives into Simbody's u and udot for every mobility, and for
// Ball, Free, Ellipsoid (and the ellipsoid part of Scapulothoracic) joints Simbody reads those
// Euler-angle rates as the angular velocity of M in F, expressed in F (OPENSIM_SEMANTICS.md 3.2,
// 7 step 7). IdEngineOptions::rates_as_u marks such joints: for them the engine receives u
// and udot (the data's rates, taken as OpenSim takes them) and returns the generalized force
// conjugate to u, as OpenSim writes it. Unmarked joints get (qdot, qddot) and return the force
// conjugate to qdot. The map between the two is core/dynamics/speed_map.hpp.
//
// Header-only: plugin/simbody implements the interface and links core only.
#include <stdexcept>
#include <string>
#include <vector>

#include "core/dynamics/body_loads.hpp"
#include "core/skeleton/model.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

/// One external load at one instant, as an OpenSim ExternalForce gives it (§7 step 8).
/// Bodies are core body indices; -1 is ground.
struct IdLoadSample {
  int body = -1;         ///< the body the load is applied to (never ground)
  int force_frame = -1;  ///< frame the force and the torque are expressed in
  int point_frame = -1;  ///< frame the point is expressed in
  bool has_force = false, has_point = false, has_torque = false;
  Vec3 force = Vec3::Zero();   ///< in force_frame
  Vec3 point = Vec3::Zero();   ///< in point_frame; the body origin when !has_point
  Vec3 torque = Vec3::Zero();  ///< in force_frame
};

/// Loads in the form ExternalLoads takes them, for body poses E_wi (world <- body, nb):
/// F_w = R_w,fexp F; the point is re-expressed in the applied body with the current poses and the
/// force acts at that station; the torque T_w = R_w,fexp T is a pure torque (OpenSim's
/// ExternalForce::computeForce). Loads on ground are skipped.
inline void resolveLoads(const std::vector<IdLoadSample>& loads, const std::vector<Mat4>& E_wi,
                         std::vector<PointForce>& point_forces, std::vector<BodyWrench>& wrenches) {
  point_forces.clear();
  wrenches.clear();
  auto rotation = [&](int frame) -> Mat3 {
    return frame < 0 ? Mat3(Mat3::Identity()) : Mat3(E_wi[frame].topLeftCorner<3, 3>());
  };
  for (const IdLoadSample& l : loads) {
    if (l.body < 0) continue;
    const Mat3 R_wf = rotation(l.force_frame);
    if (l.has_force) {
      Vec3 x_i = Vec3::Zero();
      if (l.has_point) {
        // point frame -> world -> applied body, with the current poses
        const Vec3 x_w = l.point_frame < 0 ? l.point : transformPoint(E_wi[l.point_frame], l.point);
        x_i = transformPoint(inverseE(E_wi[l.body]), x_w);
      }
      point_forces.push_back({l.body, x_i, R_wf * l.force});
    }
    if (l.has_torque) wrenches.push_back({l.body, R_wf * l.torque, Vec3::Zero()});
  }
}
inline void resolveLoads(const std::vector<IdLoadSample>& loads, const std::vector<Mat4>& E_wi, ExternalLoads& out) {
  resolveLoads(loads, E_wi, out.point_forces, out.wrenches);
}

/// How an engine treats the speeds it is given.
struct IdEngineOptions {
  /// per core joint slot (nb, or empty = none): the joint's speeds are OpenSim's u, i.e. the
  /// data's Euler-angle rates read as angular velocity of M in F, expressed in F (and, for a free
  /// joint, the translation rates as the velocity of M's origin in F); the joint's generalized
  /// forces are returned conjugate to that u. Only Ball-, Free- and Ellipsoid-like joints
  /// (SphericalEuler XYZ, Free3D::opensim(), Ellipsoid, a Composite starting with an Ellipsoid,
  /// or one of these Reversed) may be marked.
  std::vector<bool> rates_as_u;
  bool marked(int joint) const {
    return joint >= 0 && joint < static_cast<int>(rates_as_u.size()) && rates_as_u[joint];
  }
};

/// Inverse dynamics at one instant, ignoring constraints:
///   tau = M(q) vdot + c(q, v) - (gravity + external loads + joint springs and dampers)
/// in the velocity convention above.
class IdEngine {
 public:
  virtual ~IdEngine() = default;
  /// "core" or "simbody"
  virtual std::string name() const = 0;
  /// q, v, vdot and tau have the model's nr entries (core coordinate order = OpenSim's q order);
  /// loads as produced by the tool for time t. Throws std::runtime_error (e.g. a velocity map
  /// that is singular at q: gimbal lock) when the frame cannot be solved.
  virtual void calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                                     const std::vector<IdLoadSample>& loads, VecX& tau) = 0;
};

/// A frame the engine could not solve (exit code 1 at the command line).
class IdEngineError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace redmax
