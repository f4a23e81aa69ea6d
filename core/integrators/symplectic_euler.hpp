#pragma once
#include "core/integrators/integrator.hpp"

namespace redmax {

/// Semi-implicit Euler [D Eq. 4.19-4.20], the CLI's integrator "euler":
///   M qdot+ = M qdot + h f(q, qdot),   q+ = q + h qdot+.
/// First order, explicit in the forces (stable only while h is below ~2/omega_max). Its energy
/// error stays bounded only when M is constant (then it is the symplectic Euler method); with
/// M = M(q) it is not symplectic and the energy error grows linearly in time (docs/notes.md).
/// The integrator "symplectic" is VariationalEuler (variational_euler.hpp). Constraints are applied at the velocity level
/// [D Eq. 4.102, 4.104, 4.110] as one KKT system
///   [M G^T; G 0] [qdot+; lambda] = [M qdot + h f; G qdot + h rhs - vel_err],
/// where rhs = -Gdot qdot (+ prescribed accelerations) and subtracting vel_err removes velocity
/// drift: for a closed loop vel_err = G qdot, so G qdot+ = -h Gdot qdot, i.e. G(q+) qdot+ ~ 0.
class SymplecticEuler final : public FixedStepIntegrator {
 public:
  explicit SymplecticEuler(const IntegratorOptions& opt) : FixedStepIntegrator(opt) {}
  std::string name() const override { return "euler"; }
  /// one step of size h (state.t += h); M, f and constraint rows at the start of the step
  void step(const System& sys, State& state, double h, DynamicsWorkspace& ws) override;
};

}  // namespace redmax
