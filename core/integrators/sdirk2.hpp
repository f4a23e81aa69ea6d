#pragma once
#include "core/integrators/integrator.hpp"

namespace redmax {

/// Two-stage, L-stable, stiffly accurate SDIRK of order 2 (Alexander 1977), gamma = 1 - 1/sqrt(2):
///   c = (gamma, 1),  A = [gamma 0; 1-gamma gamma],  b = (1-gamma, gamma)
/// on the first-order system y = (q, qdot), y' = (qdot, qddot(q, qdot)) [D Eq. 4.21], fixed step.
/// Each stage Y = (Q, V) solves Q = zq + h gamma V, V = zv + h gamma qddot(Q, V) for V by Newton.
/// The Newton matrix (scaled by M) is approximated by
///   M + h gamma D + (h gamma)^2 K        (K = -df/dq, D = -df/dqdot of springs, dampers, terms)
/// i.e. the derivatives of M, gravity and the velocity-product terms are neglected: for them
/// the iteration contracts like (h gamma)^2 |M^-1 df/dq| + h gamma |M^-1 df/dqdot|, fast at the
/// steps this method is used with, while stiff springs/dampers are inverted exactly. If that
/// iteration diverges or is too slow to reach the tolerance in newton_max_iter iterations, the
/// stage restarts with full Newton on a forward-difference Jacobian of the residual (ndof extra
/// dynamics evaluations per iteration; counted in stats().failed_steps); if that fails too,
/// SimulationError.
/// Stopping rule: |dV| <= newton_tol (1 + |V|), or the error estimated from the contraction rate
/// theta, theta / (1 - theta) |dV|, below the same bound. Stage 1 is predicted with the end
/// acceleration of the previous step (free: the method is stiffly accurate).
/// Constraints: qddot comes from the acceleration-level KKT system (System::forwardDynamics)
/// with the System's Baumgarte stabilisation (System::stabilization); Newton steps are solved
/// with the constraint rows in the KKT matrix. Without stabilisation the position drift of
/// closed loops grows with time as with any index-1 formulation.
class Sdirk2 final : public FixedStepIntegrator {
 public:
  explicit Sdirk2(const IntegratorOptions& opt) : FixedStepIntegrator(opt) {}
  std::string name() const override { return "sdirk2"; }
  /// one step of size h (state.t += h)
  void step(const System& sys, State& state, double h, DynamicsWorkspace& ws) override;

  /// gamma = 1 - 1/sqrt(2)
  static double gamma();

 private:
  /// solve V = zv + hg qddot(zq + hg V, V) at time t; V holds the initial guess on entry
  void solveStage(const System& sys, double t, const VecX& zq, const VecX& zv, double hg,
                  double h, VecX& V, DynamicsWorkspace& ws);

  // the acceleration at the end of the last step, F(Y2) = (V2 - zv) / (h gamma) (stiffly
  // accurate, so it is qddot(y+)), predicts the next stage 1 if the next step starts there
  VecX a_end_;
  State end_;
  VecX z_;  // the auxiliary states of the step being taken
};

}  // namespace redmax
