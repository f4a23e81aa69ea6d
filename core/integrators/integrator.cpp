#include "core/integrators/integrator.hpp"

#include <cmath>
#include <sstream>

#include "core/integrators/linearly_implicit_euler.hpp"
#include "core/integrators/sdirk2.hpp"
#include "core/integrators/sundials_integrators.hpp"
#include "core/integrators/symplectic_euler.hpp"
#include "core/integrators/variational_euler.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax {

namespace {
void checkOptions(const std::string& name, const IntegratorOptions& opt) {
  auto bad = [&](const std::string& what) {
    throw std::invalid_argument("integrator '" + name + "': " + what);
  };
  const bool adaptive = name == "rk45" || name == "cvode";
  if (!adaptive && !(opt.dt > 0.0 && std::isfinite(opt.dt))) bad("dt must be positive and finite");
  if (adaptive && !(opt.rtol > 0.0 && std::isfinite(opt.rtol))) bad("rtol must be positive and finite");
  if (adaptive && !(opt.atol > 0.0 && std::isfinite(opt.atol))) bad("atol must be positive and finite");
  if (!(opt.max_step >= 0.0)) bad("max_step must be >= 0 (0 = unlimited)");
  if (!(opt.initial_step >= 0.0)) bad("initial_step must be >= 0 (0 = estimated)");
  if (opt.max_steps <= 0) bad("max_steps must be positive");
  if (name == "sdirk2" && !(opt.newton_tol > 0.0)) bad("newton_tol must be positive");
  if (name == "sdirk2" && opt.newton_max_iter <= 0) bad("newton_max_iter must be positive");
}
}  // namespace

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorOptions& opt) {
  std::unique_ptr<Integrator> integ;
  if (name == "euler") integ = std::make_unique<SymplecticEuler>(opt);
  else if (name == "symplectic") integ = std::make_unique<VariationalEuler>(opt);
  else if (name == "bdf1") integ = std::make_unique<LinearlyImplicitEuler>(opt);
  else if (name == "sdirk2") integ = std::make_unique<Sdirk2>(opt);
  else if (name == "rk45") integ = std::make_unique<ArkodeRk45>(opt);
  else if (name == "cvode") integ = std::make_unique<CvodeBdf>(opt);
  else
    throw std::invalid_argument("unknown integrator '" + name +
                                "' (expected euler, symplectic, bdf1, sdirk2, rk45 or cvode)");
  checkOptions(name, opt);
  return integ;
}

void checkFinite(const State& s, double h, const char* where, const std::vector<std::string>* z_names) {
  for (int k = 0; k < s.q.size(); ++k) {
    const bool q_ok = std::isfinite(s.q[k]) && std::abs(s.q[k]) <= kDivergenceLimit;
    const bool qd_ok = std::isfinite(s.qdot[k]) && std::abs(s.qdot[k]) <= kDivergenceLimit;
    if (q_ok && qd_ok) continue;
    const char* which = q_ok ? "qdot" : "q";
    const double v = q_ok ? s.qdot[k] : s.q[k];
    std::ostringstream os;
    os << where << ": " << (std::isfinite(v) ? "diverged: " : "non-finite ") << which << "[" << k
       << "] = " << v;
    if (std::isfinite(v)) os << " (beyond " << kDivergenceLimit << " in magnitude)";
    os << " at t = " << s.t << " with step h = " << h;
    throw SimulationError(os.str(), s.t, h);
  }
  for (int k = 0; k < s.z.size(); ++k) {
    const double v = s.z[k];
    if (std::isfinite(v) && std::abs(v) <= kDivergenceLimit) continue;
    std::ostringstream os;
    os << where << ": " << (std::isfinite(v) ? "diverged: " : "non-finite ") << "state ";
    if (z_names && k < static_cast<int>(z_names->size())) os << (*z_names)[k];
    else os << "z[" << k << "]";
    os << " = " << v;
    if (std::isfinite(v)) os << " (beyond " << kDivergenceLimit << " in magnitude)";
    os << " at t = " << s.t << " with step h = " << h;
    throw SimulationError(os.str(), s.t, h);
  }
}

void checkAdvanceArguments(const System& sys, const State& s, double t_out, const char* where) {
  const int n = sys.ndof();
  if (s.q.size() != n || s.qdot.size() != n) {
    std::ostringstream os;
    os << where << ": state has " << s.q.size() << " coordinates and " << s.qdot.size()
       << " speeds, the system has " << n;
    throw std::invalid_argument(os.str());
  }
  if (s.z.size() != sys.numStates()) {
    std::ostringstream os;
    os << where << ": state has " << s.z.size() << " auxiliary states, the system has " << sys.numStates();
    throw std::invalid_argument(os.str());
  }
  if (!std::isfinite(t_out) || !std::isfinite(s.t)) {
    throw std::invalid_argument(std::string(where) + ": non-finite time");
  }
  if (t_out < s.t) {
    std::ostringstream os;
    os << where << ": cannot integrate backwards from t = " << s.t << " to t_out = " << t_out;
    throw std::invalid_argument(os.str());
  }
}

void checkUnilateralSupport(const Integrator& integ, const System& sys) {
  if (sys.unilateral() && !integ.handlesUnilateral())
    throw std::invalid_argument("integrator '" + integ.name() +
                                "' cannot enforce hard unilateral constraints (joint limits, contacts); "
                                "use bdf1 (docs/contact.md §6)");
}

DynamicsWorkspace& FixedStepIntegrator::workspace(const System& sys) {
  if (!ws_ || ws_->system_id != sys.id()) ws_ = std::make_unique<DynamicsWorkspace>(sys);
  return *ws_;
}

void FixedStepIntegrator::advance(const System& sys, State& s, double t_out) {
  const std::string who = name();
  checkAdvanceArguments(sys, s, t_out, who.c_str());
  checkUnilateralSupport(*this, sys);
  const double span = t_out - s.t;
  if (span <= 0.0) return;
  // ceil(span / dt) equal steps landing on t_out exactly (the 1e-9 slack keeps a round-off
  // excess from adding a sliver step)
  const double ratio = span / opt_.dt;
  if (!(ratio < 1e15)) throw std::invalid_argument(who + ": span / dt too large");
  const long n = std::max(1L, static_cast<long>(std::ceil(ratio - 1e-9)));
  if (n > opt_.max_steps) {
    throw SimulationError(who + ": " + std::to_string(n) + " steps requested, more than max_steps = " +
                              std::to_string(opt_.max_steps),
                          s.t, opt_.dt);
  }
  const double h = span / static_cast<double>(n);
  const double t0 = s.t;
  const int nz = sys.numStates();
  const std::vector<std::string> z_names = nz > 0 ? sys.stateNames() : std::vector<std::string>{};
  checkFinite(s, h, who.c_str(), &z_names);
  DynamicsWorkspace& ws = workspace(sys);
  State last_good = s;
  VecX zdot;
  for (long k = 0; k < n; ++k) {
    try {
      // auxiliary states: explicit Euler with the rate at the step's start (see the header)
      if (nz > 0) {
        sys.calcStateDerivatives(s, ws);
        zdot = ws.zdot;
      }
      step(sys, s, h, ws);
      if (nz > 0) s.z.noalias() += h * zdot;
      // time from the step count, so round-off does not accumulate over long runs
      s.t = (k + 1 == n) ? t_out : t0 + static_cast<double>(k + 1) * h;
      checkFinite(s, h, who.c_str(), &z_names);
    } catch (...) {
      // hand back the last finite state, never NaN
      s = last_good;
      throw;
    }
    ++stats_.steps;
    stats_.reparameterizations += sys.reparameterize(s);
    last_good.t = s.t;
    last_good.q = s.q;
    last_good.qdot = s.qdot;
    if (nz > 0) last_good.z = s.z;
  }
  s.t = t_out;
}

}  // namespace redmax
