#include "core/integrators/variational_euler.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "core/integrators/implicit_solve.hpp"

namespace redmax {

VecX VariationalEuler::momentum(const System& sys, const State& s, double h, DynamicsWorkspace& ws) {
  // p_k = D2 L_d(q_k-1, q_k) = M(q_k-1) v_k with q_k-1 = q_k - h v_k
  State prev = s;
  prev.q = s.q - h * s.qdot;
  sys.calcMassAndForce(prev, ws);
  return ws.M * s.qdot;
}

VariationalEulerWorkspace& VariationalEuler::cacheFor(const System& sys) {
  if (cache_.system_id != sys.id()) {
    cache_ = VariationalEulerWorkspace{};
    cache_.system_id = sys.id();
  }
  return cache_;
}

const VecX& VariationalEuler::momentumOf(const System& sys, const State& s, double h, DynamicsWorkspace& ws) {
  VariationalEulerWorkspace& c = cacheFor(sys);
  // the cached momentum belongs to exactly the state this integrator returned last
  const bool same = c.have_state && c.q_end.size() == s.q.size() && c.v_end.size() == s.qdot.size();
  const bool hit = same && ((c.q_end == s.q && c.v_end == s.qdot) || liftThroughChartSwitch(sys, s, c));
  if (!hit) {
    c.p = momentum(sys, s, h, ws);
    ++stats_.rhs_evals;
    c.have_state = true;
    c.q_end = s.q;
    c.v_end = s.qdot;
    c.have_prev = false;
  }
  return c.p;
}

void VariationalEuler::setMomentum(const System& sys, const State& s, const VecX& p) {
  const int n = sys.ndof();
  if (s.q.size() != n || s.qdot.size() != n || p.size() != n)
    throw std::invalid_argument("symplectic: setMomentum: state or momentum does not have " + std::to_string(n) +
                                " entries");
  VariationalEulerWorkspace& c = cacheFor(sys);
  c.have_state = true;
  c.q_end = s.q;
  c.v_end = s.qdot;
  c.p = p;
  c.have_prev = false;
}

void VariationalEuler::step(const System& sys, State& s, double h, DynamicsWorkspace& ws) {
  VecX p = momentumOf(sys, s, h, ws);  // a copy: the cache stays valid if the step throws
  VariationalEulerWorkspace& c = cacheFor(sys);
  // linear extrapolation of the velocity predicts v_k+1 to O(h^2) (one or two iterations fewer)
  VecX guess;
  const VecX* guess_ptr = nullptr;
  if (c.have_prev) {
    guess = 2.0 * s.qdot - c.v_prev;
    guess_ptr = &guess;
  }
  const VecX v_k = s.qdot;
  stepMomentum(sys, s, p, h, ws, guess_ptr);
  c.p = std::move(p);
  c.q_end = s.q;
  c.v_end = s.qdot;
  c.v_prev = v_k;
  c.have_prev = true;
}

bool VariationalEuler::liftThroughChartSwitch(const System& sys, const State& s, VariationalEulerWorkspace& c) {
  // is s the chart switch of the state we returned?
  State sw;
  sw.t = s.t;
  sw.q = c.q_end;
  sw.qdot = c.v_end;
  if (sys.reparameterize(sw) == 0 || sw.q != s.q || sw.qdot != s.qdot) return false;
  // the switch q' = phi(q) maps velocities linearly, qdot' = Dphi(q) qdot; its cotangent lift
  // p' = Dphi^-T p is a symplectic change of coordinates, so the composed map stays symplectic.
  // (Rebuilding p' = M(q' - h qdot') qdot' instead would be off by O(h) in p at every switch.)
  const int n = static_cast<int>(s.q.size());
  MatX Dphi(n, n);
  State e;
  e.t = s.t;
  for (int j = 0; j < n; ++j) {
    e.q = c.q_end;
    e.qdot = VecX::Unit(n, j);
    sys.reparameterize(e);
    Dphi.col(j) = e.qdot;
  }
  const Eigen::PartialPivLU<MatX> lu(Dphi.transpose());
  c.p = lu.solve(c.p);
  if (c.have_prev) c.v_prev = Dphi * c.v_prev;
  c.q_end = s.q;
  c.v_end = s.qdot;
  return true;
}

void VariationalEuler::stepMomentum(const System& sys, State& s, VecX& p, double h, DynamicsWorkspace& ws,
                                    const VecX* guess) {
  const int n = sys.ndof();
  const int nc = sys.numConstraintRows();
  if (p.size() != n || s.q.size() != n || s.qdot.size() != n)
    throw std::invalid_argument("symplectic: momentum or state does not have ndof entries");
  VariationalEulerWorkspace& c = cacheFor(sys);
  MatX& Jg = c.Jg;
  const VecX q_k = s.q;
  const VecX v_k = s.qdot;
  State sv;
  sv.t = s.t;
  sv.z = s.z;  // auxiliary states held over the step (integrator.hpp)
  sv.q = q_k;
  sv.qdot = v_k;

  // velocity-level constraint rows at the start of the step, as in euler [D Eq. 4.102, 4.110]
  MatX G(0, n);
  VecX b;
  if (nc > 0) {
    sys.calcMassAndForce(sv, ws);
    ++stats_.rhs_evals;
    sys.calcConstraints(sv, ws);
    G = ws.G;
    b = ws.G * v_k + h * ws.rhs - ws.vel_err;
  }

  // g(v) = f(q_k, v) + Mdot(q_k, v) v = dL/dq + f_nc at (q_k, v)
  VecX g, Mdv;
  auto evalG = [&](const VecX& v) {
    sv.qdot = v;
    sys.calcMassAndForce(sv, ws);
    ++stats_.rhs_evals;
    sys.calcMassDotTimesVelocity(sv, ws, Mdv);
    g = ws.f + Mdv;
  };

  VecX v = guess ? *guess : v_k;
  evalG(v);
  const MatX M_k = ws.M;  // M depends on q only: fixed over the iteration

  // forward-difference Jacobian dg/dv at v (g holds g(v) on entry and on exit); an iteration
  // matrix only, so O(d) accuracy is enough
  auto jacobian = [&]() {
    const VecX g0 = g;
    VecX vp;
    Jg.resize(n, n);
    for (int j = 0; j < n; ++j) {
      const double d = 1e-7 * (1.0 + std::abs(v[j]));
      vp = v;
      vp[j] += d;
      evalG(vp);
      Jg.col(j) = (g - g0) / d;
    }
    g = g0;
    c.have_jacobian = true;
    ++stats_.jacobian_evals;
  };

  // iteration matrix A ~ dR/dv = M_k - h dg/dv with the Jacobian of an earlier step kept current
  // by Broyden updates (one difference Jacobian on the first step of a system)
  MatX A;
  Eigen::PartialPivLU<MatX> lu;
  auto setMatrix = [&](MatX Anew) {
    A = std::move(Anew);
    if (nc == 0) lu.compute(A);
  };
  if (!c.have_jacobian || Jg.rows() != n) jacobian();
  setMatrix(M_k - h * Jg);

  // residual R(v) = M_k v - h g(v) - p; every solve is A v+ = A v - R(v) with constraint rows
  int iters = 0, since = 0, refreshes = 0;
  bool converged = false;
  double dv = 0.0, dv_prev = 0.0;
  while (iters < max_iter_) {
    const VecX a = A * v - (M_k * v - h * g - p);
    const VecX v_new = nc == 0 ? VecX(lu.solve(a)) : detail::solveImplicit(A, G, a, b, &ws.lambda);
    ++iters;
    ++since;
    dv_prev = dv;
    dv = (v_new - v).norm();
    if (!std::isfinite(dv)) {
      // diverged with the current matrix: restart from v_k with a fresh Jacobian
      if (refreshes >= kMaxRefreshes) break;
      v = v_k;
      evalG(v);
      jacobian();
      ++refreshes;
      setMatrix(M_k - h * Jg);
      since = 0;
      dv = 0.0;
      continue;
    }
    const VecX v_prev = v;
    v = v_new;
    // stopping rule: |dv| below the bound, or the error estimated from the contraction rate
    const double bound = tol_ * (1.0 + v.norm());
    const double theta = since > 1 ? dv / dv_prev : 0.0;
    if (dv <= bound || (since > 1 && theta < 1.0 && theta / (1.0 - theta) * dv <= bound)) {
      converged = true;
      break;
    }
    // round-off floor: no more progress at a level a thousand times the tolerance
    if (since > 1 && theta >= 0.5 && dv <= 1e3 * bound) {
      converged = true;
      break;
    }
    const VecX g_old = g;
    evalG(v);
    if (since > 1 && theta > kRefreshAbove && refreshes < kMaxRefreshes) {
      // slow contraction: the matrix misses the velocity products, refresh the Jacobian (from
      // the start of the step if the iteration was moving away)
      if (theta >= 1.0) {
        v = v_k;
        evalG(v);
      }
      jacobian();
      ++refreshes;
      setMatrix(M_k - h * Jg);
      since = 0;
    } else if (dv > 1e-8 * (1.0 + v.norm())) {
      // Broyden's rank-one update keeps Jg current along the trajectory at no extra evaluation
      // (skipped once dv is so small that g's round-off would dominate the secant)
      const VecX dvec = v - v_prev;
      Jg += ((g - g_old) - Jg * dvec) * (dvec.transpose() / dvec.squaredNorm());
      setMatrix(M_k - h * Jg);
    }
  }
  iterations_ += iters;
  max_iterations_per_step_ = std::max(max_iterations_per_step_, iters);
  if (!converged) {
    std::ostringstream os;
    if (std::isfinite(dv))
      os << "symplectic: the implicit momentum equation did not converge (last |dv| = " << dv << " after "
         << iters << " iterations) at t = " << s.t << " with step h = " << h << "; reduce dt";
    else
      os << "symplectic: non-finite velocity in the implicit momentum equation (non-finite forces or "
            "mass matrix?) at t = "
         << s.t << " with step h = " << h;
    throw SimulationError(os.str(), s.t, h);
  }

  // q_k+1 = q_k + h v, p_k+1 = D2 L_d = M(q_k) v
  s.qdot = v;
  s.q = q_k + h * v;
  p = M_k * v;
  s.t += h;
}

}  // namespace redmax
