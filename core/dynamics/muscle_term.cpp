#include "core/dynamics/muscle_term.hpp"

#include <algorithm>
#include <cmath>

#include "core/dynamics/muscle_force_term.hpp"
#include "core/dynamics/system.hpp"

namespace redmax {

namespace {

// no path-wise inverse dynamics for Type III paths, nor for fibre-following points (their placement
// moves with the fibre), nor for paths through deformable nodes (no body wrench carries a node's
// force): those take the compact J_ar route (with a_z)
// fibre-following points: the fibre's own motion adds the bias acceleration a_z to each point
bool hasFibreBias(const Muscle& m, const MuscleKinematics& mk) {
  return m.fibre.enabled() && mk.a_z.size() == 3 * m.mass_points.size();
}

}  // namespace

MuscleTerm::MuscleTerm(const Model& model, std::vector<Muscle> muscles, MuscleTermOptions options)
    : MuscleTerm(model, std::move(muscles), options, {}) {}

MuscleTerm::MuscleTerm(const Model& model, std::vector<Muscle> muscles, MuscleTermOptions options,
                       std::vector<MuscleStateIndex> states)
    : muscles_(std::move(muscles)), options_(options), nr_(model.nr()) {
  if (!states.empty() && states.size() != muscles_.size())
    throw ModelError("MuscleTerm: " + std::to_string(states.size()) + " state indices for " +
                     std::to_string(muscles_.size()) + " muscles");
  for (size_t k = 0; k < muscles_.size(); ++k) {
    const Muscle& m = muscles_[k];
    validateMuscle(model, m);
    if (m.mass_points.size() == 0) continue;
    massive_.push_back(m);
    compact_id_.push_back(pathwiseInverseDynamicsRefusal(m) != nullptr);
    massive_states_.push_back(states.empty() ? MuscleStateIndex{} : states[k]);
    for (double mass : m.mass_points.mass) adds_mass_ = adds_mass_ || mass != 0.0;
    node_points_ = node_points_ || hasNodePoints(m.path);
  }
}

std::unique_ptr<TermScratch> MuscleTerm::makeScratch(const Model& model) const {
  if (massive_.empty()) return nullptr;
  return std::make_unique<MuscleTermScratch>(model, massive_);
}

double MuscleTerm::totalMass() const {
  double m = 0.0;
  for (const Muscle& mu : massive_) m += mu.mass_points.totalMass();
  return m;
}

void MuscleTerm::kinematicsOf(size_t m, const Model& model, const State& s, const TermContext& ctx,
                              MuscleKinematics& mk) const {
  const Muscle& mu = massive_[m];
  if (!mu.fibre.enabled()) {
    calcMuscleKinematics(model, s, ctx.sk, mu, mk, true);
    return;
  }
  // fibre-following placement: the muscle's states in s.z, else its equilibrium
  const MuscleStateIndex& si = massive_states_[m];
  FibreStates fs;
  if (si.z >= 0 && si.z + mu.fibre.model->numStates() <= s.z.size()) fs.z = s.z.data() + si.z;
  if (si.u >= 0 && ctx.controls && si.u < ctx.controls->size()) fs.excitation = (*ctx.controls)[si.u];
  calcMuscleKinematics(model, s, ctx.sk, mu, mk, true, fs);
}

MuscleTermScratch& MuscleTerm::evaluate(const Model& model, const State& s, const TermContext& ctx,
                                        MuscleTermScratch& local) const {
  if (model.nr() != nr_)
    throw std::logic_error("MuscleTerm: built for a model with " + std::to_string(nr_) +
                           " coordinates, used with one with " + std::to_string(model.nr()));
  auto* slot = dynamic_cast<MuscleTermScratch*>(ctx.scratch);
  MuscleTermScratch& sc = slot ? *slot : local;
  // one evaluation serves addMass, addForce, Mdot qdot and the energies of the same state
  if (slot && ctx.evaluation != 0 && sc.evaluation == ctx.evaluation) return sc;
  sc.evaluation = 0;  // stays 0 if the evaluation throws
  if (sc.ws.muscles.size() != massive_.size()) sc.ws = MuscleWorkspace(model, massive_);
  for (size_t m = 0; m < massive_.size(); ++m) kinematicsOf(m, model, s, ctx, sc.ws.muscles[m]);
  sc.evaluation = slot ? ctx.evaluation : 0;
  return sc;
}

template <class Add>
void MuscleTerm::forEachMuscleMass(const Model& model, const State& s, const TermContext& ctx, Add&& add) const {
  MuscleTermScratch local;
  MuscleTermScratch& sc = evaluate(model, s, ctx, local);
  // J_ar^T M_a J_ar, M_a diagonal [D Eq. 5.7b]
  // one product per muscle on sqrt(m_a)-scaled rows, (W^1/2 J)^T (W^1/2 J) = J^T W J, in the
  // muscle's compact columns
  for (size_t m = 0; m < massive_.size(); ++m) {
    const MassPoints& mp = massive_[m].mass_points;
    const MuscleKinematics& mk = sc.ws.muscles[m];
    const MatX& J = mk.J_ar;
    sc.scaled_J.resize(J.rows(), J.cols());
    for (int a = 0; a < mp.size(); ++a) sc.scaled_J.middleRows<3>(3 * a) = std::sqrt(mp.mass[a]) * J.middleRows<3>(3 * a);
    sc.Mc.noalias() = sc.scaled_J.transpose() * sc.scaled_J;
    add(mk.cols, sc.Mc);
  }
}

void MuscleTerm::addMass(const Model& model, const State& s, const TermContext& ctx, MatX& M) const {
  if (massive_.empty()) return;
  forEachMuscleMass(model, s, ctx, [&M](const std::vector<int>& cols, const MatX& Mc) {
    const int k = static_cast<int>(cols.size());
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) M(cols[i], cols[j]) += Mc(i, j);
  });
}

bool MuscleTerm::addSparseMatrices(const Model& model, const State& s, const TermContext& ctx, bool, Triplets& M,
                                   Triplets&, Triplets&) const {
  if (!node_points_) return false;  // the q_r block: the dense addMass
  forEachMuscleMass(model, s, ctx, [&M](const std::vector<int>& cols, const MatX& Mc) {
    const int k = static_cast<int>(cols.size());
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) M.emplace_back(cols[i], cols[j], Mc(i, j));
  });
  return true;
}

void MuscleTerm::addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const {
  if (massive_.empty()) return;
  MuscleTermScratch local;
  MuscleTermScratch& sc = evaluate(model, s, ctx, local);
  // J_ar^T (f_a - M_a Jdot_ar qdot), f_a = m_a g [D Eq. 5.6, 5.7c], in compact columns
  for (size_t m = 0; m < massive_.size(); ++m) {
    const MassPoints& mp = massive_[m].mass_points;
    const MuscleKinematics& mk = sc.ws.muscles[m];
    gatherColumns(s.qdot, mk, sc.qdot_c);
    sc.fc.setZero(sc.qdot_c.size());
    const bool fibre = hasFibreBias(massive_[m], mk);
    for (int a = 0; a < mp.size(); ++a) {
      Vec3 fa = mp.mass[a] * model.gravity();
      if (options_.quadratic_velocity) fa.noalias() -= mp.mass[a] * (mk.Jdot_ar.middleRows<3>(3 * a) * sc.qdot_c);
      if (fibre) fa.noalias() -= mp.mass[a] * mk.a_z.segment<3>(3 * a);
      sc.fc.noalias() += mk.J_ar.middleRows<3>(3 * a).transpose() * fa;
    }
    scatterAddColumns(sc.fc, mk, f);
  }
}

void MuscleTerm::addMassDotTimesVelocity(const Model& model, const State& s, const TermContext& ctx,
                                         VecX& Mdot_v) const {
  if (massive_.empty()) return;
  MuscleTermScratch local;
  MuscleTermScratch& sc = evaluate(model, s, ctx, local);
  // d/dt (J_ar^T M_a J_ar) qdot with M_a constant [D Eq. 5.7b], in compact columns
  for (size_t m = 0; m < massive_.size(); ++m) {
    const MassPoints& mp = massive_[m].mass_points;
    const MuscleKinematics& mk = sc.ws.muscles[m];
    gatherColumns(s.qdot, mk, sc.qdot_c);
    sc.fc.setZero(sc.qdot_c.size());
    for (int a = 0; a < mp.size(); ++a) {
      const auto J = mk.J_ar.middleRows<3>(3 * a);
      const auto Jd = mk.Jdot_ar.middleRows<3>(3 * a);
      const Vec3 m_xdot = mp.mass[a] * (J * sc.qdot_c);
      const Vec3 m_Jdv = mp.mass[a] * (Jd * sc.qdot_c);
      sc.fc.noalias() += Jd.transpose() * m_xdot;
      sc.fc.noalias() += J.transpose() * m_Jdv;
    }
    scatterAddColumns(sc.fc, mk, Mdot_v);
  }
}

TermIdRoute MuscleTerm::idRoute() const {
  if (!options_.quadratic_velocity) return TermIdRoute::WrenchesWithKinematics;
  for (bool compact : compact_id_)
    if (compact) return TermIdRoute::WrenchesWithKinematics;
  return TermIdRoute::Wrenches;
}

void MuscleTerm::addInverseDynamics(const Model& model, const State& s, const VecX& qddot, const TermContext& ctx,
                                    const BodyMotion& motion, std::vector<Vec6>& wrench, VecX& tau) const {
  if (massive_.empty()) return;
  if (model.nr() != nr_)
    throw std::logic_error("MuscleTerm: built for a model with " + std::to_string(nr_) +
                           " coordinates, used with one with " + std::to_string(model.nr()));
  auto* slot = dynamic_cast<MuscleTermScratch*>(ctx.scratch);
  MuscleTermScratch local;
  MuscleTermScratch& sc = slot ? *slot : local;
  if (sc.ws.muscles.size() != massive_.size()) sc.ws = MuscleWorkspace(model, massive_);
  sc.id.resize(massive_.size());
  sc.evaluation = 0;  // the muscles' kinematics below are partial: no reuse by addMass & co.
  // the bodies' world motion serves the path-wise muscles only (with none, e.g. all Type III, skip it)
  const bool pathwise =
      options_.quadratic_velocity && std::find(compact_id_.begin(), compact_id_.end(), false) != compact_id_.end();
  if (pathwise) {
    calcBodyWorldMotion(motion, sc.bodies);
    sc.w_world.assign(wrench.size(), Vec6::Zero());  // (zeroed here: a muscle that threw may have left sums)
  }
  for (size_t m = 0; m < massive_.size(); ++m) {
    const Muscle& mu = massive_[m];
    MuscleKinematics& mk = sc.ws.muscles[m];
    if (pathwise && !compact_id_[m]) {
      addMuscleInverseDynamics(model, s, qddot, sc.bodies, model.gravity(), mu, mk, sc.id[m], sc.w_world, tau);
      continue;
    }
    // compact J_ar: sum_a J_ar^T m_a (J_ar qddot + Jdot_ar qdot (+ a_z) - g) in the muscle's columns
    kinematicsOf(m, model, s, ctx, mk);
    const bool fibre = hasFibreBias(mu, mk);
    gatherColumns(s.qdot, mk, sc.qdot_c);
    gatherColumns(qddot, mk, sc.qddot_c);
    sc.fc.setZero(sc.qdot_c.size());
    addCompactMuscleIdShare(mu.mass_points, mk, sc.qdot_c, sc.qddot_c, model.gravity(), options_.quadratic_velocity,
                            fibre, sc.fc);
    scatterAddColumns(sc.fc, mk, tau);
  }
  if (pathwise) addWorldWrenches(sc.bodies, sc.w_world, wrench);
}

double MuscleTerm::kineticEnergy(const Model& model, const State& s, const TermContext& ctx) const {
  if (massive_.empty()) return 0.0;
  MuscleTermScratch local;
  MuscleTermScratch& sc = evaluate(model, s, ctx, local);
  double T = 0.0;
  for (size_t m = 0; m < massive_.size(); ++m)
    T += muscleKineticEnergy(massive_[m].mass_points, sc.ws.muscles[m], s.qdot);
  return T;
}

double MuscleTerm::potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const {
  if (massive_.empty()) return 0.0;
  MuscleTermScratch local;
  MuscleTermScratch& sc = evaluate(model, s, ctx, local);
  double V = 0.0;
  for (size_t m = 0; m < massive_.size(); ++m)
    V += musclePotentialEnergy(massive_[m].mass_points, sc.ws.muscles[m], model.gravity());
  return V;
}

void MuscleTerm::takeWrapFallbackCounts(TermScratch* scratch, WrapFallbackMonitor& monitor) const {
  auto* sc = dynamic_cast<MuscleTermScratch*>(scratch);
  if (!sc) return;
  for (size_t k = 0; k < sc->ws.muscles.size() && k < massive_.size(); ++k) {
    WrapFallbackCounts& c = sc->ws.muscles[k].wrap_counts;
    monitor.add(massive_[k], c);
    c = {};
  }
}

std::vector<std::string> bindMuscleStates(System& sys) {
  std::vector<std::string> notes;
  int im = -1, iff = -1;
  for (size_t i = 0; i < sys.terms().size(); ++i) {
    if (dynamic_cast<const MuscleTerm*>(sys.terms()[i].get())) im = static_cast<int>(i);
    if (dynamic_cast<const MuscleForceTerm*>(sys.terms()[i].get())) iff = static_cast<int>(i);
  }
  if (im < 0 || iff < 0) return notes;
  const auto& term = static_cast<const MuscleTerm&>(*sys.terms()[im]);
  const auto& force = static_cast<const MuscleForceTerm&>(*sys.terms()[iff]);
  std::vector<Muscle> muscles = term.muscles();
  std::vector<MuscleStateIndex> states(muscles.size());
  bool any = false;
  for (size_t k = 0; k < muscles.size(); ++k) {
    Muscle& mu = muscles[k];
    if (!mu.fibre.enabled()) continue;
    const auto& act = force.actuated();
    const auto it = std::find_if(act.begin(), act.end(), [&](const auto& a) { return a.muscle.name == mu.name; });
    const std::string why = it == act.end() ? std::string("it exerts no force (no muscle model)")
                                            : fibrePlacementUnsupportedReason(mu, it->model.get());
    if (!why.empty()) {
      // uniform at the arc fractions the points had at the default pose
      mu.fibre = FibreFollowing{};
      notes.push_back("muscle '" + mu.name + "': mass placement uniform (" + why + ")");
      continue;
    }
    mu.fibre.model = it->model;
    mu.fibre.fiber_state = fiberStateIndex(*it->model);
    const size_t a = static_cast<size_t>(it - act.begin());
    states[k].z = sys.stateOffset(iff) + it->z_offset;
    states[k].u = sys.controlOffset(iff) + static_cast<int>(a);
    any = true;
  }
  if (!any && notes.empty()) return notes;
  sys.replaceTerm(im, std::make_shared<MuscleTerm>(sys.model(), std::move(muscles), term.options(), std::move(states)));
  return notes;
}

void takeWrapFallbackCounts(const System& sys, DynamicsWorkspace& ws, WrapFallbackMonitor& monitor) {
  if (ws.system_id != sys.id()) return;  // slots of another system (or none yet)
  for (size_t i = 0; i < sys.terms().size() && i < ws.term_scratch.size(); ++i)
    if (const auto* term = dynamic_cast<const MuscleTerm*>(sys.terms()[i].get()))
      term->takeWrapFallbackCounts(ws.term_scratch[i].get(), monitor);
}

}  // namespace redmax
