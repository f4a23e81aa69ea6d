#include "core/dynamics/muscle_term.hpp"

#include <cmath>

namespace redmax {

MuscleTerm::MuscleTerm(const Model& model, std::vector<Muscle> muscles, MuscleTermOptions options)
    : muscles_(std::move(muscles)), options_(options), nr_(model.nr()) {
  for (const Muscle& m : muscles_) {
    validateMuscle(model, m);
    if (m.mass_points.size() > 0) massive_.push_back(m);
  }
  ws_ = MuscleWorkspace(model, massive_);
}

double MuscleTerm::totalMass() const {
  double m = 0.0;
  for (const Muscle& mu : massive_) m += mu.mass_points.totalMass();
  return m;
}

void MuscleTerm::update(const Model& model, const State& s, const SkeletonWorkspace& sk) const {
  if (model.nr() != nr_)
    throw std::logic_error("MuscleTerm: built for a model with " + std::to_string(nr_) +
                           " coordinates, used with one with " + std::to_string(model.nr()));
  // one evaluation serves addMass, addForce and the energies of the same state
  if (cache_valid_ && q_cache_.size() == s.q.size() && qdot_cache_.size() == s.qdot.size() &&
      q_cache_ == s.q && qdot_cache_ == s.qdot)
    return;
  cache_valid_ = false;
  calcMuscleKinematics(model, s, sk, massive_, ws_, true);
  q_cache_ = s.q;
  qdot_cache_ = s.qdot;
  cache_valid_ = true;
}

void MuscleTerm::addMass(const Model& model, const State& s, const SkeletonWorkspace& sk, MatX& M) const {
  if (massive_.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  update(model, s, sk);
  // J_ar^T M_a J_ar, M_a diagonal [D Eq. 5.7b]
  // one product per muscle on sqrt(m_a)-scaled rows, (W^1/2 J)^T (W^1/2 J) = J^T W J, in the
  // muscle's compact columns, then scattered into M
  for (size_t m = 0; m < massive_.size(); ++m) {
    const MassPoints& mp = massive_[m].mass_points;
    const MuscleKinematics& mk = ws_.muscles[m];
    const MatX& J = mk.J_ar;
    scratch_.resize(J.rows(), J.cols());
    for (int a = 0; a < mp.size(); ++a) scratch_.middleRows<3>(3 * a) = std::sqrt(mp.mass[a]) * J.middleRows<3>(3 * a);
    Mc_.noalias() = scratch_.transpose() * scratch_;
    const int k = static_cast<int>(mk.cols.size());
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) M(mk.cols[i], mk.cols[j]) += Mc_(i, j);
  }
}

void MuscleTerm::addForce(const Model& model, const State& s, const SkeletonWorkspace& sk, VecX& f) const {
  if (massive_.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  update(model, s, sk);
  // J_ar^T (f_a - M_a Jdot_ar qdot), f_a = m_a g [D Eq. 5.6, 5.7c], in compact columns
  for (size_t m = 0; m < massive_.size(); ++m) {
    const MassPoints& mp = massive_[m].mass_points;
    const MuscleKinematics& mk = ws_.muscles[m];
    gatherColumns(s.qdot, mk, qdot_c_);
    fc_.setZero(qdot_c_.size());
    for (int a = 0; a < mp.size(); ++a) {
      Vec3 fa = mp.mass[a] * model.gravity();
      if (options_.quadratic_velocity) fa.noalias() -= mp.mass[a] * (mk.Jdot_ar.middleRows<3>(3 * a) * qdot_c_);
      fc_.noalias() += mk.J_ar.middleRows<3>(3 * a).transpose() * fa;
    }
    scatterAddColumns(fc_, mk, f);
  }
}

void MuscleTerm::addMassDotTimesVelocity(const Model& model, const State& s, const SkeletonWorkspace& sk,
                                         VecX& Mdot_v) const {
  if (massive_.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  update(model, s, sk);
  // d/dt (J_ar^T M_a J_ar) qdot with M_a constant [D Eq. 5.7b], in compact columns
  for (size_t m = 0; m < massive_.size(); ++m) {
    const MassPoints& mp = massive_[m].mass_points;
    const MuscleKinematics& mk = ws_.muscles[m];
    gatherColumns(s.qdot, mk, qdot_c_);
    fc_.setZero(qdot_c_.size());
    for (int a = 0; a < mp.size(); ++a) {
      const auto J = mk.J_ar.middleRows<3>(3 * a);
      const auto Jd = mk.Jdot_ar.middleRows<3>(3 * a);
      const Vec3 m_xdot = mp.mass[a] * (J * qdot_c_);
      const Vec3 m_Jdv = mp.mass[a] * (Jd * qdot_c_);
      fc_.noalias() += Jd.transpose() * m_xdot;
      fc_.noalias() += J.transpose() * m_Jdv;
    }
    scatterAddColumns(fc_, mk, Mdot_v);
  }
}

double MuscleTerm::kineticEnergy(const Model& model, const State& s, const SkeletonWorkspace& sk) const {
  if (massive_.empty()) return 0.0;
  std::lock_guard<std::mutex> lock(mutex_);
  update(model, s, sk);
  double T = 0.0;
  for (size_t m = 0; m < massive_.size(); ++m)
    T += muscleKineticEnergy(massive_[m].mass_points, ws_.muscles[m], s.qdot);
  return T;
}

double MuscleTerm::potentialEnergy(const Model& model, const State& s, const SkeletonWorkspace& sk) const {
  if (massive_.empty()) return 0.0;
  std::lock_guard<std::mutex> lock(mutex_);
  update(model, s, sk);
  double V = 0.0;
  for (size_t m = 0; m < massive_.size(); ++m)
    V += musclePotentialEnergy(massive_[m].mass_points, ws_.muscles[m], model.gravity());
  return V;
}

}  // namespace redmax
