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
// Thread safety: the term caches the muscle kinematics of the last (q, qdot) it saw, so that
// addMass, addForce and the energies of one state share one evaluation; a mutex guards the
// cache, so one term may be shared, but concurrent callers then take turns.
#include <mutex>
#include <vector>

#include "core/dynamics/force_term.hpp"
#include "core/muscles/muscle_kinematics.hpp"

namespace redmax {

struct MuscleTermOptions {
  /// keep -J_ar^T M_a Jdot_ar qdot in f; false drops it (the dissertation's energy experiment,
  /// Sec. 6.2.4). The bones' own quadratic velocity vector is not affected.
  bool quadratic_velocity = true;
};

class MuscleTerm final : public ForceTerm {
 public:
  /// Validates every muscle against `model` (validateMuscle; throws ModelError). Muscles without
  /// mass points are kept (muscles()) but add nothing.
  MuscleTerm(const Model& model, std::vector<Muscle> muscles, MuscleTermOptions options = {});

  std::string name() const override { return "muscle_mass"; }
  void addMass(const Model& model, const State& s, const SkeletonWorkspace& sk, MatX& M) const override;
  void addForce(const Model& model, const State& s, const SkeletonWorkspace& sk, VecX& f) const override;
  /// analytic Mdot qdot of the mass points: sum_a m_a (Jdot_ar^T J_ar + J_ar^T Jdot_ar) qdot
  void addMassDotTimesVelocity(const Model& model, const State& s, const SkeletonWorkspace& sk,
                               VecX& Mdot_v) const override;
  double kineticEnergy(const Model& model, const State& s, const SkeletonWorkspace& sk) const override;
  double potentialEnergy(const Model& model, const State& s, const SkeletonWorkspace& sk) const override;

  const std::vector<Muscle>& muscles() const { return muscles_; }
  const MuscleTermOptions& options() const { return options_; }
  /// sum of all mass-point masses (kg)
  double totalMass() const;

 private:
  // evaluate (or reuse) the kinematics of the muscles with mass at this state; caller holds mutex_
  void update(const Model& model, const State& s, const SkeletonWorkspace& sk) const;

  std::vector<Muscle> muscles_;
  std::vector<Muscle> massive_;        // the muscles with at least one mass point
  MuscleTermOptions options_;
  int nr_ = 0;

  mutable std::mutex mutex_;
  mutable MuscleWorkspace ws_;         // kinematics of massive_
  mutable VecX q_cache_, qdot_cache_;
  mutable bool cache_valid_ = false;
  mutable MatX scratch_;               // sqrt(m_a)-scaled J_ar of one muscle (addMass)  (3N x k)
  mutable MatX Mc_;                    // its J^T W J                                     (k x k)
  mutable VecX qdot_c_, fc_;           // qdot and force in one muscle's columns          (k)
};

}  // namespace redmax
