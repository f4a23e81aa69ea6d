#pragma once
// Muscle mass points on a Simbody matter subsystem that somebody else built (OpenSim's), located
// through a body and coordinate map instead of plugin/simbody's SimbodyModel. The kinematics and
// the generalized forces are those of plugin/simbody/muscle_inertia.hpp, which states them in
// full [D Eq. 5.4-5.7]:
//   x_i, xdot_i   station position and velocity of each active path point (Simbody),
//   xddot_i = JS_i udot + JSdot_i u (+ moving-point terms),
//   a_a = J_ax xddot + Jdot_ax xdot (Type III: a_a = J vdot + b),   f_a = m_a (a_a - g),
//   f_u = sum_i JS_i^T (J_ax^T f)_i (+ N^T of the moving-point columns, + JF^T for wrap frames).
// f_u is what inverse dynamics must add to Simbody's residual for the mass points.
//
// Why a second copy of that algorithm: MuscleInertia holds a SimbodyModel (the system it built
// from a core model); here the system is OpenSim's and only its matter subsystem, mobilized-body
// indices and q indices are known. If MuscleInertia ever takes such a map, this file can go.
//
// Frames: path points are stations in the core bodies' frames, which are the OpenSim bodies'
// frames (DESIGN.md §2), so a core body maps to the mobilized body of the OpenSim body of the same
// name.
//
// Simbody comes through plugin/simbody/simbody_include.hpp, whose C++20 fix for index comparisons is
// needed by Debian's Simbody 3.7 and harmless with OpenSim's newer one (its member operator== is the
// better match), so the same source compiles against both: in libredmax_opensim against OpenSim's
// Simbody, and in tests/opensim_matter against Debian's, where it is checked against MuscleInertia.
#include <string>
#include <vector>

#include "plugin/simbody/simbody_include.hpp"

#include "core/muscles/mass_points.hpp"
#include "core/muscles/path_map.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::opensim {

/// Where a core model's bodies and coordinates are in a Simbody system built elsewhere.
struct MatterMap {
  /// per core body (nb): its mobilized body (core body frame = mobilized body frame B)
  std::vector<SimTK::MobilizedBodyIndex> mobod_of_body;
  /// per core coordinate (nr): the Simbody q index holding its value; -1 when it has none (then a
  /// path point may not depend on it)
  std::vector<int> q_of_coordinate;
};

/// Mass points of the muscles of a core model, on a foreign Simbody matter subsystem. Keeps a
/// reference to `matter` (it must outlive this object); copies the muscles. Muscles without mass
/// points are skipped.
class MatterMuscleInertia {
 public:
  /// Validates the muscles against `model` (validateMuscle: throws ModelError) and the map's sizes
  /// (std::invalid_argument); `gravity` (world, m/s^2) acts on the mass points.
  MatterMuscleInertia(const SimTK::SimbodyMatterSubsystem& matter, MatterMap map, const Model& model,
                      std::vector<Muscle> muscles, const Vec3& gravity);

  /// f_u (nu, Simbody u order) of the mass points at `state` (realized to Stage::Velocity) for
  /// generalized accelerations udot (nu). Throws MuscleError for a degenerate path.
  void calcGeneralizedForces(const SimTK::State& state, const SimTK::Vector& udot, SimTK::Vector& f_u);

  /// kinetic energy 1/2 sum m_a |xdot_a|^2 (J) of the mass points at `state` (Stage::Velocity)
  double kineticEnergy(const SimTK::State& state);
  /// mass point positions (world, m) of every muscle with mass, after the last evaluation,
  /// concatenated in muscle order
  std::vector<Vec3> massPointPositions() const;

  /// sum of all mass-point masses (kg)
  double totalMass() const;
  /// the muscles that carry mass points
  int numMassiveMuscles() const { return static_cast<int>(entries_.size()); }

 private:
  struct Entry {
    int muscle = 0;  // index into muscles_
    PathMap map;
    // Type III: the surface (path.wraps[0]) on body `surface_body` (-1: Ground) at E_bs
    bool wrap = false;
    WrapPathMap wmap;
    int surface_body = -1;
    SimTK::Transform X_bs;
    // per active point, refreshed by evaluate()
    std::vector<int> active;  // indices into path.points
    std::vector<Vec3> x, xdot, x_b, dx_b, ddx_b;
  };
  const SimTK::MobilizedBody& mobod(int body) const;
  void evaluate(const SimTK::State& state, bool velocity);
  VecX wrapVelocity(const SimTK::State& state, const Entry& e) const;

  const SimTK::SimbodyMatterSubsystem& matter_;
  MatterMap map_;
  std::vector<Muscle> muscles_;
  std::vector<Entry> entries_;
  Vec3 gravity_;
  VecX q_core_;  // core q read from the state (nr); coordinates without a q stay 0
  SimTK::Array_<SimTK::MobilizedBodyIndex> bodies_;
  SimTK::Array_<SimTK::Vec3> stations_;
  SimTK::Vector_<SimTK::Vec3> JSudot_, bias_, forces_;
  SimTK::Array_<SimTK::MobilizedBodyIndex> frame_bodies_;
  SimTK::Array_<SimTK::Vec3> frame_origins_;
  SimTK::Vector_<SimTK::SpatialVec> JFudot_, frame_bias_, frame_forces_;
};

}  // namespace redmax::opensim
