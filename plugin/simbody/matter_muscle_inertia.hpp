#pragma once
// Muscle inertia on any Simbody matter subsystem: the generalized forces of muscle mass points,
// with the path-point kinematics taken from Simbody itself and the mass points from the path maps
// shared with the core (core/muscles/path_map.hpp) [D Eq. 5.4-5.7]:
//   x_i, xdot_i          station position and velocity of each active path point (Simbody),
//   xddot_i = JS_i udot + JSdot_i u (+ moving-point terms)   (station Jacobian and its bias),
//   a_a  = J_ax xddot + Jdot_ax xdot,   f_a = m_a (a_a - g),
//   f_u  = sum_i JS_i^T (J_ax^T f)_i   (+ N^T of the moving-point columns).
// f_u is what the mass points add to Simbody's residual M udot + c - f_applied, i.e. the
// generalized force, in Simbody's u space, that inverse dynamics must supply for them.
//
// The system is located through a MatterMap (core body -> mobilized body, core coordinate -> q
// index), so the one implementation serves plugin/simbody's own systems (MuscleInertia builds the
// map from its SimbodyModel) and OpenSim's (plugin/opensim builds it from the OpenSim model).
// Frames: path points are stations in the core bodies' frames, which are the mobilized bodies'
// frames B (docs/design.md §2).
//
// Path points: conditional points only change the active set (isPathPointActive on q). A moving
// point x_b(q_c) in body b adds through its coordinate c velocity R x_b' qdot_c and acceleration
// 2 w x (R x_b' qdot_c) + R (x_b'' qdot_c^2 + x_b' qddot_c), and a generalized force (R x_b')^T F
// on qdot_c, mapped to u by N^T (qdot = N u). Points on the world (body -1) are stations on Ground.
//
// Type III (any path the core takes: via, conditional and moving points, wraps on different
// segments; core/muscles/wrap_muscle.hpp): each wrap object's surface frame s is a frame on its
// body (X_GS = X_GB E_bs), whose spatial velocity (omega, pdot) and acceleration come from
// Simbody's frame Jacobian and its bias; the path map is calcGeneralPathMap
// (core/muscles/path_map.hpp: the core's segment construction and wrap model), v = (xdot, (omega_w,
// pdot_w) per wrap), a_a = J vdot + b, and each wrap's (omega, pdot) part of J^T f_a is a spatial
// force (torque, force at the surface origin) that JF^T takes to u [D Eq. 5.45-5.57]. The exact
// wrap model on paths other than origin -> one surface -> insertion is OpenSim's whole path, its J
// and bias differences in v (path_map.hpp), so it agrees with the core (differences in q) to
// the differences' error (docs/simbody.md).
//
// Simbody comes through plugin/simbody/simbody_include.hpp, whose C++20 fix for index comparisons
// is needed by Debian's Simbody 3.7 and harmless with OpenSim's newer one (its member operator== is
// the better match), so this source compiles against both: in redmax_simbody against Debian's and
// in libredmax_opensim (plugin/opensim/CMakeLists.txt) against OpenSim's. Keep it free of
// SimbodyModel and of anything else that is compiled only against Debian's Simbody.
#include <string>
#include <vector>

#include "plugin/simbody/simbody_include.hpp"

#include "core/muscles/mass_points.hpp"
#include "core/muscles/path_map.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::simbody {

/// "" when a muscle with mass points can be carried by the Simbody side, else why not: every path
/// the core takes, with mass points at fixed arc fractions (not fibre-following placement), and no
/// deformable node points.
std::string simbodyWrapShapeUnsupportedReason(const Muscle& muscle);

/// Where a core model's bodies and coordinates are in a Simbody system.
struct MatterMap {
  /// per core body (nb): its mobilized body (core body frame = mobilized body frame B)
  std::vector<SimTK::MobilizedBodyIndex> mobod_of_body;
  /// per core coordinate (nr): the Simbody q index holding its value; -1 when it has none (then a
  /// path point may not depend on it)
  std::vector<int> q_of_coordinate;
};

/// Mass points of the muscles of a core model on a Simbody matter subsystem. Keeps a reference to
/// `matter` (it must outlive this object); copies the muscles. Muscles without mass points are
/// skipped.
class MatterMuscleInertia {
 public:
  /// Validates the muscles against `model` (validateMuscle: throws ModelError; an unsupported
  /// wrapping shape too) and the map (std::invalid_argument: sizes, a body or coordinate a path
  /// needs and the system lacks); `gravity` (world, m/s^2) acts on the mass points.
  MatterMuscleInertia(const SimTK::SimbodyMatterSubsystem& matter, MatterMap map, const Model& model,
                      std::vector<Muscle> muscles, const Vec3& gravity);

  /// f_u (nu, Simbody u order) of the mass points at `state` (realized to Stage::Velocity) for
  /// generalized accelerations udot (nu). Throws MuscleError for a degenerate path.
  void calcGeneralizedForces(const SimTK::State& state, const SimTK::Vector& udot, SimTK::Vector& f_u);

  /// kinetic energy 1/2 sum m_a |xdot_a|^2 (J) of the mass points at `state` (Stage::Velocity)
  double kineticEnergy(const SimTK::State& state);
  /// positions x_a (world, m) and velocities xdot_a = J v (m/s) of every mass point at `state`
  /// (Stage::Velocity), concatenated in muscle order (muscles with mass points only)
  void calcMassPointMotion(const SimTK::State& state, std::vector<Vec3>& x, std::vector<Vec3>& xdot);
  /// gravitational potential -sum m_a g . x_a (J, world origin) at `state` (Stage::Position)
  double potentialEnergy(const SimTK::State& state);
  /// mass point positions (world, m) of every muscle with mass, after the last evaluation,
  /// concatenated in muscle order
  std::vector<Vec3> massPointPositions() const;
  /// mass point positions (world, m) of the e-th muscle with mass after the last evaluation
  const std::vector<Vec3>& massPointPositions(int e) const;

  /// sum of all mass-point masses (kg)
  double totalMass() const;
  /// the muscles that carry mass points
  int numMassiveMuscles() const { return static_cast<int>(entries_.size()); }
  const std::vector<Muscle>& muscles() const { return muscles_; }

 private:
  struct Entry {
    int muscle = 0;  // index into muscles_
    GeneralPathMap gmap;  // the path map, every type (Types I and II: no frames)
    // Type III: per wrap object (path.wraps), its body (-1: Ground), its frame X_bs on it and the
    // frame's pose and velocity refreshed by evaluate()
    std::vector<int> surface_body;
    std::vector<SimTK::Transform> X_bs;
    std::vector<SurfaceFrameState> frames;
    // per active point, refreshed by evaluate()
    std::vector<int> active;  // indices into path.points
    std::vector<Vec3> x, xdot, x_b, dx_b, ddx_b;
  };
  const SimTK::MobilizedBody& mobod(int body) const;
  // active points, positions and velocities (and the path maps) of every entry
  void evaluate(const SimTK::State& state, bool velocity);

  const SimTK::SimbodyMatterSubsystem& matter_;
  MatterMap map_;
  std::vector<Muscle> muscles_;
  std::vector<Entry> entries_;
  Vec3 gravity_;
  VecX q_core_;  // core q read from the state (nr); coordinates without a q stay 0
  // batch buffers for Simbody's station and frame operators
  SimTK::Array_<SimTK::MobilizedBodyIndex> bodies_;
  SimTK::Array_<SimTK::Vec3> stations_;
  SimTK::Vector_<SimTK::Vec3> JSudot_, bias_, forces_;
  SimTK::Array_<SimTK::MobilizedBodyIndex> frame_bodies_;  // one frame per wrap object of a Type III entry
  SimTK::Array_<SimTK::Vec3> frame_origins_;
  SimTK::Vector_<SimTK::SpatialVec> JFudot_, frame_bias_, frame_forces_;
};

}  // namespace redmax::simbody
