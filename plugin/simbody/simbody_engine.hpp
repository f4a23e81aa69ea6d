#pragma once
// A core model run by Simbody behind a Simbody-free interface (pimpl), for the benchmarks and the
// `redmax bench` command: they time Simbody's own operations on the same tree without paying for
// Simbody's headers. Vectors in "u space" are in Simbody's mobility order and meaning (u = T qdot,
// see model_to_simbody.hpp); the *Core functions convert to core coordinates.
#include <memory>
#include <string>
#include <vector>

#include "core/skeleton/model.hpp"
#include "core/skeleton/state.hpp"
#include "plugin/simbody/simbody_options.hpp"

namespace redmax::simbody {

class SimbodyEngine {
 public:
  /// builds the Simbody system (throws SimbodyBuildError) and a state at the model's defaults
  explicit SimbodyEngine(const Model& model, const SimbodyBuildOptions& opt = {});
  ~SimbodyEngine();
  SimbodyEngine(const SimbodyEngine&) = delete;
  SimbodyEngine& operator=(const SimbodyEngine&) = delete;

  const Model& model() const;
  int nu() const;

  /// copy a core state in: q as is, u = T qdot. Invalidates Stage::Position and above.
  void setState(const State& s);
  /// the current Simbody state as a core state (qdot = T^-1 u)
  State coreState() const;
  /// u = T qdot and udot = T qddot + Tdot qdot for the current state (nu each)
  void mapVelocities(const VecX& qdot, const VecX& qddot, VecX& u, VecX& udot) const;

  // --- Simbody operations on the current state (u space), for timing ---------------------------
  /// mark q (and hence every stage above Model) as changed, so the next realize recomputes it
  void invalidatePositions();
  void realizePosition();
  void realizeVelocity();
  void realizeDynamics();
  void realizeAcceleration();
  /// SimbodyMatterSubsystem::calcM; needs Stage::Position (nu x nu)
  void calcMassMatrix(MatX& M_u) const;
  /// calcResidualForceIgnoringConstraints with the force subsystem's body and mobility forces at
  /// Stage::Dynamics as applied forces (gravity, springs); needs Stage::Dynamics
  void calcResidualForces(const VecX& udot, VecX& f_u) const;
  /// generalized accelerations after realizeAcceleration() (nu)
  VecX udot() const;

  // --- core-space results (tests, cross-checks) --------------------------------------------------
  MatX massMatrixCore(const State& s);
  VecX inverseDynamicsCore(const State& s, const VecX& qddot);
  VecX forwardDynamicsCore(const State& s);

  // --- Simbody integrators ------------------------------------------------------------------------
  /// names accepted by initIntegrator: "semi-explicit-euler" (fixed step), "semi-explicit-euler2"
  /// (fixed step), "rk-merson" (adaptive, accuracy), "cpodes" (adaptive BDF, accuracy)
  static std::vector<std::string> integratorNames();
  /// start integrating from the current state; throws std::invalid_argument on an unknown name
  void initIntegrator(const std::string& name, double dt, double accuracy);
  /// advance the integrator by dt (one reporting interval; adaptive methods may take several
  /// internal steps) and make its state the current one
  void stepIntegrator();
  /// Simbody's internal steps since the integrator was last (re)started from setState; 0 before
  long integratorSteps() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace redmax::simbody
