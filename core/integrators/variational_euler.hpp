#pragma once
// Variational (truly symplectic) Euler for mass matrices that depend on q: integrator "symplectic".
//
// Why a second Euler. The dissertation's semi-implicit Euler [D Eq. 4.20] (integrator "euler",
// core/integrators/symplectic_euler.hpp) updates M(q_k) (v+ - v) = h f(q_k, v) with the velocity
// products of f taken explicitly. With a constant M that is the symplectic Euler method; with
// M = M(q) it is not symplectic, and on the 5-link chain of tests/core/integrators its energy
// error grows linearly in time (first order in h). This method keeps the energy error bounded.
//
// Derivation. L(q, v) = 1/2 v^T M(q) v - V(q), non-conservative forces f_nc(q, v) (dampers,
// external loads). The Euler-Lagrange equation d/dt(M v) = dL/dq + f_nc and the
// System's M qddot = f give the identity
//   dL/dq + f_nc = f + Mdot v,       Mdot = sum_j dM/dq_j v_j     (System::calcMassDotTimesVelocity)
// so everything below is available from the System without a separate Lagrangian.
// Discrete Lagrangian L_d(q_k, q_k+1) = h L(q_k, v) with v = (q_k+1 - q_k) / h:
//   D1 L_d = h dL/dq(q_k, v) - M(q_k) v,      D2 L_d = M(q_k) v.
// The discrete Legendre transforms p_k = -D1 L_d - h f_nc(q_k, v) (discrete Lagrange-d'Alembert,
// left-point forcing) and p_k+1 = D2 L_d give the step (q_k, p_k) -> (q_k+1, p_k+1):
//   solve   M(q_k) v - h [f(q_k, v) + Mdot(q_k, v) v] = p_k      for v = v_k+1   (implicit in v)
//   then    q_k+1 = q_k + h v,    p_k+1 = M(q_k) v.
// Without f_nc this map is exactly symplectic in (q, p) (it is the symplectic Euler method
// applied to H(q, p) with p = dL/dv, written in Lagrangian variables): a nearby modified
// Hamiltonian is conserved, so the energy error stays O(h) without secular growth. With M
// constant and f independent of v it reduces to "euler".
//
// Momentum and the state. State stores q and qdot only; the step needs p_k, which is not
// M(q_k) qdot_k but M(q_k-1) qdot_k. The integrator therefore keeps p after each step in the
// workspace it steps with (DynamicsWorkspace::integrator, a VariationalEulerScratch; advance()
// keeps one workspace per system across calls, see FixedStepIntegrator), together with the exact
// bits of the (q, qdot) it returned (as the SUNDIALS integrators keep their internal state). A
// workspace bound to another system has no cache. A state that does not match (a new initial
// condition, a state modified by the caller) is given
//   p = M(q - h qdot) qdot,
// the momentum it would have had had it come from a step of size h (equal to the cached one up to
// round-off for a state produced by this integrator, so results do not depend on how a span is
// split into advance() calls). A fresh initial condition thus starts with a momentum O(h) away
// from M(q) qdot, within the method's first-order accuracy. setMomentum() seeds the cache.
//
// Chart switches [D Sec. 4.5.8] (System::reparameterize after each step, e.g. exponential
// coordinates past |q| = 1.5 pi): the switch q' = phi(q) maps velocities linearly,
// qdot' = Dphi qdot, and the momentum is carried over by the cotangent lift p' = Dphi^-T p, a
// symplectic change of coordinates, so step + switch stays symplectic. (Rebuilding p' from the
// switched state instead is off by O(h) in p and not symplectic.) The modified energy that a
// first-order symplectic method conserves, H - h/2 H_p . H_q + O(h^2), depends on the chart, so
// each switch moves its level by O(h): with switches at random states (a chaotic chain) this is
// a small random walk, with the same switch every revolution (a steady spin) a slow drift, still
// an order of magnitude below euler's (tests/core/integrators/variational_euler_test.cpp).
//
// Solving for v. At fixed q_k the residual R(v) = M v - h g(v) - p_k, g = f + Mdot v, depends on
// v only through the velocity products (quadratic) and dampers; springs and gravity act at q_k
// and need no iteration. The iteration v+ = v - A^-1 R(v) uses A = M(q_k) - h J with J ~ dg/dv
// a forward-difference Jacobian (ndof dynamics evaluations) taken on the first step and kept
// current by Broyden rank-one updates from the iterates; it is retaken when the iteration
// contracts slower than theta = 0.1 (restarting from v_k if it moved away), at most 3 times a
// step. Gyroscopic terms of small inertias (a rod spinning about its axis) make the simpler
// M + h D contract too slowly to be useful. Stopping rule: |dv| <= tol (1 + |v|), or the error
// estimated from the contraction rate, theta / (1 - theta) |dv|, below that bound (tol = 1e-12);
// no convergence in max_iter iterations is a SimulationError. The first iterate is predicted by
// linear extrapolation 2 v_k - v_k-1. Cost on the 5-link chain at 1 ms: about 5 dynamics
// evaluations (M, f and Mdot v) per step.
//
// Mass matrices that jump. Where M(q) is discontinuous (a Type II mass point passing a via point:
// J_ar changes segment, [D Eq. 5.29-5.36]) the step M(q_k) v_k+1 - h g = M(q_k-1) v_k carries p
// across the jump, so as h -> 0 this method follows v+ = M+^-1 M- v- at each crossing, while the
// ODE M qddot = f that the other integrators solve keeps qdot continuous. Both are consistent
// limits of different jump rules (their kinetic-energy jumps are +-1/2 v^T (M+ - M-) v to first
// order), so on such scenes "symplectic" converges at order 1 to another trajectory
// (tests/core/integrators/variational_muscle_test.cpp; README, notes a researcher should know).
//
// Constraints: enforced at the velocity level as in "euler" [D Eq. 4.102, 4.110]: every linear
// solve is the KKT system [A G^T; G 0] [v; lambda] = [A v_n - R(v_n); G v_k + h rhs - vel_err]
// with G, rhs and vel_err at the start of the step (q_k, v_k); the constraint impulse enters p_k+1
// through v. Hyper-reduced coordinates (System::setCoordinateMap) need nothing special: M, f and
// Mdot v are the System's, in q_R.
#include "core/integrators/integrator.hpp"

namespace redmax {

/// The variational integrator's part of a DynamicsWorkspace (DynamicsWorkspace::integrator).
struct VariationalEulerScratch final : TermScratch {
  // momentum cache: p belongs to the state (q_end, v_end) this integrator returned last
  bool have_state = false;
  VecX q_end, v_end, p;      // (ndof)
  VecX v_prev;               // velocity of the step before, for the predictor (ndof)
  bool have_prev = false;
  // last difference Jacobian dg/dv, kept current by Broyden updates; reused as the iteration
  // matrix of later steps until the contraction slows down        (ndof x ndof)
  MatX Jg;
  bool have_jacobian = false;
};

class VariationalEuler final : public FixedStepIntegrator {
 public:
  /// tol: relative convergence tolerance on v; max_iter: iterations per step
  explicit VariationalEuler(const IntegratorOptions& opt, double tol = 1e-12, int max_iter = 30)
      : FixedStepIntegrator(opt), tol_(tol), max_iter_(max_iter) {}
  std::string name() const override { return "symplectic"; }

  /// one step of size h (state.t += h), with p from ws's cache or reconstructed (see above)
  void step(const System& sys, State& state, double h, DynamicsWorkspace& ws) override;

  /// One step of the (q, p) map: on entry s.q = q_k, s.qdot = v_k (start of the constraint rows
  /// and first guess of v unless `guess` is given), p = p_k (ndof); on exit s.q = q_k+1,
  /// s.qdot = v_k+1, p = p_k+1 = M(q_k) v_k+1, s.t += h. No chart switch, no momentum cache
  /// update (the difference Jacobian in ws is kept).
  void stepMomentum(const System& sys, State& s, VecX& p, double h, DynamicsWorkspace& ws,
                    const VecX* guess = nullptr);

  /// discrete momentum of a state reached by a step of size h: p = M(q - h qdot) qdot (ndof)
  static VecX momentum(const System& sys, const State& s, double h, DynamicsWorkspace& ws);

  /// Seed the cache of advance()'s workspace for sys: the next advance from exactly s (same
  /// System, same q and qdot bits) uses momentum p (ndof), e.g. to resume from a saved (q, qdot,
  /// p). Throws std::invalid_argument on sizes that do not match the system.
  void setMomentum(const System& sys, const State& s, const VecX& p);

  /// The momentum the next step from s with ws will use (ndof): ws's cached p if s is the state
  /// returned last by a step with ws, carried through a joint chart switch if s is that state
  /// switched, else momentum(sys, s, h, ws). Updates ws's cache accordingly.
  const VecX& momentumOf(const System& sys, const State& s, double h, DynamicsWorkspace& ws);

  /// linear solves of the implicit momentum equation over all steps, and the most in one step
  /// (difference Jacobians are counted in stats().jacobian_evals, their evaluations in rhs_evals)
  long iterations() const { return iterations_; }
  int maxIterationsPerStep() const { return max_iterations_per_step_; }

 private:
  // ws's VariationalEulerScratch for sys (made on first use, dropped with the binding)
  static VariationalEulerScratch& scratchOf(const System& sys, DynamicsWorkspace& ws);
  // if s is the chart switch of (c.q_end, c.v_end), carry c.p (and the predictor) over to the new
  // chart by the cotangent lift and return true
  static bool liftThroughChartSwitch(const System& sys, const State& s, VariationalEulerScratch& c);

  static constexpr int kMaxRefreshes = 3;      // difference Jacobians per step at most
  static constexpr double kRefreshAbove = 0.1;  // contraction rate that triggers one

  double tol_;
  int max_iter_;
  long iterations_ = 0;
  int max_iterations_per_step_ = 0;

};

}  // namespace redmax
