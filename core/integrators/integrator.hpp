#pragma once
// Forward-dynamics integrators behind one interface [D Eq. 4.20, 4.21, 4.82].
// SUNDIALS appears only in core/integrators/*.cpp, never in a header (docs/design.md §3).
//
//   name        method                                            step      constraints
//   euler       semi-implicit Euler [D Eq. 4.20] (SymplecticEuler)  fixed   velocity-level KKT [D Eq. 4.102, 4.110]
//   symplectic  variational Euler, implicit in v (VariationalEuler) fixed   velocity-level KKT
//   bdf1        linearly implicit backward Euler [D Eq. 4.80-4.82] fixed  velocity-level KKT
//   sdirk2      2-stage L-stable SDIRK, order 2, Newton           fixed     KKT accelerations + Baumgarte
//   rk45        Dormand-Prince 5(4), SUNDIALS ARKODE ERKStep      adaptive  KKT accelerations + Baumgarte
//   cvode       variable-order BDF, SUNDIALS CVODE, dense Newton  adaptive  KKT accelerations + Baumgarte
//
// euler is symplectic only when M is constant; with M(q) its energy error grows linearly in time,
// while symplectic keeps it bounded (docs/notes.md).
//
// Every method treats q and qdot as independent coordinates with dq/dt = qdot (true for every
// joint type, see core/joints/joint.hpp). After each internal step the joints get a chance to
// switch chart (System::reparameterize, exponential coordinates [D Sec. 4.5.8]).
//
// Auxiliary states z (State::z, System::numStates(): muscle activations, fibre lengths,
// docs/forward.md): rk45 and cvode integrate y = [q, qdot, z] as one system (the same rtol, atol);
// the fixed-step methods advance z by explicit Euler with zdot at the start of each step
// (z+ = z + h zdot(t, q, qdot, z)), holding z at its start value inside the step's own (implicit)
// solve of q and qdot: first order in z, whatever their order in q. With nz = 0 nothing changes.
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/dynamics/system.hpp"

namespace redmax {

struct IntegratorOptions {
  double dt = 1e-3;        // fixed step (euler, bdf1, sdirk2); the last step of a span is not shortened:
                           // a span is cut into ceil(span / dt) equal steps
  double rtol = 1e-6;      // adaptive methods (rk45, cvode)
  double atol = 1e-8;      // absolute tolerance on every q, qdot and z entry (rk45, cvode)
  double max_step = 0.0;   // adaptive methods: largest internal step; 0 = unlimited
  double initial_step = 0.0;    // adaptive methods: first step; 0 = estimated by SUNDIALS
  long max_steps = 10'000'000;  // per advance() call
  double newton_tol = 1e-10;    // sdirk2: converged when |dV| <= newton_tol (1 + |V|)
  int newton_max_iter = 12;     // sdirk2: iterations per Newton phase (approximate, then FD Jacobian)
  // bdf1 with extra coordinates (deformable nodes): "dense" forms M, K, D over all coordinates,
  // "sparse" assembles them sparse (System::calcSparseMatrices) and factors sparse; "auto" takes
  // sparse from kSparseStepFrom coordinates on (measured crossover, docs/deformable.md §5) unless
  // the system has hard unilateral constraints or a coordinate map (dense only)
  std::string linear_solver = "auto";
  // rk45 and cvode with hard unilateral constraints (core/integrators/event_driven.hpp): the largest
  // time between event checks (s); an impact and rebound both inside one interval would be missed
  double event_check_interval = 1e-3;
};

/// Counters accumulated over the lifetime of one Integrator (all advance() calls).
struct IntegratorStats {
  long steps = 0;              // accepted internal steps
  long rhs_evals = 0;          // evaluations of M and f (for cvode including its difference-quotient Jacobians)
  long jacobian_evals = 0;     // implicit methods: Newton/implicit matrix assemblies (K, D or FD Jacobians)
  long reparameterizations = 0;  // joint chart switches applied to the integrated state
  long failed_steps = 0;       // rejected steps (error test or Newton failures)
  // hard unilateral constraints (bdf1 with System::unilateral(); core/dynamics/unilateral/)
  long unilateral_steps = 0;   // steps that solved a contact QP (some candidate row present)
  long qp_iterations = 0;      // active-set changes, all QPs
  long qp_solves = 0;          // QPs (the friction fixed-point iterations count each)
  long contact_rows = 0;       // sum over steps of rows with a positive impulse
  int max_contacts = 0;        // most rows with a positive impulse in one step
  double max_penetration = 0.0;  // largest penetration at a step's start (m, or rad for limits)
  long friction_unconverged = 0; // steps whose friction fixed point hit its iteration limit
  // hard unilateral constraints under rk45 / cvode (event location, core/integrators/event_driven.hpp;
  // max_penetration above is then the largest seen at the event checks)
  long event_impacts = 0;        // contact points and limit sides in resolved impacts
  long event_releases = 0;       // held contacts released
  long event_slips = 0;          // sticking friction directions that began to slide
  long event_sticks = 0;         // sliding friction directions that stuck
};

/// A simulation produced NaN/Inf or diverged: says when, what, and with which step.
class SimulationError : public std::runtime_error {
 public:
  SimulationError(const std::string& what, double t, double h)
      : std::runtime_error(what), time(t), step(h) {}
  double time;
  double step;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;
  /// Advance `state` from state.t to t_out; afterwards state.t == t_out exactly. Fixed-step
  /// methods cut the span into ceil(span / dt) equal steps; adaptive methods step past t_out and
  /// interpolate (their dense output), continuing from their internal state on the next call when
  /// `state` is still the one they returned. t_out == state.t does nothing.
  /// Throws std::invalid_argument if t_out < state.t or q/qdot do not have sys.ndof() entries,
  /// SimulationError on NaN/Inf, divergence or a solver failure; `state` then holds the last
  /// finite step reached (fixed-step methods) or is left as it was passed (adaptive methods).
  virtual void advance(const System& sys, State& state, double t_out) = 0;
  const IntegratorStats& stats() const { return stats_; }
  /// the workspace advance() last evaluated the system in (null before the first call), kept
  /// across calls for the same system: callers that report run-time counts take them from its
  /// term slots (takeWrapFallbackCounts, core/dynamics/muscle_term.hpp)
  virtual DynamicsWorkspace* lastWorkspace() { return nullptr; }
  /// true if the method enforces System::unilateral(): bdf1 (limits and contacts, the contact
  /// QP), rk45 and cvode (joint limits and contacts by event location); advance() of the others throws
  /// std::invalid_argument for a system that has them
  virtual bool handlesUnilateral() const { return false; }

 protected:
  IntegratorStats stats_;
};

/// names: euler (symplectic/semi-implicit), bdf1 (linearly implicit), sdirk2, rk45 (ARKODE
/// Dormand-Prince 5(4)), cvode (adaptive BDF). Throws std::invalid_argument on an unknown name or
/// on invalid options (non-positive dt or tolerances).
std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorOptions& opt);

/// Throws SimulationError naming the first non-finite entry of q, qdot or z, or the first entry
/// whose magnitude exceeds kDivergenceLimit (a diverging simulation, reported before it overflows).
/// z entries are named by z_names (System::stateNames()) when given, else as z[k].
void checkFinite(const State& s, double h, const char* where,
                 const std::vector<std::string>* z_names = nullptr);

/// |q| or |qdot| beyond this is reported as divergence by checkFinite.
inline constexpr double kDivergenceLimit = 1e100;

/// Throws std::invalid_argument if the state (q, qdot, z) does not fit the system or t_out < state.t.
void checkAdvanceArguments(const System& sys, const State& s, double t_out, const char* where);
/// Throws std::invalid_argument if sys has hard unilateral constraints that integ cannot enforce.
void checkUnilateralSupport(const Integrator& integ, const System& sys);

/// Shared driver of the fixed-step methods: cuts [state.t, t_out] into ceil(span / dt) equal
/// steps, calls step() for each, lets the joints switch chart after each step, checks for
/// NaN/Inf, and sets state.t = t_out exactly at the end. advance() steps with one workspace per
/// integrator, kept across calls while the system stays the same (System::id), so what a method
/// carries from step to step (DynamicsWorkspace::integrator) survives a span cut into calls.
class FixedStepIntegrator : public Integrator {
 public:
  explicit FixedStepIntegrator(const IntegratorOptions& opt) : opt_(opt) {}
  void advance(const System& sys, State& state, double t_out) override;
  /// one step of size h from state (state.t advanced by h); no chart switch, no NaN check
  virtual void step(const System& sys, State& state, double h, DynamicsWorkspace& ws) = 0;
  const IntegratorOptions& options() const { return opt_; }
  /// the workspace advance() uses for sys (a new one when sys is not the system of the last)
  DynamicsWorkspace& workspace(const System& sys);
  DynamicsWorkspace* lastWorkspace() override { return ws_.get(); }

 protected:
  IntegratorOptions opt_;

 private:
  std::unique_ptr<DynamicsWorkspace> ws_;
};

}  // namespace redmax
