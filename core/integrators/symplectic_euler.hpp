#pragma once
#include "core/integrators/integrator.hpp"

namespace redmax {

/// Semi-implicit (symplectic) Euler [D Eq. 4.20]: M qdot+ = M qdot + h f, q+ = q + h qdot+.
/// Constraints are applied at the velocity level [D Eq. 4.102, 4.110]:
///   G qdot+ = G qdot + h rhs - vel_err (drift correction), solved as one KKT system.
class SymplecticEuler final : public Integrator {
 public:
  explicit SymplecticEuler(const IntegratorOptions& opt) : opt_(opt) {}
  std::string name() const override { return "euler"; }
  void advance(const System& sys, State& state, double t_out) override;
  /// one step of size h
  void step(const System& sys, State& state, double h, DynamicsWorkspace& ws);

 private:
  IntegratorOptions opt_;
};

}  // namespace redmax
