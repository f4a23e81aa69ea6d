#include "core/integrators/event_driven.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/dynamics/unilateral/held_contacts.hpp"
#include "core/dynamics/unilateral/unilateral.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax {
namespace {

// a free point counts as beyond its surface below -kGapTol (m or rad), so that one released at
// zero gap with round-off on its gap does not re-enter at once; a sliding direction sticks when
// its speed passes zero by kSpeedTol (m/s or rad/s)
constexpr double kGapTol = 1e-12;
constexpr double kSpeedTol = 1e-12;
// mode changes at one instant before the run gives up (chattering, Painleve-like inconsistency)
constexpr int kMaxChangesAtOneInstant = 200;
// mode changes within kZenoWindow s of simulated time before the run gives up: events that
// accumulate (a body rocking or bouncing ever faster between points) would otherwise run for ever
constexpr int kMaxChangesInWindow = 300;
constexpr double kZenoWindow = 1e-3;

void addStats(IntegratorStats& to, const IntegratorStats& from) {
  to.steps += from.steps;
  to.rhs_evals += from.rhs_evals;
  to.jacobian_evals += from.jacobian_evals;
  to.failed_steps += from.failed_steps;
  to.reparameterizations += from.reparameterizations;
}

// what a check at one state found (indices into the candidates or the held list)
struct Found {
  std::vector<ContactKey> crossing;               // free points beyond their surface, approaching
  std::vector<std::pair<int, int>> stick;         // (held, direction) whose sliding speed passed zero
  std::vector<int> release;                       // held contacts whose normal force would pull
  std::vector<std::pair<int, int>> slip;          // (held, direction) outside the friction pyramid
  std::vector<int> slip_sign;                     // the sliding sign each slip starts with
  bool any() const { return !crossing.empty() || !stick.empty() || !release.empty() || !slip.empty(); }
};

class Driver {
 public:
  Driver(const System& sys, UnilateralEventCounts& cnt) : sys_(sys), model_(sys.model()), cnt_(cnt) {
    u_ = sys.unilateral();
    base_ = std::make_shared<System>(sys);
    base_->setUnilateral(nullptr);
    nc0_ = base_->numConstraintRows();
  }

  // points sitting on their surface (not moving off or into it) start held; the first check
  // releases those that pull and lets those that cannot stick slip
  void start(const State& s) {
    UnilateralRows rows;
    detectAt(s, rows);
    std::vector<int> idx;
    for (size_t i = 0; i < rows.c.size(); ++i)
      if (std::abs(rows.c[i].gap) <= kGapTol && std::abs(rows.c[i].approach) <= speedTol()) idx.push_back(static_cast<int>(i));
    held_ = classify(rows, idx, s.qdot);
  }

  void resume(const std::vector<HeldContact>& held) { held_ = held; }
  const std::vector<HeldContact>& held() const { return held_; }

  std::shared_ptr<System> phase() {
    auto p = std::make_shared<System>(*base_);
    held_c_.reset();
    if (!held_.empty()) {
      held_c_ = std::make_shared<HeldContacts>(u_, held_);
      p->addConstraint(held_c_);
    }
    return p;
  }

  Found check(const System& P, const State& x) {
    Found f;
    UnilateralRows rows;
    detectAt(x, rows);
    for (size_t i = 0; i < rows.c.size(); ++i) {
      const auto& c = rows.c[i];
      const int h = heldIndex(ContactKey::of(c));
      if (h < 0) {
        if (c.gap < -kGapTol && c.approach < 0.0) f.crossing.push_back(ContactKey::of(c));
        continue;
      }
      for (int k = 0; k < 2; ++k) {
        if (held_[h].slide[k] == 0) continue;
        const double w = rows.Jt.row(c.tangent_row + k).dot(x.qdot);
        if (w * held_[h].slide[k] < -kSpeedTol) f.stick.emplace_back(h, k);
      }
    }
    if (f.any() || held_.empty()) return f;
    DynamicsWorkspace ws(P);
    P.forwardDynamics(x, ws);
    const VecX& lam = ws.lambda;
    const double scale = 1e-10 * (1.0 + lam.cwiseAbs().maxCoeff());
    for (size_t h = 0; h < held_.size(); ++h) {
      int r = nc0_ + held_c_->firstRow(static_cast<int>(h));
      const double pn = -lam[r++];  // the contact force along the row (System: M qddot = f - G^T lambda)
      if (pn < -scale) {
        f.release.push_back(static_cast<int>(h));
        continue;
      }
      if (held_[h].mu == 0.0) continue;
      for (int k = 0; k < 2; ++k) {
        if (held_[h].slide[k] != 0) continue;
        const double pt = -lam[r++];
        if (std::abs(pt) > held_[h].mu * std::max(pn, 0.0) + scale) {
          f.slip.emplace_back(static_cast<int>(h), k);
          f.slip_sign.push_back(pt > 0.0 ? -1 : 1);  // it slides against the force that held it
        }
      }
    }
    return f;
  }

  // change the modes as f says (impacts first; releases before slips, whose forces assumed them
  // held), then project s onto the new held set
  void apply(State& s, const Found& f) {
    if (!f.crossing.empty()) {
      impact(s, f.crossing);
    } else if (!f.stick.empty()) {
      for (const auto& [h, k] : f.stick) held_[h].slide[k] = 0;
      cnt_.sticks += static_cast<long>(f.stick.size());
    } else if (!f.release.empty()) {
      for (auto it = f.release.rbegin(); it != f.release.rend(); ++it) held_.erase(held_.begin() + *it);
      cnt_.releases += static_cast<long>(f.release.size());
    } else {
      for (size_t j = 0; j < f.slip.size(); ++j) held_[f.slip[j].first].slide[f.slip[j].second] = f.slip_sign[j];
      cnt_.slips += static_cast<long>(f.slip.size());
    }
    std::shared_ptr<System> P = phase();
    if (P->numConstraintRows() > 0) {
      DynamicsWorkspace ws(*P);
      P->projectPositions(s, ws);
      P->projectVelocities(s, ws);
    }
  }

 private:
  double speedTol() const {
    // the QP's regularisation leaves stopped rows at about 1e-9 of the speeds involved
    return std::max(1e-9, 1e-6 * u_->options().restitution_threshold);
  }

  void detectAt(const State& x, UnilateralRows& rows) {
    SkeletonWorkspace sk(model_);
    calcKinematics(model_, x, sk);
    u_->detect(model_, x, sk, sys_.ndof(), 1.0, rows);
  }

 public:
  // the deepest penetration of an accepted state (not of the checks beyond an event)
  void notePenetration(const State& x) {
    UnilateralRows rows;
    detectAt(x, rows);
    cnt_.max_penetration = std::max(cnt_.max_penetration, rows.max_penetration);
  }

 private:

  int heldIndex(const ContactKey& key) const {
    for (size_t h = 0; h < held_.size(); ++h)
      if (held_[h].key == key) return static_cast<int>(h);
    return -1;
  }

  // held contacts from candidates idx of rows at velocity qdot: sticking where a tangential speed is
  // zero, sliding with its sign elsewhere
  std::vector<HeldContact> classify(const UnilateralRows& rows, const std::vector<int>& idx, const VecX& qdot) const {
    std::vector<HeldContact> out;
    for (int i : idx) {
      const auto& c = rows.c[i];
      HeldContact h;
      h.key = ContactKey::of(c);
      h.mu = c.limit ? 0.0 : c.mu;
      if (h.mu > 0.0)
        for (int k = 0; k < 2; ++k) {
          const double w = rows.Jt.row(c.tangent_row + k).dot(qdot);
          h.slide[k] = std::abs(w) <= speedTol() ? 0 : (w > 0.0 ? 1 : -1);
        }
      out.push_back(h);
    }
    return out;
  }

  // the contact QP at velocity level over the held points and those crossing
  void impact(State& s, const std::vector<ContactKey>& crossing) {
    UnilateralRows rows;
    detectAt(s, rows);
    const UnilateralOptions& uo = u_->options();
    UnilateralRows imp;
    imp.h = 1.0;
    std::vector<int> sel;
    std::vector<VecX> jn, jt;
    for (size_t i = 0; i < rows.c.size(); ++i) {
      const ContactKey key = ContactKey::of(rows.c[i]);
      const bool crosses = std::find(crossing.begin(), crossing.end(), key) != crossing.end();
      if (!crosses && heldIndex(key) < 0) continue;
      UnilateralRows::Candidate c = rows.c[i];
      const double e = c.limit ? u_->limits()[c.source].restitution : u_->pairs()[c.source].restitution;
      c.gap = 0.0;
      c.target = crosses && c.approach < -uo.restitution_threshold ? -e * c.approach : 0.0;
      if (c.tangent_row >= 0) {
        const int t = c.tangent_row;
        c.tangent_row = static_cast<int>(jt.size());
        jt.push_back(rows.Jt.row(t).transpose());
        jt.push_back(rows.Jt.row(t + 1).transpose());
      }
      jn.push_back(rows.Jn.row(static_cast<int>(i)).transpose());
      imp.c.push_back(c);
      sel.push_back(static_cast<int>(imp.c.size()) - 1);
    }
    const int n = sys_.ndof();
    imp.Jn.resize(static_cast<int>(jn.size()), n);
    for (size_t k = 0; k < jn.size(); ++k) imp.Jn.row(static_cast<int>(k)) = jn[k].transpose();
    imp.Jt.resize(static_cast<int>(jt.size()), n);
    for (size_t k = 0; k < jt.size(); ++k) imp.Jt.row(static_cast<int>(k)) = jt[k].transpose();

    DynamicsWorkspace ws(*base_);
    base_->calcMassAndForce(s, ws);
    MatX G;
    VecX b;
    if (nc0_ > 0) {
      base_->calcConstraints(s, ws);
      G = ws.G;
      b = G * s.qdot;
    }
    // a slow impact (none of the crossing points above the restitution threshold) holds every
    // point it involves: the velocity-level QP would let a held point lift off at the speed of the
    // impact, and a body rocking between two points would then impact again within microseconds
    // without end (Zeno); lift-off is left to the release check, where the normal force decides it
    double fastest = 0.0;
    for (int j : sel)
      if (std::find(crossing.begin(), crossing.end(), ContactKey::of(imp.c[j])) != crossing.end())
        fastest = std::max(fastest, -imp.c[j].approach);
    const bool slow = fastest < uo.restitution_threshold;
    if (slow) {
      MatX Ge(G.rows() + imp.Jn.rows(), n);
      if (G.rows() > 0) Ge.topRows(G.rows()) = G;
      Ge.bottomRows(imp.Jn.rows()) = imp.Jn;
      VecX be = VecX::Zero(Ge.rows());
      if (G.rows() > 0) be.head(G.rows()) = b;
      s.qdot = System::solveKKT(ws.M, Ge, ws.M * s.qdot, be, nullptr);
    } else {
      s.qdot = solveUnilateralStep(ws.M, ws.M * s.qdot, G, b, imp, uo, nullptr, nullptr, nullptr);
    }
    cnt_.impacts += static_cast<long>(crossing.size());
    // held from now on: the points that stopped (the rest leave their surfaces)
    std::vector<int> stopped;
    for (int j : sel)
      if (slow || imp.Jn.row(j).dot(s.qdot) <= speedTol()) stopped.push_back(j);
    held_ = classify(imp, stopped, s.qdot);
  }

  const System& sys_;
  const Model& model_;
  UnilateralEventCounts& cnt_;
  std::shared_ptr<const UnilateralConstraints> u_;
  std::shared_ptr<System> base_;
  int nc0_ = 0;
  std::vector<HeldContact> held_;
  std::shared_ptr<HeldContacts> held_c_;
};

}  // namespace

void advanceWithUnilateralEvents(const std::string& method, const IntegratorOptions& opt, const System& sys,
                                 State& s, double t_out, double check_interval, IntegratorStats& stats,
                                 UnilateralEventCounts* counts, EventMemory* memory) {
  const auto& u = sys.unilateral();
  if (!u) throw std::logic_error("advanceWithUnilateralEvents: the system has no unilateral constraints");
  if (!u->pairs().empty() && sys.ndof() != sys.model().nr())
    throw std::invalid_argument("integrator '" + method +
                                "' takes contact pairs by event location only on systems without extra coordinates; "
                                "use bdf1 (docs/contact.md §6)");
  if (!(check_interval > 0.0)) throw std::invalid_argument("advanceWithUnilateralEvents: check interval must be positive");
  UnilateralEventCounts local;
  UnilateralEventCounts& cnt = counts ? *counts : local;
  Driver d(sys, cnt);
  if (memory && memory->sys == &sys && memory->end.t == s.t && memory->end.q == s.q && memory->end.qdot == s.qdot &&
      memory->end.z == s.z)
    d.resume(memory->held);
  else
    d.start(s);
  d.notePenetration(s);

  // the times of the last kMaxChangesInWindow + 1 mode changes: chattering at one instant and
  // events accumulating over a short time are both read off them
  std::deque<double> changes;
  while (s.t < t_out) {
    std::shared_ptr<System> P = d.phase();
    const Found here = d.check(*P, s);
    if (here.any()) {
      changes.push_back(s.t);
      if (changes.size() > static_cast<size_t>(kMaxChangesInWindow) + 1) changes.pop_front();
      if (changes.size() > static_cast<size_t>(kMaxChangesAtOneInstant) &&
          changes[changes.size() - 1 - kMaxChangesAtOneInstant] == s.t) {
        std::ostringstream os;
        os << method << ": the contact modes do not settle at t = " << s.t << " (" << kMaxChangesAtOneInstant
           << " changes at one instant: chattering or a frictional inconsistency); use bdf1";
        throw SimulationError(os.str(), s.t, 0.0);
      }
      if (changes.size() == static_cast<size_t>(kMaxChangesInWindow) + 1 && s.t - changes.front() < kZenoWindow) {
        std::ostringstream os;
        os << method << ": the contact modes changed " << kMaxChangesInWindow << " times between t = "
           << changes.front() << " and t = " << s.t << " (events accumulating: a body rocking or bouncing ever "
           << "faster between contact points); use bdf1";
        throw SimulationError(os.str(), s.t, 0.0);
      }
      d.apply(s, here);
      d.notePenetration(s);
      continue;
    }
    std::unique_ptr<Integrator> inner = makeIntegrator(method, opt);
    bool phase_over = false;
    while (!phase_over && s.t < t_out) {
      const double tb = std::min(t_out, s.t + check_interval);
      State b = s;
      inner->advance(*P, b, tb);
      if (!d.check(*P, b).any()) {
        s = b;
        d.notePenetration(s);
        continue;
      }
      // the event lies in (s.t, tb]: bisection on re-runs from the last state without one. The
      // run stops at the state in which the event was seen (not a re-run to the same time: near a
      // slow crossing two runs' positions differ by their integration error, more than the gap
      // tolerance, and a re-run may miss the event and find it again 1e-12 s later, for ever)
      State lo = s;
      State at_hi = b;
      double hi = tb;
      while (hi - lo.t > 1e-12 * std::max(1.0, std::abs(hi))) {
        const double mid = 0.5 * (lo.t + hi);
        State m = lo;
        std::unique_ptr<Integrator> probe = makeIntegrator(method, opt);
        probe->advance(*P, m, mid);
        addStats(stats, probe->stats());
        ++cnt.bisections;
        if (!d.check(*P, m).any()) {
          lo = std::move(m);
        } else {
          hi = mid;
          at_hi = std::move(m);
        }
      }
      s = std::move(at_hi);  // the next pass applies the event found here
      d.notePenetration(s);
      phase_over = true;
    }
    addStats(stats, inner->stats());
  }
  s.t = t_out;
  if (memory) {
    memory->sys = &sys;
    memory->end = s;
    memory->held = d.held();
  }
}

}  // namespace redmax
