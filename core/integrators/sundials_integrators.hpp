#pragma once
// Adaptive integrators from SUNDIALS 6.4 (ARKODE ERKStep and CVODE). SUNDIALS types stay in
// sundials_integrators.cpp: this header only sees an opaque implementation (docs/design.md §3, and
// docs/build.md trap 2: its symbols are hidden inside libredmax_integrators).
#include <memory>

#include "core/integrators/integrator.hpp"
#include "core/integrators/event_driven.hpp"

namespace redmax {

namespace detail {
struct SundialsSolver;  // SUNDIALS context, vectors, solver memory (sundials_integrators.cpp)
}

/// Common driver of the SUNDIALS integrators on y = (q, qdot), y' = (qdot, qddot) [D Eq. 4.21],
/// qddot from System::forwardDynamics (KKT accelerations with the System's Baumgarte
/// stabilisation when there are constraints).
///  - one-step mode: after every internal step the state is checked for NaN/Inf and the joints
///    may switch chart (System::reparameterize); a switch re-initialises the solver at that step.
///  - output: the solver steps past t_out and interpolates (its dense output); the next call
///    resumes from the internal state if `state` is unchanged since this call returned it,
///    otherwise it re-initialises at `state`.
///  - the SUNDIALS objects are created once and reused while the system size is unchanged.
///  - a non-finite qddot, an exception in the dynamics, or a solver failure (error-test or
///    convergence failures, step size underflow) becomes SimulationError with time and step.
class SundialsIntegrator : public Integrator {
 public:
  explicit SundialsIntegrator(const IntegratorOptions& opt);
  ~SundialsIntegrator() override;
  SundialsIntegrator(const SundialsIntegrator&) = delete;
  SundialsIntegrator& operator=(const SundialsIntegrator&) = delete;
  /// with hard joint limits (System::unilateral()): event location (core/integrators/event_driven.hpp)
  void advance(const System& sys, State& state, double t_out) override;
  DynamicsWorkspace* lastWorkspace() override { return ws_.get(); }
  bool handlesUnilateral() const override { return true; }

 protected:
  IntegratorOptions opt_;
  std::unique_ptr<detail::SundialsSolver> solver_;

 private:
  std::unique_ptr<DynamicsWorkspace> ws_;  // kept across advance() calls for one system
  EventMemory events_;                     // the held contacts, carried to the next advance()
};

/// Dormand-Prince 5(4) with local error control (ARKODE ERKStep, ARKODE_DORMAND_PRINCE_7_4_5),
/// rtol/atol from the options. Chart switches use ERKStepReset (step size history kept).
class ArkodeRk45 final : public SundialsIntegrator {
 public:
  explicit ArkodeRk45(const IntegratorOptions& opt);
  std::string name() const override { return "rk45"; }
};

/// Variable-order (1-5) variable-step BDF (CVODE) with Newton iterations on a dense
/// difference-quotient Jacobian (SUNDenseMatrix + SUNLinSol_Dense). For stiff systems (stiff
/// springs, muscles). Chart switches use CVodeReInit (restarts at order 1).
class CvodeBdf final : public SundialsIntegrator {
 public:
  explicit CvodeBdf(const IntegratorOptions& opt);
  std::string name() const override { return "cvode"; }
};

}  // namespace redmax
