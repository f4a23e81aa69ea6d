#pragma once
// Muscle inertia in a Simbody system: the generalized forces of muscle mass points for a Simbody
// system built from a core model (model_to_simbody.hpp), with the path-point kinematics taken from
// Simbody itself and the mass points from the path maps shared with the core
// (core/muscles/path_map.hpp) [D Eq. 5.4-5.7]:
//   x_i, xdot_i          station position and velocity of each active path point (Simbody),
//   xddot_i = JS_i udot + JSdot_i u (+ moving-point terms)   (station Jacobian and its bias),
//   a_a  = J_ax xddot + Jdot_ax xdot,   f_a = m_a (a_a - g),
//   f_u  = sum_i JS_i^T (J_ax^T f)_i   (+ N^T of the moving-point columns).
// f_u is what the mass points add to Simbody's residual M udot + c - f_applied, i.e. the
// generalized force, in Simbody's u space, that inverse dynamics must supply for them.
//
// Path points: conditional points only change the active set (isPathPointActive on q). A moving
// point x_b(q_c) in body b adds through its coordinate c (core q index = Simbody q index, Euler
// angles) velocity R x_b' qdot_c and acceleration 2 w x (R x_b' qdot_c) + R (x_b'' qdot_c^2 +
// x_b' qddot_c), and a generalized force (R x_b')^T F on qdot_c, mapped to u by N^T (qdot = N u).
// Points on the world (body -1) are stations on Ground.
//
// Type III (origin, one wrap surface, insertion; core/muscles/wrap_muscle.hpp's shape): the
// surface frame s is a frame on its body (X_GS = X_GB E_bs), whose spatial velocity (omega, pdot)
// and acceleration come from Simbody's frame Jacobian and its bias; the path map is
// calcWrapPathMap (core/muscles/path_map.hpp: the core's wrap model), v = (xdot1, xdot2, omega,
// pdot), a_a = J vdot + b, and the (omega, pdot) part of J^T f_a is a spatial force (torque, force
// at the surface origin) that JF^T takes to u [D Eq. 5.45-5.57].
//
// Only TUs that need Simbody include this header (plugin/simbody/simbody_include.hpp).
#include <string>
#include <vector>

#include "plugin/simbody/model_to_simbody.hpp"

#include "core/muscles/mass_points.hpp"
#include "core/muscles/path_map.hpp"

namespace redmax::simbody {

/// "" when a muscle with mass points can be carried by the Simbody side, else why not: Type III
/// only as origin -> one wrap surface -> insertion with fixed or moving ends (the path map of
/// calcWrapPathMap); other wrapping shapes the core may take are refused.
std::string simbodyWrapShapeUnsupportedReason(const Muscle& muscle);

/// Muscle mass points of a Simbody system. Keeps references to `sm` (it must outlive this object);
/// copies the model's muscles. Muscles without mass points are skipped.
class MuscleInertia {
 public:
  /// Validates the muscles against `model` (validateMuscle: throws ModelError); `gravity` (world,
  /// m/s^2) acts on the mass points, by default the model's.
  MuscleInertia(const SimbodyModel& sm, const Model& model, std::vector<Muscle> muscles);
  MuscleInertia(const SimbodyModel& sm, const Model& model, std::vector<Muscle> muscles, const Vec3& gravity);

  /// f_u (nu, Simbody u order) of the mass points at `state` (realized to Stage::Velocity at
  /// least) for generalized accelerations udot (nu). Throws MuscleError for a degenerate path.
  void calcGeneralizedForces(const SimTK::State& state, const SimTK::Vector& udot, SimTK::Vector& f_u);
  VecX calcGeneralizedForces(const SimTK::State& state, const VecX& udot);

  /// kinetic energy 1/2 sum m_a |xdot_a|^2 (J) and gravitational potential -sum m_a g . x_a (J,
  /// world origin) of the mass points at `state` (Stage::Velocity)
  double kineticEnergy(const SimTK::State& state);
  double potentialEnergy(const SimTK::State& state);

  /// mass point positions (world) of muscle m (index into muscles()) after the last evaluation
  const std::vector<Vec3>& massPointPositions(int m) const {
    const Entry& e = entries_.at(m);
    return e.wrap ? e.wmap.x_a : e.map.x_a;
  }
  const std::vector<Muscle>& muscles() const { return muscles_; }
  /// sum of all mass-point masses (kg)
  double totalMass() const;

 private:
  struct Entry {
    int muscle = 0;                        // index into muscles_
    PathMap map;
    // Type III: the surface (path.wraps[0]) on body `surface_body` (-1: Ground) at E_bs
    bool wrap = false;
    WrapPathMap wmap;
    int surface_body = -1;
    SimTK::Transform X_bs;
    // per active point, refreshed by evaluate()
    std::vector<int> active;               // indices into path.points
    std::vector<Vec3> x, xdot, x_b, dx_b, ddx_b;
  };
  // active points, positions and velocities (and the path maps) of every entry
  void evaluate(const SimTK::State& state, bool velocity);
  // v = (xdot1, xdot2, omega, pdot) of a Type III entry after evaluate(state, true)
  VecX wrapVelocity(const SimTK::State& state, const Entry& e) const;

  const SimbodyModel& sm_;
  std::vector<Muscle> muscles_;
  std::vector<Entry> entries_;             // the muscles with mass points
  std::vector<int> simbody_q_of_;          // core coordinate -> Simbody q index         (nr)
  Vec3 gravity_;
  VecX q_core_;                            // core q read from the state                 (nr)
  // batch buffers for Simbody's station operators
  SimTK::Array_<SimTK::MobilizedBodyIndex> bodies_;
  SimTK::Array_<SimTK::Vec3> stations_;
  SimTK::Vector_<SimTK::Vec3> JSudot_, bias_, forces_;
  SimTK::Array_<SimTK::MobilizedBodyIndex> frame_bodies_;  // one frame per Type III entry
  SimTK::Array_<SimTK::Vec3> frame_origins_;
  SimTK::Vector_<SimTK::SpatialVec> JFudot_, frame_bias_, frame_forces_;
};

}  // namespace redmax::simbody
