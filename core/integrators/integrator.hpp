#pragma once
// Forward-dynamics integrators behind one interface [D Eq. 4.20, 4.21, 4.82].
// SUNDIALS appears only in core/integrators/*.cpp, never in a header (STYLE.md).
#include <memory>
#include <stdexcept>
#include <string>

#include "core/dynamics/system.hpp"

namespace redmax {

struct IntegratorOptions {
  double dt = 1e-3;        // fixed step (euler, bdf1, sdirk2); initial step hint for adaptive ones
  double rtol = 1e-6;      // adaptive methods (rk45, cvode)
  double atol = 1e-8;
  double max_step = 0.0;   // 0: unlimited
  long max_steps = 10'000'000;  // per advance() call
};

struct IntegratorStats {
  long steps = 0;
  long rhs_evals = 0;          // evaluations of M and f
  long jacobian_evals = 0;     // implicit methods
  long reparameterizations = 0;
  long failed_steps = 0;
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
  /// advance `state` from state.t to t_out. Fixed-step methods shorten the last step to land on
  /// t_out exactly, so output sampling needs no events.
  virtual void advance(const System& sys, State& state, double t_out) = 0;
  const IntegratorStats& stats() const { return stats_; }

 protected:
  IntegratorStats stats_;
};

/// names: euler (symplectic/semi-implicit), bdf1 (linearly implicit), sdirk2, rk45 (ARKODE
/// Dormand-Prince 5(4)), cvode (adaptive BDF). Throws std::invalid_argument on an unknown name.
std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorOptions& opt);

/// throws SimulationError naming the first non-finite entry of q or qdot
void checkFinite(const State& s, double h, const char* where);

}  // namespace redmax
