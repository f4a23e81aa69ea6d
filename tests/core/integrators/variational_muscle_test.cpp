// The variational integrator "symplectic" on Type II muscles whose mass points cross a via point.
//
// A mass point sits at a fixed arc fraction alpha; while the via point's Eulerian coordinate s_1
// passes alpha the point changes segment, so x_a(q) has a kink there and J_ar, hence M(q), jumps
// [D Eq. 5.29-5.36]. The ODE M(q) qddot = f has bounded qddot, so its solution keeps qdot
// continuous across the jump (what euler, rk45, cvode, ... converge to). The discrete
// Euler-Lagrange step M(q_k) v_k+1 - h g = M(q_k-1) v_k sees no delta in dL/dq and so keeps the
// momentum p = M qdot continuous instead. These tests pin that finding with an independent
// event-located RK4 reference for each jump rule:
//   - no crossing over the run: symplectic converges to the qdot-continuous solution at order 1;
//   - with a crossing: its error against that solution stops shrinking, while its error against
//     the solution with v+ = M+^-1 M- v- at each crossing converges at order 1.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "core/dynamics/muscle_term.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

// origin on the world near the hinge, a via point on link1 above the middle hinge, insertion on
// link2: s_1 = l_0 / (l_0 + l_1) moves with q1 and q2
Muscle viaMuscle(double alpha, double mass) {
  Muscle mu;
  mu.name = "via";
  mu.path.points = {makeFixedPoint(-1, Vec3(0.15, 0.0, 0.0), "origin"), makeFixedPoint(0, Vec3(0.06, -0.85, 0.0), "via"),
                    makeFixedPoint(1, Vec3(0.06, -0.6, 0.0), "insertion")};
  mu.mass_points = makeMassPoints(std::vector<double>{alpha}, std::vector<double>{mass});
  return mu;
}

struct Scene {
  explicit Scene(double alpha)
      : model(scenes::doublePendulum()), muscle(viaMuscle(alpha, 0.5)), sys(model) {
    sys.addTerm(std::make_shared<MuscleTerm>(model, std::vector<Muscle>{muscle}));
    s0 = sys.defaultState();
    s0.q << 0.8, -0.4;
    s0.qdot.setZero();
  }
  Model model;
  Muscle muscle;
  System sys;
  State s0;
};

// the via point's Eulerian coordinate s_1 at q
double viaS(const Scene& sc, const VecX& q) {
  State s;
  s.q = q;
  s.qdot = VecX::Zero(q.size());
  SkeletonWorkspace sk(sc.model);
  calcKinematics(sc.model, s, sk);
  const std::vector<Muscle> mus{sc.muscle};
  MuscleWorkspace mw(sc.model, mus);
  calcMuscleKinematics(sc.model, s, sk, mus, mw, false);
  return mw.muscles[0].s[1];
}

enum class Jump { Velocity, Momentum };

struct Reference {
  State end;
  int crossings = 0;
  double s_min = 1.0, s_max = 0.0;
  std::vector<double> kick;      // |v+ - v-|_inf that the momentum rule gives at each crossing
  std::vector<double> dE_v, dE_p;  // kinetic-energy change at each crossing under either rule (J)
};

// classic RK4 on qddot = M^-1 f with h fixed; a step in which s_1 - alpha changes sign is split at
// the crossing (bisection to 1e-9 of the step: far enough apart that MuscleTerm's own segment
// choice, which rounds differently, has switched too) so each piece integrates a smooth field, and
// Jump::Momentum applies v+ = M+^-1 M- v- there (one-sided M from the two bracketing states)
Reference rk4Reference(const Scene& sc, double alpha, double T, double h, Jump rule) {
  DynamicsWorkspace ws(sc.model);
  auto rk4 = [&](const State& x, double dt) {
    auto acc = [&](const VecX& q, const VecX& v) {
      State s;
      s.t = x.t;
      s.q = q;
      s.qdot = v;
      return sc.sys.forwardDynamics(s, ws);
    };
    const VecX k1v = acc(x.q, x.qdot), k1q = x.qdot;
    const VecX k2q = x.qdot + 0.5 * dt * k1v, k2v = acc(x.q + 0.5 * dt * k1q, k2q);
    const VecX k3q = x.qdot + 0.5 * dt * k2v, k3v = acc(x.q + 0.5 * dt * k2q, k3q);
    const VecX k4q = x.qdot + dt * k3v, k4v = acc(x.q + dt * k3q, k4q);
    State y = x;
    y.q += dt / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
    y.qdot += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    y.t += dt;
    return y;
  };
  auto massAt = [&](const State& x) {
    sc.sys.calcMassAndForce(x, ws);
    return MatX(ws.M);
  };
  Reference r;
  State x = sc.s0;
  const int n = static_cast<int>(std::lround(T / h));
  for (int k = 0; k < n; ++k) {
    double left = h;  // of this step
    for (;;) {
      const State y = rk4(x, left);
      const double c0 = viaS(sc, x.q) - alpha, c1 = viaS(sc, y.q) - alpha;
      r.s_min = std::min(r.s_min, c1 + alpha);
      r.s_max = std::max(r.s_max, c1 + alpha);
      if ((c0 < 0.0) == (c1 < 0.0)) {
        x = y;
        break;
      }
      double lo = 0.0, hi = left;  // c changes sign in (lo, hi]
      while (hi - lo > 1e-9 * h) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        if (((viaS(sc, rk4(x, mid).q) - alpha) < 0.0) == (c0 < 0.0))
          lo = mid;
        else
          hi = mid;
      }
      const State before = rk4(x, lo);
      State after = rk4(x, hi);
      {
        const MatX Mm = massAt(before), Mp = massAt(after);
        const VecX vp = Mp.ldlt().solve(Mm * before.qdot);
        const double Tm = 0.5 * before.qdot.dot(Mm * before.qdot);
        r.kick.push_back((vp - before.qdot).lpNorm<Eigen::Infinity>());
        r.dE_v.push_back(0.5 * before.qdot.dot(Mp * before.qdot) - Tm);
        r.dE_p.push_back(0.5 * vp.dot(Mp * vp) - Tm);
        if (rule == Jump::Momentum) after.qdot = vp;
      }
      ++r.crossings;
      left -= hi;
      x = after;
      if (left <= 0.0) break;
    }
  }
  r.end = x;
  return r;
}

double stateError(const State& a, const State& b) {
  VecX d(a.q.size() + a.qdot.size());
  d << a.q - b.q, a.qdot - b.qdot;
  return d.lpNorm<Eigen::Infinity>();
}

State runFixed(const std::string& name, const Scene& sc, double T, double dt) {
  IntegratorOptions opt;
  opt.dt = dt;
  auto integ = makeIntegrator(name, opt);
  State s = sc.s0;
  integ->advance(sc.sys, s, T);
  return s;
}

State runRk45(const Scene& sc, double T) {
  IntegratorOptions o;
  o.rtol = 1e-11;
  o.atol = 1e-13;
  auto rk = makeIntegrator("rk45", o);
  State s = sc.s0;
  rk->advance(sc.sys, s, T);
  return s;
}

constexpr double kT = 2.0;       // s simulated
constexpr double kHRef = 2e-4;   // RK4 reference step (its error is ~1e-12 without crossings)

// no mass point crosses the via point: M(q) is smooth along the run and symplectic converges at
// order 1 to the one solution (error halves with the step, ratio within [1.7, 2.3])
TEST(VariationalViaPoint, ConvergesWhenNoMassPointCrosses) {
  const double alpha = 0.45;  // s_1 stays in [0.493, 0.556] over the run
  const Scene sc(alpha);
  const Reference ref = rk4Reference(sc, alpha, kT, kHRef, Jump::Velocity);
  ASSERT_EQ(ref.crossings, 0);
  EXPECT_GT(ref.s_min, alpha);
  EXPECT_LT(stateError(runRk45(sc, kT), ref.end), 1e-8);  // the reference, cross-checked
  double prev = 0.0;
  for (double dt : {2e-3, 1e-3, 5e-4}) {
    const double e = stateError(runFixed("symplectic", sc, kT, dt), ref.end);
    std::printf("no crossing: symplectic dt %.1e error %.3e\n", dt, e);
    if (prev > 0.0) {
      EXPECT_GT(prev / e, 1.7) << "dt " << dt;
      EXPECT_LT(prev / e, 2.3) << "dt " << dt;
    }
    prev = e;
  }
  EXPECT_LT(prev, 3e-3);
}

// With crossings the two jump rules give solutions `gap` apart. symplectic converges at order 1
// to the momentum-continuous one (error over two halvings of the step / 2.8 or more) and not to
// the qdot-continuous one that rk45 and euler converge to (its distance from that stays above
// gap / 2). alpha 0.5: one crossing at t = 0.156 s; alpha 0.55: four (six under the momentum
// rule), near the top of s_1's range.
class VariationalViaPointCrossing : public ::testing::TestWithParam<double> {};

TEST_P(VariationalViaPointCrossing, ConvergesToTheMomentumContinuousSolution) {
  const double alpha = GetParam();
  const Scene sc(alpha);
  const Reference rv = rk4Reference(sc, alpha, kT, kHRef, Jump::Velocity);
  const Reference rp = rk4Reference(sc, alpha, kT, kHRef, Jump::Momentum);
  ASSERT_GE(rv.crossings, 1);
  ASSERT_GE(rp.crossings, 1);
  // the qdot-continuous reference is the ODE solution that rk45 computes
  EXPECT_LT(stateError(runRk45(sc, kT), rv.end), 1e-6);
  const double gap = stateError(rv.end, rp.end);
  EXPECT_GT(gap, 1e-2);
  // at each crossing of the ODE solution: the momentum rule would kick qdot, and the kinetic
  // energy jumps under either rule, with opposite signs and nearly equal size (to first order in
  // the jump, +-1/2 v^T (M+ - M-) v), so neither conserves energy
  for (std::size_t i = 0; i < rv.kick.size(); ++i) {
    std::printf("  crossing %zu: |v+ - v-| under the momentum rule %.3e rad/s, dT qdot-rule %+.3e J, "
                "momentum rule %+.3e J\n", i, rv.kick[i], rv.dE_v[i], rv.dE_p[i]);
    EXPECT_GT(rv.kick[i], 1e-3);
    EXPECT_LT(rv.dE_v[i] * rv.dE_p[i], 0.0);
    EXPECT_LT(std::abs(rv.dE_v[i] + rv.dE_p[i]), 0.25 * std::max(std::abs(rv.dE_v[i]), std::abs(rv.dE_p[i])));
  }
  double e_first[2] = {0, 0}, e_last[2] = {0, 0}, eu_first = 0, eu_last = 0;
  for (double dt : {1e-3, 2.5e-4}) {
    const State ss = runFixed("symplectic", sc, kT, dt);
    const State se = runFixed("euler", sc, kT, dt);
    const double ep = stateError(ss, rp.end), ev = stateError(ss, rv.end), eu = stateError(se, rv.end);
    std::printf("alpha %.2f (%d crossings, gap %.3e) dt %.1e: symplectic vs momentum-rule %.3e vs qdot-rule %.3e; "
                "euler vs qdot-rule %.3e\n",
                alpha, rv.crossings, gap, dt, ep, ev, eu);
    (dt > 5e-4 ? e_first : e_last)[0] = ep;
    (dt > 5e-4 ? e_first : e_last)[1] = ev;
    (dt > 5e-4 ? eu_first : eu_last) = eu;
  }
  EXPECT_GT(e_first[0] / e_last[0], 2.8);   // order ~1 towards the momentum rule
  EXPECT_LT(e_last[0], 0.1 * gap);
  EXPECT_GT(e_last[1], 0.5 * gap);          // no convergence towards the ODE solution
  EXPECT_GT(eu_first / eu_last, 2.8);       // while euler converges to it
  EXPECT_LT(eu_last, 0.25 * gap);
}

INSTANTIATE_TEST_SUITE_P(Alpha, VariationalViaPointCrossing, ::testing::Values(0.5, 0.55),
                         [](const ::testing::TestParamInfo<double>& i) {
                           return "alpha" + std::to_string(static_cast<int>(std::lround(i.param * 100))) + "pct";
                         });

}  // namespace
}  // namespace redmax
