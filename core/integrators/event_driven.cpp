#include "core/integrators/event_driven.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/unilateral/unilateral.hpp"

namespace redmax {
namespace {

struct Side {
  int limit = 0;
  int sub = 0;  // 0: the lower bound, 1: the upper bound
  bool operator==(const Side& o) const { return limit == o.limit && sub == o.sub; }
};

double bound(const JointLimit& l, int sub) { return sub == 0 ? l.lower : l.upper; }
// signed distance from the bound (negative: beyond it) and its rate
double gap(const JointLimit& l, int sub, const State& s) {
  return sub == 0 ? s.q[l.coordinate] - l.lower : l.upper - s.q[l.coordinate];
}
double rate(const JointLimit& l, int sub, const State& s) { return sub == 0 ? s.qdot[l.coordinate] : -s.qdot[l.coordinate]; }

// sys without its unilateral constraints, the active sides locked at their bounds (rows after sys's own)
std::shared_ptr<System> phaseSystem(const System& sys, const std::vector<JointLimit>& limits,
                                    const std::vector<Side>& active) {
  auto p = std::make_shared<System>(sys);
  p->setUnilateral(nullptr);
  for (const Side& a : active)
    p->addConstraint(PrescribedCoordinate::makeLocked(sys.model(), limits[a.limit].coordinate,
                                                      bound(limits[a.limit], a.sub)));
  return p;
}

void addStats(IntegratorStats& to, const IntegratorStats& from) {
  to.steps += from.steps;
  to.rhs_evals += from.rhs_evals;
  to.jacobian_evals += from.jacobian_evals;
  to.failed_steps += from.failed_steps;
  to.reparameterizations += from.reparameterizations;
}

enum class Event { None, Crossing, Release };

}  // namespace

void advanceWithLimitEvents(const std::string& method, const IntegratorOptions& opt, const System& sys, State& s,
                            double t_out, double check_interval, IntegratorStats& stats, LimitEventCounts* counts) {
  const auto& u = sys.unilateral();
  if (!u) throw std::logic_error("advanceWithLimitEvents: the system has no unilateral constraints");
  if (!u->pairs().empty())
    throw std::invalid_argument("integrator '" + method +
                                "' takes hard joint limits (by event location) but not contact pairs; use bdf1 "
                                "(docs/contact.md §6)");
  if (!(check_interval > 0.0)) throw std::invalid_argument("advanceWithLimitEvents: check interval must be positive");
  const std::vector<JointLimit>& limits = u->limits();
  const UnilateralOptions& uo = u->options();
  const int nc0 = sys.numConstraintRows();
  LimitEventCounts local;
  LimitEventCounts& cnt = counts ? *counts : local;

  // sides sitting on their bound (not moving off it) start locked; a pulling one is released below
  std::vector<Side> active;
  for (int i = 0; i < static_cast<int>(limits.size()); ++i)
    for (int sub = 0; sub < 2; ++sub)
      if (gap(limits[i], sub, s) <= 1e-12 && rate(limits[i], sub, s) <= 1e-12) active.push_back({i, sub});

  // the event at state x of phase system P (None, a free side beyond its bound, or a locked side
  // whose torque would pull)
  auto eventAt = [&](const System& P, const State& x, std::vector<Side>* crossing, std::vector<Side>* release) {
    Event ev = Event::None;
    for (int i = 0; i < static_cast<int>(limits.size()); ++i)
      for (int sub = 0; sub < 2; ++sub) {
        const Side side{i, sub};
        if (std::find(active.begin(), active.end(), side) != active.end()) continue;
        if (gap(limits[i], sub, x) < 0.0) {
          ev = Event::Crossing;
          if (crossing) crossing->push_back(side);
        }
      }
    if (ev != Event::None || active.empty()) return ev;
    DynamicsWorkspace ws(P);
    P.forwardDynamics(x, ws);
    const double scale = 1e-10 * (1.0 + ws.lambda.cwiseAbs().maxCoeff());
    for (size_t j = 0; j < active.size(); ++j) {
      const double lam = ws.lambda[nc0 + static_cast<int>(j)];  // the torque the limit applies on its coordinate
      if ((active[j].sub == 0 && lam < -scale) || (active[j].sub == 1 && lam > scale)) {
        ev = Event::Release;
        if (release) release->push_back(active[j]);
      }
    }
    return ev;
  };

  int guard = 0;
  while (s.t < t_out) {
    if (++guard > 10'000'000) throw SimulationError(method + ": too many limit events", s.t, 0.0);
    std::shared_ptr<System> P = phaseSystem(sys, limits, active);
    // a locked side that pulls at the phase's start is released before integrating
    std::vector<Side> pull;
    if (eventAt(*P, s, nullptr, &pull) == Event::Release) {
      for (const Side& r : pull) active.erase(std::find(active.begin(), active.end(), r));
      cnt.releases += static_cast<long>(pull.size());
      continue;
    }
    std::unique_ptr<Integrator> inner = makeIntegrator(method, opt);
    bool phase_over = false;
    while (!phase_over && s.t < t_out) {
      const double tb = std::min(t_out, s.t + check_interval);
      State b = s;
      inner->advance(*P, b, tb);
      std::vector<Side> crossing, release;
      if (eventAt(*P, b, nullptr, nullptr) == Event::None) {
        s = b;
        continue;
      }
      // the event lies in (s.t, tb]: bisection on re-runs from s
      State lo = s;
      double hi = tb;
      while (hi - lo.t > 1e-12 * std::max(1.0, std::abs(hi))) {
        const double mid = 0.5 * (lo.t + hi);
        State m = lo;
        std::unique_ptr<Integrator> probe = makeIntegrator(method, opt);
        probe->advance(*P, m, mid);
        addStats(stats, probe->stats());
        ++cnt.bisections;
        if (eventAt(*P, m, nullptr, nullptr) == Event::None) lo = m;
        else hi = mid;
      }
      State e = lo;
      std::unique_ptr<Integrator> last = makeIntegrator(method, opt);
      last->advance(*P, e, hi);
      addStats(stats, last->stats());
      const Event ev = eventAt(*P, e, &crossing, &release);
      if (ev == Event::Crossing) {
        // impact: the contact QP at velocity level (A = M, the locks and the system's own rows kept)
        DynamicsWorkspace ws(*P);
        P->calcMassAndForce(e, ws);
        if (P->numConstraintRows() > 0) P->calcConstraints(e, ws);
        UnilateralRows rows;
        rows.h = 1.0;
        rows.Jn.setZero(static_cast<int>(crossing.size()), P->ndof());
        rows.Jt.resize(0, P->ndof());
        for (size_t r = 0; r < crossing.size(); ++r) {
          const JointLimit& l = limits[crossing[r].limit];
          UnilateralRows::Candidate c;
          c.limit = true;
          c.source = crossing[r].limit;
          c.sub = crossing[r].sub;
          c.gap = 0.0;
          c.approach = rate(l, c.sub, e);
          c.target = c.approach < -uo.restitution_threshold ? -l.restitution * c.approach : 0.0;
          rows.c.push_back(c);
          rows.Jn(static_cast<int>(r), l.coordinate) = c.sub == 0 ? 1.0 : -1.0;
        }
        const MatX& G = ws.G;
        const VecX b_rows = P->numConstraintRows() > 0 ? VecX(G * e.qdot) : VecX();
        e.qdot = solveUnilateralStep(ws.M, ws.M * e.qdot, P->numConstraintRows() > 0 ? G : MatX(), b_rows, rows, uo,
                                     nullptr, nullptr, nullptr);
        for (const Side& c : crossing) {
          const JointLimit& l = limits[c.limit];
          e.q[l.coordinate] = bound(l, c.sub);  // (beyond it by at most the located time's error)
          if (rate(l, c.sub, e) <= std::max(1e-12, 1e-9 * uo.restitution_threshold)) {
            e.qdot[l.coordinate] = 0.0;  // stopped: held from now on
            active.push_back(c);
          }
        }
        cnt.impacts += static_cast<long>(crossing.size());
      } else if (ev == Event::Release) {
        for (const Side& r : release) active.erase(std::find(active.begin(), active.end(), r));
        cnt.releases += static_cast<long>(release.size());
      }
      s = e;
      phase_over = true;
    }
    addStats(stats, inner->stats());
  }
  s.t = t_out;
}

}  // namespace redmax
