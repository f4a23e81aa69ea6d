#pragma once
// Muscles that pull: each muscle with a Hill-type model (core/muscles/hill/muscle_model.hpp) as a
// ForceTerm with its own states and one control (docs/forward.md). At a state, for muscle m:
//   l, ldot      path length and lengthening speed (core/muscles/path_kinematics.hpp; with wrap
//                objects OpenSim's wrapped length, core/muscles/wrap/wrap_path.hpp)
//   dl/dq        Type I/II: sum over segments i of dxbar_i^T (J_x,i+1 - J_x,i) from J_xr (exact),
//                as OpenSim's GeometryPath::produceForces applies it: segments within one body
//                skipped, a MovingPathPoint's derivative at its coordinate's unclamped value;
//                Type III: central differences of the wrapped length in each coordinate that can
//                move the path (h = 1e-7 rad or m), and ldot = dl/dq qdot
//   F_t, zdot    the model's calc(z_m, {l, ldot, u_m})
//   f           -= F_t (dl/dq)^T                 (the tendon pulls the path's ends together)
// so the actuator's power is f . qdot = -F_t ldot. The term adds no mass (the muscles' inertia is
// MuscleTerm's) and no stiffness: implicit integrators treat it explicitly.
//
// States: the model's stateNames() of every muscle, in muscle order, named
// /forceset/<muscle>/<state> (OpenSim 4); controls: one excitation per muscle, named as the
// muscle. Muscles without a model (null) are kept out: no states, no control, no force.
//
// Thread safety: the term is immutable; the path kinematics and model outputs of one evaluation
// live in its MuscleForceScratch (TermContext::evaluation), so addForce and calcStateDerivatives
// of one state share them.
#include <memory>
#include <string>
#include <vector>

#include "core/dynamics/force_term.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/muscle_workspace.hpp"

namespace redmax {

/// Per-workspace scratch of a MuscleForceTerm: one entry per actuated muscle.
struct MuscleForceScratch final : TermScratch {
  struct Entry {
    MuscleKinematics mk;          // path points (Type I/II) and the columns cols     (k columns)
    VecX dl_dq;                   // d length / dq in mk's compact columns             (k)
    double length = 0.0, speed = 0.0;
    hill::MuscleOutput out;
    VecX zdot;                    // the model's state rates                           (model states)
  };
  std::vector<Entry> muscles;
  std::vector<Mat4> E_wi;         // body poses at perturbed q (Type III differences)  (nb)
  VecX q;                         // perturbed q                                       (nr)
};

class MuscleForceTerm final : public ForceTerm {
 public:
  /// muscles and their models (same size; a null model leaves that muscle out). Validates the
  /// paths (validatePath); throws ModelError on a size mismatch.
  MuscleForceTerm(const Model& model, const std::vector<Muscle>& muscles,
                  const std::vector<std::shared_ptr<const hill::MuscleModel>>& models);

  std::string name() const override { return "muscle_force"; }
  std::unique_ptr<TermScratch> makeScratch(const Model& model) const override;
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;

  int numStates() const override { return nz_; }
  std::vector<std::string> stateNames() const override;
  void defaultStates(const Model& model, Eigen::Ref<VecX> z) const override;
  void calcStateDerivatives(const Model& model, const State& s, const TermContext& ctx,
                            Eigen::Ref<VecX> zdot) const override;
  /// each model's equilibrate at the path's length and speed and the muscle's control
  void equilibrateStates(const Model& model, const State& s, const TermContext& ctx,
                         Eigen::Ref<VecX> z) const override;
  int numControls() const override { return static_cast<int>(actuated_.size()); }
  std::vector<std::string> controlNames() const override;

  /// the actuated muscles (those with a model), in state and control order
  struct Actuated {
    Muscle muscle;
    std::shared_ptr<const hill::MuscleModel> model;
    int z_offset = 0;  // within this term's states
  };
  const std::vector<Actuated>& actuated() const { return actuated_; }
  /// the outputs of actuated muscle k at s (an evaluation without scratch), e.g. for reports
  hill::MuscleOutput calcOutput(const Model& model, const State& s, const TermContext& ctx, int k) const;
  /// path length, speed and dl/dq (nr, or all of s.q with extra coordinates) of actuated muscle k
  /// at s (Stage::Velocity)
  void calcPath(const Model& model, const State& s, const SkeletonWorkspace& sk, int k, double& length,
                double& speed, VecX& dl_dq) const;
  /// the same with the caller's scratch, kept between calls (sized for every muscle on first use;
  /// no allocation afterwards): for callers that evaluate single muscles many times
  void calcPath(const Model& model, const State& s, const SkeletonWorkspace& sk, int k, MuscleForceScratch& sc,
                double& length, double& speed, VecX& dl_dq) const;

 private:
  MuscleForceScratch& evaluate(const Model& model, const State& s, const TermContext& ctx,
                               MuscleForceScratch& local) const;
  void evalPath(const Model& model, const State& s, const SkeletonWorkspace& sk, int k,
                MuscleForceScratch& sc) const;

  std::vector<Actuated> actuated_;
  int nz_ = 0;
};

}  // namespace redmax
