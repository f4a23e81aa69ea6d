// SUNDIALS 6.4 back ends of rk45 (ARKODE ERKStep, Dormand-Prince 5(4)) and cvode (CVODE BDF,
// dense Newton). The only translation unit that includes SUNDIALS headers; the static SUNDIALS
// archives are linked into libredmax_integrators with their symbols hidden (docs/build.md trap 2).
#include "core/integrators/sundials_integrators.hpp"
#include "core/integrators/event_driven.hpp"

#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <sstream>

#include "core/skeleton/kinematics.hpp"

namespace redmax {
namespace detail {

enum class SundialsKind { Erk, Cvode };

/// Everything SUNDIALS: context, state vectors, solver memory, plus the binding to the System
/// for the duration of one advance() call.
struct SundialsSolver {
  SundialsSolver(SundialsKind k, const IntegratorOptions& o) : kind(k), opt(o) {}
  ~SundialsSolver() { release(); }

  SundialsKind kind;
  IntegratorOptions opt;
  const char* label() const { return kind == SundialsKind::Erk ? "rk45" : "cvode"; }

  // SUNDIALS objects, created once per system size
  SUNContext ctx = nullptr;
  N_Vector y = nullptr;     // internal state y = [q, qdot, z] (2 ndof + nz) at t_cur
  N_Vector yout = nullptr;  // interpolated output
  void* mem = nullptr;
  SUNMatrix A = nullptr;
  SUNLinearSolver LS = nullptr;
  sunindextype N = 0;

  // binding while advance() runs
  const System* sys = nullptr;
  DynamicsWorkspace* ws = nullptr;
  State scratch;
  std::vector<std::string> z_names;  // System::stateNames() of the bound system
  std::exception_ptr rhs_exception;  // thrown inside the RHS (never propagated through C frames)
  std::string rhs_error;             // why the RHS refused (non-finite input or output)
  double rhs_error_t = 0.0;          // at which time
  // The RHS refused a trial stage (non-finite state, acceleration or rate): a smaller step may
  // stay inside the model's domain (a muscle's fibre pushed far beyond its curves by one long
  // stage, docs/forward.md §1). ERKStep treats every RHS error as fatal, so for rk45 step()
  // retries it from the last accepted state with a quarter of the step.
  bool rhs_recoverable = false;
  N_Vector y_accepted = nullptr;     // y at t_cur, the start of the step being tried (rk45)
  std::string sun_message;           // last error reported by SUNDIALS

  // where the internal solution is, and what the last advance() returned
  bool valid = false;
  double t_cur = 0.0;
  bool pending_chart_check = false;
  std::uint64_t last_sys = 0;  // System::id() of the system last integrated (0: none)
  State last_out;

  // counters already folded into the stats
  long seen_steps = 0, seen_rhs = 0, seen_jac = 0, seen_fail = 0;

  void release() {
    if (mem) {
      if (kind == SundialsKind::Erk) ERKStepFree(&mem);
      else CVodeFree(&mem);
    }
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (y) N_VDestroy(y);
    if (yout) N_VDestroy(yout);
    if (y_accepted) N_VDestroy(y_accepted);
    y_accepted = nullptr;
    if (ctx) SUNContext_Free(&ctx);
    mem = nullptr;
    LS = nullptr;
    A = nullptr;
    y = yout = nullptr;
    ctx = nullptr;
    N = 0;
    valid = false;
  }

  [[noreturn]] void fail(const std::string& what, int flag) {
    valid = false;
    // an exception from the dynamics is rethrown as it was
    if (rhs_exception) {
      std::exception_ptr e = rhs_exception;
      rhs_exception = nullptr;
      std::rethrow_exception(e);
    }
    double t = t_cur, h = 0.0;
    if (mem) {
      if (kind == SundialsKind::Erk) {
        ERKStepGetCurrentTime(mem, &t);
        ERKStepGetCurrentStep(mem, &h);
      } else {
        CVodeGetCurrentTime(mem, &t);
        CVodeGetCurrentStep(mem, &h);
      }
    }
    // a refused RHS evaluation pins the time down better than the step start
    if (!rhs_error.empty()) t = rhs_error_t;
    std::ostringstream os;
    os << label() << ": " << what;
    if (flag != 0) {
      char* name = kind == SundialsKind::Erk ? ERKStepGetReturnFlagName(flag)
                                             : CVodeGetReturnFlagName(flag);
      os << " (" << (name ? name : "?") << ")";
      std::free(name);
    }
    os << " at t = " << t << " with step h = " << h;
    if (!rhs_error.empty()) os << ": " << rhs_error;
    else if (!sun_message.empty()) os << ": " << sun_message;
    throw SimulationError(os.str(), t, h);
  }

  void check(int flag, const char* call) {
    if (flag < 0) fail(std::string(call) + " failed", flag);
  }

  /// a non-finite input or output of the dynamics: rk45 retries the step (step(); a singular mass
  /// matrix stays singular and fails after the retries); cvode stops (its own recoverable-error
  /// retries creep up to a persisting NaN for minutes)
  int refuse(const std::string& why, double t) {
    rhs_error = why;
    rhs_error_t = t;
    rhs_recoverable = true;
    return -1;
  }

  static int rhs(sunrealtype t, N_Vector yv, N_Vector ydot, void* user) {
    auto* self = static_cast<SundialsSolver*>(user);
    try {
      const int n = self->sys->ndof();
      const int nz = self->sys->numStates();
      const Eigen::Map<const VecX> Y(N_VGetArrayPointer(yv), 2 * n + nz);
      Eigen::Map<VecX> Yd(N_VGetArrayPointer(ydot), 2 * n + nz);
      if (!Y.allFinite()) {
        std::ostringstream os;
        os << "non-finite state passed to the dynamics at t = " << t;
        return self->refuse(os.str(), t);
      }
      State& s = self->scratch;
      s.t = t;
      s.q = Y.head(n);
      s.qdot = Y.segment(n, n);
      if (nz > 0) s.z = Y.tail(nz);
      const VecX qddot = self->sys->forwardDynamics(s, *self->ws);
      for (int k = 0; k < n; ++k) {
        if (!std::isfinite(qddot[k])) {
          std::ostringstream os;
          os << "non-finite qddot[" << k << "] = " << qddot[k] << " at t = " << t;
          return self->refuse(os.str(), t);
        }
      }
      for (int k = 0; k < nz; ++k) {
        if (!std::isfinite(self->ws->zdot[k])) {
          std::ostringstream os;
          os << "non-finite rate of state "
             << (k < static_cast<int>(self->z_names.size()) ? self->z_names[k] : "z[" + std::to_string(k) + "]")
             << " = " << self->ws->zdot[k] << " at t = " << t;
          return self->refuse(os.str(), t);
        }
      }
      Yd.head(n) = s.qdot;
      Yd.segment(n, n) = qddot;
      if (nz > 0) Yd.tail(nz) = self->ws->zdot;
      return 0;
    } catch (...) {
      self->rhs_exception = std::current_exception();
      return -1;
    }
  }

  static void errHandler(int code, const char* module, const char* function, char* msg, void* user) {
    if (code > 0) return;  // warnings (e.g. t + h == t) are not failures
    auto* self = static_cast<SundialsSolver*>(user);
    self->sun_message = std::string(module ? module : "") + "::" + (function ? function : "") + ": " +
                        (msg ? msg : "");
  }

  /// make sure the vectors fit 2 ndof + nz; a new size frees and recreates everything
  void ensureSize(int n2) {
    if (ctx && N == n2) return;
    release();
    if (SUNContext_Create(nullptr, &ctx) != 0 || !ctx) fail("SUNContext_Create failed", 0);
    N = n2;
    y = N_VNew_Serial(N, ctx);
    yout = N_VNew_Serial(N, ctx);
    y_accepted = N_VNew_Serial(N, ctx);
    if (!y || !yout || !y_accepted) fail("N_VNew_Serial failed", 0);
  }

  /// (re)initialise the solver at (t0, y); keeps all options
  void init(double t0) {
    if (kind == SundialsKind::Erk) {
      if (!mem) {
        mem = ERKStepCreate(&SundialsSolver::rhs, t0, y, ctx);
        if (!mem) fail("ERKStepCreate failed", 0);
        check(ERKStepSetTableNum(mem, ARKODE_DORMAND_PRINCE_7_4_5), "ERKStepSetTableNum");
        check(ERKStepSStolerances(mem, opt.rtol, opt.atol), "ERKStepSStolerances");
        check(ERKStepSetUserData(mem, this), "ERKStepSetUserData");
        check(ERKStepSetErrHandlerFn(mem, &SundialsSolver::errHandler, this), "ERKStepSetErrHandlerFn");
        if (opt.max_step > 0.0) check(ERKStepSetMaxStep(mem, opt.max_step), "ERKStepSetMaxStep");
        if (opt.initial_step > 0.0) check(ERKStepSetInitStep(mem, opt.initial_step), "ERKStepSetInitStep");
      } else {
        check(ERKStepSetInitStep(mem, opt.initial_step), "ERKStepSetInitStep");
        check(ERKStepReInit(mem, &SundialsSolver::rhs, t0, y), "ERKStepReInit");
      }
    } else {
      if (!mem) {
        mem = CVodeCreate(CV_BDF, ctx);
        if (!mem) fail("CVodeCreate failed", 0);
        check(CVodeSetErrHandlerFn(mem, &SundialsSolver::errHandler, this), "CVodeSetErrHandlerFn");
        check(CVodeInit(mem, &SundialsSolver::rhs, t0, y), "CVodeInit");
        check(CVodeSStolerances(mem, opt.rtol, opt.atol), "CVodeSStolerances");
        check(CVodeSetUserData(mem, this), "CVodeSetUserData");
        A = SUNDenseMatrix(N, N, ctx);
        LS = A ? SUNLinSol_Dense(y, A, ctx) : nullptr;
        if (!A || !LS) fail("SUNDenseMatrix/SUNLinSol_Dense failed", 0);
        // no Jacobian function: CVODE's difference quotients (2 ndof RHS evaluations each)
        check(CVodeSetLinearSolver(mem, LS, A), "CVodeSetLinearSolver");
        if (opt.max_step > 0.0) check(CVodeSetMaxStep(mem, opt.max_step), "CVodeSetMaxStep");
        if (opt.initial_step > 0.0) check(CVodeSetInitStep(mem, opt.initial_step), "CVodeSetInitStep");
      } else {
        check(CVodeReInit(mem, t0, y), "CVodeReInit");
      }
    }
    t_cur = t0;
    resetCounterBaseline();
  }

  /// restart after a chart switch of the state in y at t_cur
  void restartAfterChartSwitch() {
    if (kind == SundialsKind::Erk) {
      // keeps counters and the step size history
      check(ERKStepReset(mem, t_cur, y), "ERKStepReset");
      resetCounterBaseline();
    } else {
      init(t_cur);
    }
  }

  void readCounters(long& nst, long& nfe, long& nje, long& nfail) {
    nst = nfe = nje = nfail = 0;
    if (!mem) return;
    if (kind == SundialsKind::Erk) {
      long netf = 0;
      ERKStepGetNumSteps(mem, &nst);
      ERKStepGetNumRhsEvals(mem, &nfe);
      ERKStepGetNumErrTestFails(mem, &netf);
      nfail = netf;
    } else {
      long nfe_ls = 0, netf = 0, ncfn = 0;
      CVodeGetNumSteps(mem, &nst);
      CVodeGetNumRhsEvals(mem, &nfe);
      CVodeGetNumLinRhsEvals(mem, &nfe_ls);
      CVodeGetNumJacEvals(mem, &nje);
      CVodeGetNumErrTestFails(mem, &netf);
      CVodeGetNumNonlinSolvConvFails(mem, &ncfn);
      nfe += nfe_ls;
      nfail = netf + ncfn;
    }
  }

  void resetCounterBaseline() { readCounters(seen_steps, seen_rhs, seen_jac, seen_fail); }

  /// fold counter increments since the last call into the stats (works whether a re-init
  /// resets SUNDIALS' counters or not, since the baseline is re-read after each)
  void syncStats(IntegratorStats& st) {
    long nst, nfe, nje, nfail;
    readCounters(nst, nfe, nje, nfail);
    auto add = [](long& stat, long& seen, long now) {
      stat += now >= seen ? now - seen : now;
      seen = now;
    };
    add(st.steps, seen_steps, nst);
    add(st.rhs_evals, seen_rhs, nfe);
    add(st.jacobian_evals, seen_jac, nje);
    add(st.failed_steps, seen_fail, nfail);
  }

  /// one internal step towards t_out; returns the new internal time
  double step(double t_out, IntegratorStats& st) {
    sunrealtype tret = t_cur;
    if (kind == SundialsKind::Erk) N_VScale(1.0, y, y_accepted);
    for (int retry = 0;; ++retry) {
      rhs_error.clear();
      sun_message.clear();
      rhs_recoverable = false;
      const int flag = kind == SundialsKind::Erk ? ERKStepEvolve(mem, t_out, y, &tret, ARK_ONE_STEP)
                                                 : CVode(mem, t_out, y, &tret, CV_ONE_STEP);
      if (flag >= 0 && !rhs_exception) break;
      // rk45: a stage the dynamics refused; retry from the step's start with a quarter of the
      // step, as Simbody's integrators shrink a step whose evaluation failed. A refusal that
      // persists (a NaN from some time on) ends when the step falls below 1e-10 (1 + |t|): the
      // accepted steps creep up to the bad time and fail there
      constexpr int kMaxRetries = 25;
      sunrealtype h = 0.0;
      if (kind == SundialsKind::Erk) ERKStepGetCurrentStep(mem, &h);
      const double h_min = 1e-10 * (1.0 + std::abs(t_cur));
      if (kind != SundialsKind::Erk || rhs_exception || !rhs_recoverable || retry >= kMaxRetries ||
          !(0.25 * h > h_min))
        fail("step failed", flag);
      syncStats(st);
      ++st.failed_steps;
      N_VScale(1.0, y_accepted, y);
      check(ERKStepSetInitStep(mem, 0.25 * h), "ERKStepSetInitStep");
      check(ERKStepReInit(mem, &SundialsSolver::rhs, t_cur, y), "ERKStepReInit");
      resetCounterBaseline();
    }
    t_cur = tret;
    return tret;
  }

  void interpolate(double t, N_Vector out) {
    const int flag = kind == SundialsKind::Erk ? ERKStepGetDky(mem, t, 0, out) : CVodeGetDky(mem, t, 0, out);
    if (flag < 0) fail("dense output failed", flag);
  }

  double lastStep() {
    sunrealtype h = 0.0;
    if (mem) {
      if (kind == SundialsKind::Erk) ERKStepGetLastStep(mem, &h);
      else CVodeGetLastStep(mem, &h);
    }
    return h;
  }
};

}  // namespace detail

namespace {
using detail::SundialsSolver;

// y = [q, qdot, z]
void toState(N_Vector v, int n, int nz, double t, State& s) {
  const Eigen::Map<const VecX> Y(N_VGetArrayPointer(v), 2 * n + nz);
  s.t = t;
  s.q = Y.head(n);
  s.qdot = Y.segment(n, n);
  if (nz > 0) s.z = Y.tail(nz);
  else s.z.resize(0);
}

void fromState(const State& s, N_Vector v) {
  const int n = static_cast<int>(s.q.size());
  const int nz = static_cast<int>(s.z.size());
  Eigen::Map<VecX> Y(N_VGetArrayPointer(v), 2 * n + nz);
  Y.head(n) = s.q;
  Y.segment(n, n) = s.qdot;
  if (nz > 0) Y.tail(nz) = s.z;
}

/// binds the System and workspace to the solver for one advance() call
struct Binding {
  Binding(SundialsSolver& s, const System& sys, DynamicsWorkspace& ws) : solver(s) {
    solver.sys = &sys;
    solver.ws = &ws;
    solver.rhs_exception = nullptr;
  }
  ~Binding() {
    solver.sys = nullptr;
    solver.ws = nullptr;
  }
  SundialsSolver& solver;
};
}  // namespace

SundialsIntegrator::SundialsIntegrator(const IntegratorOptions& opt) : opt_(opt) {}
SundialsIntegrator::~SundialsIntegrator() = default;

ArkodeRk45::ArkodeRk45(const IntegratorOptions& opt) : SundialsIntegrator(opt) {
  solver_ = std::make_unique<detail::SundialsSolver>(detail::SundialsKind::Erk, opt);
}

CvodeBdf::CvodeBdf(const IntegratorOptions& opt) : SundialsIntegrator(opt) {
  solver_ = std::make_unique<detail::SundialsSolver>(detail::SundialsKind::Cvode, opt);
}

void SundialsIntegrator::advance(const System& sys, State& s, double t_out) {
  const std::string who = name();
  checkAdvanceArguments(sys, s, t_out, who.c_str());
  if (sys.unilateral()) {
    // hard joint limits and contacts: phases between events, each run by a fresh integrator of this kind
    UnilateralEventCounts c;
    advanceWithUnilateralEvents(who, opt_, sys, s, t_out, opt_.event_check_interval, stats_, &c, &events_);
    stats_.event_impacts += c.impacts;
    stats_.event_releases += c.releases;
    stats_.event_slips += c.slips;
    stats_.event_sticks += c.sticks;
    stats_.max_penetration = std::max(stats_.max_penetration, c.max_penetration);
    return;
  }
  if (t_out == s.t) return;
  SundialsSolver& S = *solver_;
  const int n = sys.ndof();
  const int nz = sys.numStates();
  if (!ws_ || ws_->system_id != sys.id()) ws_ = std::make_unique<DynamicsWorkspace>(sys);
  DynamicsWorkspace& ws = *ws_;
  Binding bind(S, sys, ws);
  S.z_names = nz > 0 ? sys.stateNames() : std::vector<std::string>{};
  const std::vector<std::string>* z_names = &S.z_names;
  try {
    // resume from the internal solution only if the caller did not touch the returned state
    const bool resume = S.valid && S.last_sys == sys.id() && S.N == 2 * n + nz && s.t == S.last_out.t &&
                        s.q == S.last_out.q && s.qdot == S.last_out.qdot && s.z == S.last_out.z;
    if (!resume) {
      checkFinite(s, 0.0, who.c_str(), z_names);
      S.valid = false;
      S.ensureSize(2 * n + nz);
      fromState(s, S.y);
      S.init(s.t);
      S.valid = true;
      S.pending_chart_check = true;
    }
    State internal;
    long steps_here = 0;
    while (S.t_cur < t_out) {
      // chart switch of the last accepted step, deferred until its interpolant is no longer
      // needed for output (a restart discards it)
      if (S.pending_chart_check) {
        S.pending_chart_check = false;
        toState(S.y, n, nz, S.t_cur, internal);
        const int switched = sys.reparameterize(internal);
        if (switched > 0) {
          stats_.reparameterizations += switched;
          fromState(internal, S.y);
          S.restartAfterChartSwitch();
        }
      }
      if (++steps_here > opt_.max_steps) {
        S.valid = false;
        std::ostringstream os;
        os << who << ": more than max_steps = " << opt_.max_steps
           << " internal steps in one advance() call, stuck at t = " << S.t_cur
           << " with step h = " << S.lastStep() << " (stiff or singular dynamics?)";
        throw SimulationError(os.str(), S.t_cur, S.lastStep());
      }
      const double t = S.step(t_out, stats_);
      S.syncStats(stats_);
      toState(S.y, n, nz, t, internal);
      checkFinite(internal, S.lastStep(), who.c_str(), z_names);
      S.pending_chart_check = true;
    }
    // dense output at t_out; the returned state may switch chart on its own copy
    S.interpolate(t_out, S.yout);
    State out;
    toState(S.yout, n, nz, t_out, out);
    checkFinite(out, S.lastStep(), who.c_str(), z_names);
    sys.reparameterize(out);
    s.t = out.t;
    s.q = out.q;
    s.qdot = out.qdot;
    s.z = out.z;
    S.last_out = out;
    S.last_sys = sys.id();
  } catch (...) {
    S.valid = false;
    S.syncStats(stats_);
    throw;
  }
}

}  // namespace redmax
