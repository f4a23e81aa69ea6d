#pragma once
// Inertial musculotendons as a ForceTerm [D Eq. 5.6-5.7]: every mass point a of every muscle adds
//   M   += m_a J_ar^T J_ar
//   f   += J_ar^T (m_a g - m_a Jdot_ar qdot)        (the second part is the quadratic velocity vector)
//   T    = 1/2 sum m_a |J_ar qdot|^2,   V = -sum m_a g . x_a
// with J_ar, Jdot_ar from core/muscles/muscle_kinematics.hpp and g the model's gravity.
// Muscle activation forces are not applied here: they act on the skeleton (other terms) and
// move the mass points only kinematically, as in the dissertation.
//
// Implicit integrators: addStiffnessDamping is not overridden, so bdf1/sdirk2 treat the muscle
// inertia's forces (gravity on the points, QVV) explicitly in K and D; M is still exact.
//
// Thread safety: the term itself is immutable. The muscle kinematics of a state live in its
// scratch (MuscleTermScratch, one per DynamicsWorkspace), valid for one evaluation of the
// workspace (TermContext::evaluation), so that addMass, addForce, Mdot qdot and the energies of
// one state share one muscle evaluation; threads with their own workspaces share one term without
// waiting on each other. Only the muscles with mass points are evaluated (no Jdot of massless
// muscles), at the velocity stage. Run-time counts (the network wrap model's fallbacks) live in
// the scratch too; callers sum them (takeWrapFallbackCounts).
#include <vector>

#include "core/dynamics/force_term.hpp"
#include "core/muscles/muscle_inverse_dynamics.hpp"
#include "core/muscles/muscle_kinematics.hpp"

namespace redmax {

/// Where one muscle's own states (its model's, in order) and its control sit in a System's
/// State::z and controls; -1: none. Fibre-following placement (core/muscles/fibre_placement.hpp)
/// reads them; without them it takes the fibre's equilibrium.
struct MuscleStateIndex {
  int z = -1;
  int u = -1;
};

struct MuscleTermOptions {
  /// keep -J_ar^T M_a Jdot_ar qdot in f; false drops it (the dissertation's energy experiment,
  /// Sec. 6.2.4). The bones' own quadratic velocity vector is not affected.
  bool quadratic_velocity = true;
};

/// Scratch of a MuscleTerm in one workspace (ForceTerm::makeScratch).
struct MuscleTermScratch final : TermScratch {
  MuscleTermScratch() = default;
  MuscleTermScratch(const Model& model, const std::vector<Muscle>& massive) : ws(model, massive) {}
  // velocity stage: calcMuscleKinematics of the muscles with mass, at evaluation `evaluation`
  MuscleWorkspace ws;               // one MuscleKinematics per muscle with mass points   (n_massive)
  // per-muscle temporaries of addMass / addForce (k = that muscle's compact columns)
  MatX scaled_J;                    // sqrt(m_a)-scaled J_ar (addMass)                     (3N x k)
  MatX Mc;                          // its J^T W J                                         (k x k)
  VecX qdot_c, fc;                  // qdot and force in the muscle's columns              (k)
  // recursive inverse dynamics (addInverseDynamics)
  std::vector<MuscleIdScratch> id;  // path-wise pass of each Type I/II muscle            (n_massive)
  std::vector<BodyWorldMotion> bodies;  // the bodies' motion in world axes                 (nb)
  std::vector<Vec6> w_world;        // the muscles' wrenches on the bodies, world axes     (nb)
  VecX qddot_c;                     // qddot in a Type III muscle's columns                (k)
};

class MuscleTerm final : public ForceTerm {
 public:
  /// Validates every muscle against `model` (validateMuscle; throws ModelError). Muscles without
  /// mass points are kept (muscles()) but add nothing.
  MuscleTerm(const Model& model, std::vector<Muscle> muscles, MuscleTermOptions options = {});
  /// the same, fibre-following muscles reading their states at `states` (one per muscle of
  /// `muscles`, or empty); a state index beyond State::z reads none (equilibrium)
  MuscleTerm(const Model& model, std::vector<Muscle> muscles, MuscleTermOptions options,
             std::vector<MuscleStateIndex> states);

  std::string name() const override { return "muscle_mass"; }
  /// a MuscleTermScratch sized for the muscles with mass (null when there are none)
  std::unique_ptr<TermScratch> makeScratch(const Model& model) const override;
  void addMass(const Model& model, const State& s, const TermContext& ctx, MatX& M) const override;
  /// true when a mass point has non-zero mass (zero-mass points add exactly nothing to M, so
  /// such a system keeps the massless system's forward route and results)
  bool addsMass() const override { return adds_mass_; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  /// analytic Mdot qdot of the mass points: sum_a m_a (Jdot_ar^T J_ar + J_ar^T Jdot_ar) qdot
  void addMassDotTimesVelocity(const Model& model, const State& s, const TermContext& ctx,
                               VecX& Mdot_v) const override;
  double kineticEnergy(const Model& model, const State& s, const TermContext& ctx) const override;
  /// Wrenches (Types I and II: addMuscleInverseDynamics, path-wise, no J_ar); with a Type III
  /// muscle, or without the quadratic velocity vector, WrenchesWithKinematics: those muscles form
  /// their compact J_ar, Jdot_ar and add J_ar^T m_a (J_ar qddot (+ Jdot_ar qdot) - g) (no M).
  TermIdRoute idRoute() const override;
  void addInverseDynamics(const Model& model, const State& s, const VecX& qddot, const TermContext& ctx,
                          const BodyMotion& motion, std::vector<Vec6>& wrench, VecX& tau) const override;
  double potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const override;
  /// false when a muscle with mass runs through a deformable node (its M reaches extra coordinates)
  bool matricesOnSkeletonOnly() const override { return !node_points_; }
  /// M as triplets when a muscle with mass runs through a node (false otherwise: the dense q_r form)
  bool addSparseMatrices(const Model& model, const State& s, const TermContext& ctx, bool stiffness, Triplets& M,
                         Triplets& K, Triplets& D) const override;

  const std::vector<Muscle>& muscles() const { return muscles_; }
  const MuscleTermOptions& options() const { return options_; }
  /// add the network wrap-model counts gathered in `scratch` (this term's slot of a workspace) to
  /// `monitor` and zero them there; no-op for a null slot
  void takeWrapFallbackCounts(TermScratch* scratch, WrapFallbackMonitor& monitor) const;
  /// sum of all mass-point masses (kg)
  double totalMass() const;

 private:
  // the scratch holding the muscle kinematics at this evaluation: ctx's slot, evaluated unless it
  // already holds this evaluation, or (direct calls without a slot) `local`, evaluated now
  MuscleTermScratch& evaluate(const Model& model, const State& s, const TermContext& ctx,
                              MuscleTermScratch& local) const;
  // J_ar^T M_a J_ar of each muscle with mass in its compact columns: add(mk.cols, Mc)
  template <class Add>
  void forEachMuscleMass(const Model& model, const State& s, const TermContext& ctx, Add&& add) const;
  /// massive_[m]'s kinematics at s: fibre-following muscles read their states (or equilibrium)
  void kinematicsOf(size_t m, const Model& model, const State& s, const TermContext& ctx,
                    MuscleKinematics& mk) const;

  std::vector<Muscle> muscles_;
  std::vector<Muscle> massive_;        // the muscles with at least one mass point
  std::vector<bool> compact_id_;       // massive_[m] needs its compact J_ar in inverse dynamics (Type III,
                                       // fibre-following, node points)
  bool adds_mass_ = false;             // a mass point of massive_ has non-zero mass (fixed at construction)
  bool node_points_ = false;           // a muscle of massive_ runs through a deformable node
  std::vector<MuscleStateIndex> massive_states_;  // their states (fibre-following placement)
  MuscleTermOptions options_;
  int nr_ = 0;
};

class System;
struct DynamicsWorkspace;

/// Fibre-following placement in forward dynamics: the MuscleTerm of `sys` (if any) is replaced by
/// one whose fibre-following muscles read the states and control of the same-named muscle of the
/// System's MuscleForceTerm (and follow that term's model, e.g. after a muscle-class override). A
/// muscle without such a model, or whose model's states do not allow it, falls back to the
/// uniform placement: one line each in the returned notes. No-op without both terms.
std::vector<std::string> bindMuscleStates(System& sys);

/// takeWrapFallbackCounts of every MuscleTerm of `sys` over its slots in `ws`: what a caller that
/// reports fallbacks calls for each workspace it evaluated in, after a run or after each span (the
/// counts are zeroed, so nothing is added twice). Evaluations without a slot (a term called
/// directly, with a bare SkeletonWorkspace) are not counted.
void takeWrapFallbackCounts(const System& sys, DynamicsWorkspace& ws, WrapFallbackMonitor& monitor);

}  // namespace redmax
