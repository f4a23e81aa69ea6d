#pragma once
// Forward dynamics of muscle inertia in Simbody: every mass point a becomes a particle (a
// MobilizedBody::Translation from Ground carrying a point mass m_a), and each muscle gets one
// holonomic Constraint::Custom with 3N equations that keeps its particles at their path positions:
//   perr   = x_p - x_a(x)                       (x: the active path points, Simbody stations)
//   pverr  = v_p - J_ax xdot                    [D Eq. 5.4]
//   paerr  = a_p - (J_ax xddot + Jdot_ax xdot)  [D Eq. 5.5]
// with the path maps of core/muscles/path_map.hpp; the constraint forces are G^T lambda: lambda_a on
// particle a and -(J_ax^T lambda)_i at path point i. Eliminating the particles recovers the core's
// M += m_a J_ar^T J_ar, f += J_ar^T m_a (g - Jdot_ar qdot) [D Eq. 5.6-5.7], so the trajectories agree
// (Simbody's gravity force acts on the particles as on any body).
//
// A moving point x_b(q_c) makes its coordinate's mobilizer a constrained mobilizer: its position,
// velocity and acceleration gain the terms of muscle_inertia.hpp, its force a q-force (R x_b')^T F.
// Type III (any path the core takes: via and moving points, wraps on different segments;
// core/muscles/wrap_muscle.hpp): each wrap object's body is a constrained body too; x_a comes from
// calcGeneralPathMap (path_map.hpp: the core's segment construction and wrap model, smooth by
// default) on the path points and the surface frames' poses, pverr uses J v with v = (xdot,
// (omega_w, pdot_w) per wrap), paerr J vdot + b, and each surface's share of G^T lambda is a torque
// and a force at its origin. With the smooth model the path map is C2 within a segment choice, so
// the constraint is smooth across contact changes; the exact model's finite-difference J jumps
// there (on any path: the whole OpenSim path differentiated in v, path_map.hpp), so a run with the
// exact model is only meant to stay on one side of every contact change.
// Conditional points: a point's switch changes the path, so the mass points' positions and
// velocities jump where the core's (functions of q and qdot) do. Particles cannot follow a jump
// continuously; each end of a conditional point's range is a Simbody event (a witness q_c - bound),
// and at the event the active sets are taken again and every particle is put on its new path with
// the skeleton's q and u unchanged (the core's q and qdot are continuous there). Between events
// each constraint keeps its active set, so it stays smooth while Simbody localizes a crossing.
// Limits: a mass point without mass. Muscles without mass points are skipped.
#include <memory>
#include <vector>

#include "plugin/simbody/matter_muscle_inertia.hpp"
#include "plugin/simbody/model_to_simbody.hpp"

#include "core/muscles/mass_points.hpp"

namespace redmax::simbody {

namespace detail {
/// The particles' placement (ParticleMuscles::placeParticles), owned jointly by the ParticleMuscles
/// and the system's conditional-point event handlers.
struct ParticlePlacer {
  const SimbodyModel* sm = nullptr;
  std::vector<Muscle> muscles;                          // every muscle, in order
  std::vector<int> massive;                             // per path constraint: its muscle
  std::vector<std::shared_ptr<std::vector<int>>> active;  // per path constraint: its active points
  std::vector<SimTK::MobilizedBody> particles;          // muscles in order, their mass points in order
  std::unique_ptr<MatterMuscleInertia> motion;          // the mass points' motion on the skeleton
  mutable VecX q_core;                                  // scratch: the core q of a state
  /// take the active sets at sb's q and put the particles on their paths (header)
  void place(SimTK::State& sb) const;
};
}  // namespace detail

/// Adds the particles and constraints to `sm` (before any state other than its default is made):
/// realizes the topology again and replaces sm.default_state (Euler angles kept on). The particles'
/// q and u come after the skeleton's in Simbody's vectors; sm.nq and sm.nu keep the skeleton's counts.
class ParticleMuscles {
 public:
  /// Throws ModelError for a muscle that does not fit `model` (validateMuscle), SimbodyBuildError for
  /// a massless mass point.
  ParticleMuscles(SimbodyModel& sm, const Model& model, std::vector<Muscle> muscles);

  /// Put every particle at its mass point's position and velocity for the skeleton state already in
  /// `sb` (q and u of the skeleton set, e.g. by setSimbodyState): the constraints then hold exactly.
  /// Also takes the active sets of conditional points at that q, which the constraints keep until
  /// the next switch event (the system's, so one run at a time per ParticleMuscles).
  void placeParticles(SimTK::State& sb) const;

  /// The skeleton's core state (t, q, qdot = T^-1 u) from a state of the system with particles
  /// (model_to_simbody.hpp's getCoreState expects the skeleton's u alone).
  State coreState(const Model& model, const SimTK::State& sb) const;

  int numParticles() const { return static_cast<int>(placer_->particles.size()); }
  /// particle k (muscles in order, their mass points in order)
  const SimTK::MobilizedBody& particle(int k) const { return placer_->particles.at(k); }

 private:
  const SimbodyModel& sm_;
  // placeParticles' work, shared with the conditional points' event handlers
  std::shared_ptr<detail::ParticlePlacer> placer_;
};

}  // namespace redmax::simbody
