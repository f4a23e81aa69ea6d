#include "core/dynamics/system.hpp"

#include <atomic>
#include <cmath>

#include <Eigen/Dense>

#include "core/dynamics/skeleton_dynamics.hpp"

namespace redmax {

DynamicsWorkspace::DynamicsWorkspace(const Model& model) : sk(model), rid(model) {
  const int n = model.nr();
  M.setZero(n, n);
  f.setZero(n);
  K.setZero(n, n);
  D.setZero(n, n);
}

DynamicsWorkspace::DynamicsWorkspace(const System& system) : DynamicsWorkspace(system.model()) {
  const int n = system.ndof();
  M.setZero(n, n);
  f.setZero(n);
  K.setZero(n, n);
  D.setZero(n, n);
  system.bind(*this);
}

std::uint64_t System::Id::next() {
  // a counter, not a lock: ids only have to differ
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

System::System(Model model) : model_(std::move(model)), ndof_(model_.nr()) {}

void System::bind(DynamicsWorkspace& ws) const {
  if (ws.system_id == id_.value) return;
  ws.term_scratch.clear();
  ws.integrator.reset();
  for (const auto& t : terms_) ws.term_scratch.push_back(t->makeScratch(model_));
  ws.system_id = id_.value;
}

void System::addTerm(std::shared_ptr<const ForceTerm> term) {
  if (!term) throw ModelError("System::addTerm: null term");
  z_offset_.push_back(nz_);
  u_offset_.push_back(nu_);
  nz_ += term->numStates();
  nu_ += term->numControls();
  mass_terms_ = mass_terms_ || term->addsMass();
  terms_.push_back(std::move(term));
  id_.renew();
}

void System::replaceTerm(size_t i, std::shared_ptr<const ForceTerm> term) {
  if (!term || i >= terms_.size()) throw ModelError("System::replaceTerm: no term " + std::to_string(i) + " or a null term");
  if (term->numStates() != terms_[i]->numStates() || term->numControls() != terms_[i]->numControls())
    throw ModelError("System::replaceTerm: '" + term->name() + "' has other numbers of states or controls than '" +
                     terms_[i]->name() + "'");
  terms_[i] = std::move(term);
  mass_terms_ = false;
  for (const auto& t : terms_) mass_terms_ = mass_terms_ || t->addsMass();
  id_.renew();
}

std::vector<std::string> System::stateNames() const {
  std::vector<std::string> names;
  for (const auto& t : terms_)
    for (std::string& n : t->stateNames()) names.push_back(std::move(n));
  return names;
}

std::vector<std::string> System::controlNames() const {
  std::vector<std::string> names;
  for (const auto& t : terms_)
    for (std::string& n : t->controlNames()) names.push_back(std::move(n));
  return names;
}

void System::addController(std::shared_ptr<const Controller> c) {
  if (!c) throw ModelError("System::addController: null controller");
  controllers_.push_back(std::move(c));
  id_.renew();
}

void System::calcControls(const State& s_sk, DynamicsWorkspace& ws) const {
  if (nu_ == 0) return;
  if (controllers_.empty()) {
    if (ws.controls.size() != nu_) ws.controls.setZero(nu_);
    return;
  }
  ws.controls.setZero(nu_);
  for (const auto& c : controllers_) c->addControls(model_, s_sk, ws.sk, ws.controls);
}

void System::calcStateDerivativesHere(const State& s_sk, DynamicsWorkspace& ws) const {
  ws.zdot.setZero(nz_);
  for (size_t i = 0; i < terms_.size(); ++i) {
    const int m = terms_[i]->numStates();
    if (m > 0) terms_[i]->calcStateDerivatives(model_, s_sk, context(ws, i), ws.zdot.segment(z_offset_[i], m));
  }
}

void System::calcStateDerivatives(const State& s, DynamicsWorkspace& ws) const {
  if (nz_ == 0) {
    ws.zdot.resize(0);
    return;
  }
  if (s.z.size() != nz_)
    throw ModelError("System::calcStateDerivatives: state has " + std::to_string(s.z.size()) +
                     " auxiliary states, the system has " + std::to_string(nz_));
  calcStateDerivativesHere(kinematicsAndControls(s, ws), ws);
}

const State& System::kinematicsAndControls(const State& s, DynamicsWorkspace& ws) const {
  const State* s_sk = &s;
  if (map_) {
    expandInto(s, ws);
    s_sk = &ws.s_r;
  }
  calcSkeletonKinematics(*s_sk, ws);
  calcControls(*s_sk, ws);
  return *s_sk;
}

void System::equilibrateStates(State& s, DynamicsWorkspace& ws) const {
  if (nz_ == 0) return;
  if (s.z.size() != nz_) s.z = defaultState().z;
  for (size_t i = 0; i < terms_.size(); ++i) {
    const int m = terms_[i]->numStates();
    if (m == 0) continue;
    // each term at the states the terms before it left: kinematics and controls at s, a new
    // evaluation (no rates: equilibrium needs none)
    const State& s_sk = kinematicsAndControls(s, ws);
    VecX zi = s.z.segment(z_offset_[i], m);
    terms_[i]->equilibrateStates(model_, s_sk, context(ws, i), zi);
    s.z.segment(z_offset_[i], m) = zi;
  }
}

void System::calcSkeletonKinematics(const State& s, DynamicsWorkspace& ws) const {
  bind(ws);
  calcKinematics(model_, s, ws.sk);
  ++ws.evaluation;
  ws.has_mass = false;  // a new evaluation: M and f are not its own until calcMassAndForce
}

void System::calcSkeletonMassHere(DynamicsWorkspace& ws, MatX& M) const {
  if (forward_route == ForwardRoute::Dense)
    calcSkeletonMass(model_, ws.sk, M);
  else
    calcSkeletonMassCrba(model_, ws.sk, ws.fd, M);
}

void System::calcSkeletonForceHere(const State& s_sk, DynamicsWorkspace& ws, VecX& f) const {
  if (forward_route == ForwardRoute::Dense) {
    calcSkeletonForce(model_, s_sk, ws.sk, f);
    return;
  }
  // f_r = -(M_r 0 - f_r): Newton-Euler at qddot = 0, O(n) where J_mr^T (...) is O(n^2)
  ws.fd.qddot0.setZero(model_.nr());
  if (!ws.fd.rid || static_cast<int>(ws.fd.rid->jk.size()) != model_.nb()) ws.fd.rid.emplace(model_);
  recursiveIdForward(model_, s_sk, ws.fd.qddot0, *ws.fd.rid);
  recursiveIdBackward(model_, s_sk, *ws.fd.rid, f);
  f = -f;
}

ForwardRoute System::plannedForwardRoute() const {
  if (nc_ > 0 || map_ || n_extra_ > 0) return ForwardRoute::Dense;
  const bool mass_terms = mass_terms_;
  switch (forward_route) {
    case ForwardRoute::Dense: return ForwardRoute::Dense;
    case ForwardRoute::TreeSparse: return ForwardRoute::TreeSparse;
    case ForwardRoute::Articulated: return mass_terms ? ForwardRoute::Dense : ForwardRoute::Articulated;
    case ForwardRoute::Auto: break;
  }
  if (!mass_terms) return ForwardRoute::Articulated;
  return ndof_ >= kTreeSparseMinDof ? ForwardRoute::TreeSparse : ForwardRoute::Dense;
}

void System::addConstraint(std::shared_ptr<const Constraint> c) {
  if (!c) throw ModelError("System::addConstraint: null constraint");
  nc_ += c->rows();
  force_rows_ = force_rows_ || c->hasForceRows();
  id_.renew();
  constraints_.push_back(std::move(c));
}

void System::setUnilateral(std::shared_ptr<const UnilateralConstraints> u) {
  if (u && map_) throw ModelError("System::setUnilateral: hard unilateral constraints with a coordinate map are not supported");
  unilateral_ = std::move(u);
  id_.renew();
}

int System::addExtraCoordinates(int n) {
  if (n < 0) throw ModelError("System::addExtraCoordinates: negative count");
  if (map_) throw ModelError("System::addExtraCoordinates: not supported together with a coordinate map");
  const int first = ndof_;
  ndof_ += n;
  n_extra_ += n;
  id_.renew();
  return first;
}

void System::setCoordinateMap(std::shared_ptr<const CoordinateMap> map) {
  if (map && n_extra_ > 0)
    throw ModelError("System::setCoordinateMap: not supported together with extra coordinates");
  if (map && unilateral_)
    throw ModelError("System::setCoordinateMap: not supported together with hard unilateral constraints");
  if (map && map->nr() != model_.nr())
    throw ModelError("System::setCoordinateMap: map built for " + std::to_string(map->nr()) +
                     " coordinates, model has " + std::to_string(model_.nr()));
  map_ = std::move(map);
  id_.renew();
  ndof_ = map_ ? map_->nR() : model_.nr();
}

State System::defaultState() const {
  State s;
  s.q = map_ ? map_->reduce(model_.defaultQ()) : model_.defaultQ();
  s.q.conservativeResizeLike(VecX::Zero(ndof()));  // extra coordinates start at zero
  s.qdot = VecX::Zero(ndof());
  if (nz_ > 0) {
    s.z = VecX::Zero(nz_);
    for (size_t i = 0; i < terms_.size(); ++i) {
      const int m = terms_[i]->numStates();
      if (m > 0) terms_[i]->defaultStates(model_, s.z.segment(z_offset_[i], m));
    }
  }
  return s;
}

void System::expandInto(const State& s, DynamicsWorkspace& ws) const {
  ws.s_r.t = s.t;
  if (nz_ > 0) ws.s_r.z = s.z;
  map_->calc(s.q, s.qdot, ws.s_r.q, ws.s_r.qdot, ws.J_rR, ws.Jdot_rR);
}

State System::expandState(const State& s) const {
  if (!map_) return s;
  State r;
  r.t = s.t;
  r.z = s.z;
  MatX J, Jdot;
  map_->calc(s.q, s.qdot, r.q, r.qdot, J, Jdot);
  return r;
}

State System::reduceState(const State& s_r) const {
  if (!map_) return s_r;
  State s;
  s.t = s_r.t;
  s.z = s_r.z;
  s.q = map_->reduce(s_r.q);
  s.qdot = map_->reduce(s_r.qdot);
  return s;
}

int System::reparameterize(State& s) const {
  if (!map_) return reparameterizeJoints(model_, s);
  int count = 0;
  VecJ q, qd;
  for (const JointSlot& slot : model_.joints()) {
    if (slot.nq == 0) continue;
    // only joints entirely made of independent coordinates that drive no dependent one
    bool free = true;
    for (int k = 0; k < slot.nq && free; ++k) {
      const int r = slot.q_index + k;
      free = map_->reducedIndex(r) >= 0 && !map_->isArgument(r);
    }
    if (!free) continue;
    q.resize(slot.nq);
    qd.resize(slot.nq);
    for (int k = 0; k < slot.nq; ++k) {
      const int j = map_->reducedIndex(slot.q_index + k);
      q[k] = s.q[j];
      qd[k] = s.qdot[j];
    }
    if (!slot.joint.reparameterize(q, qd)) continue;
    for (int k = 0; k < slot.nq; ++k) {
      const int j = map_->reducedIndex(slot.q_index + k);
      s.q[j] = q[k];
      s.qdot[j] = qd[k];
    }
    ++count;
  }
  return count;
}

void System::calcMassAndForce(const State& s, DynamicsWorkspace& ws) const {
  if (nz_ > 0 && s.z.size() != nz_)
    throw ModelError("System::calcMassAndForce: state has " + std::to_string(s.z.size()) +
                     " auxiliary states, the system has " + std::to_string(nz_));
  if (!map_) {
    calcSkeletonKinematics(s, ws);
    calcControls(s, ws);
    if (n_extra_ == 0) {
      calcSkeletonMassHere(ws, ws.M);
      calcSkeletonForceHere(s, ws, ws.f);
    } else {
      // the skeleton fills the q_r block; terms own the extra coordinates' mass and force.
      // Assembled through the q_r scratch so M and f keep their size (no reallocation per call).
      const int nr = model_.nr();
      calcSkeletonMassHere(ws, ws.M_r);
      calcSkeletonForceHere(s, ws, ws.f_r);
      ws.M.setZero(ndof_, ndof_);
      ws.f.setZero(ndof_);
      ws.M.topLeftCorner(nr, nr) = ws.M_r;
      ws.f.head(nr) = ws.f_r;
    }
    if (!ws.loads.empty()) addExternalLoads(model_, ws.sk, ws.loads, ws.f);
    for (size_t i = 0; i < terms_.size(); ++i) {
      const TermContext ctx = context(ws, i);
      terms_[i]->addMass(model_, s, ctx, ws.M);
      terms_[i]->addForce(model_, s, ctx, ws.f);
    }
    ws.has_mass = true;
    return;
  }
  // skeleton and terms in q_r at the expanded state, then chained through J_rR [D Eq. 4.86]
  expandInto(s, ws);
  calcSkeletonKinematics(ws.s_r, ws);
  calcControls(ws.s_r, ws);
  calcSkeletonMassHere(ws, ws.M_r);
  calcSkeletonForceHere(ws.s_r, ws, ws.f_r);
  if (!ws.loads.empty()) addExternalLoads(model_, ws.sk, ws.loads, ws.f_r);
  for (size_t i = 0; i < terms_.size(); ++i) {
    const TermContext ctx = context(ws, i);
    terms_[i]->addMass(model_, ws.s_r, ctx, ws.M_r);
    terms_[i]->addForce(model_, ws.s_r, ctx, ws.f_r);
  }
  const MatX MJ = ws.M_r * ws.J_rR;
  ws.M.noalias() = ws.J_rR.transpose() * MJ;
  const VecX fr = ws.f_r - ws.M_r * (ws.Jdot_rR * s.qdot);
  ws.f.noalias() = ws.J_rR.transpose() * fr;
  ws.has_mass = true;
}

namespace {
// Mdot_r qdot_r of the bare skeleton (nr): per body Jdot_i^T M_i phi_i + J_i^T M_i Jdot_i qdot,
// the time derivative of M_r = sum_i J_i^T M_i J_i [D Eq. 4.18] along qdot; needs Stage::Velocity
void skeletonMassDotTimesVelocity(const Model& model, const State& s, const SkeletonWorkspace& sk, VecX& out) {
  const int nr = model.nr();
  out.setZero(nr);
  for (int i = 0; i < model.nb(); ++i) {
    const Body& b = model.bodies()[i];
    const auto Ji = sk.J_mr.middleRows<6>(6 * i);
    const auto Jdi = sk.Jdot_mr.middleRows<6>(6 * i);
    const Vec6 Mphi = b.M * sk.phi[i];
    const Vec6 MJdv = b.M * (Jdi * s.qdot.head(nr));
    for (int a : model.ancestors(i)) {
      const JointSlot& sa = model.joints()[a];
      if (sa.nq == 0) continue;
      out.segment(sa.q_index, sa.nq).noalias() += Jdi.middleCols(sa.q_index, sa.nq).transpose() * Mphi;
      out.segment(sa.q_index, sa.nq).noalias() += Ji.middleCols(sa.q_index, sa.nq).transpose() * MJdv;
    }
  }
}
}  // namespace

void System::calcMassDotTimesVelocity(const State& s, DynamicsWorkspace& ws, VecX& Mdot_v) const {
  const State& s_sk = map_ ? ws.s_r : s;
  VecX Mdot_r;
  skeletonMassDotTimesVelocity(model_, s_sk, ws.sk, Mdot_r);
  if (n_extra_ > 0) Mdot_r.conservativeResizeLike(VecX::Zero(ndof_));
  bind(ws);
  for (size_t i = 0; i < terms_.size(); ++i) terms_[i]->addMassDotTimesVelocity(model_, s_sk, context(ws, i), Mdot_r);
  if (!map_) {
    Mdot_v = std::move(Mdot_r);
    return;
  }
  // chain rule through q_r = g(q_R) (ws.J_rR, ws.Jdot_rR, ws.M_r from calcMassAndForce)
  Mdot_r.noalias() += ws.M_r * (ws.Jdot_rR * s.qdot);
  Mdot_v.noalias() = ws.J_rR.transpose() * Mdot_r;
  Mdot_v.noalias() += ws.Jdot_rR.transpose() * (ws.M_r * ws.s_r.qdot);
}

void System::calcSparseMatrices(const State& s, DynamicsWorkspace& ws, bool stiffness,
                                Eigen::SparseMatrix<double>& M, Eigen::SparseMatrix<double>& K,
                                Eigen::SparseMatrix<double>& D) const {
  if (map_) throw ModelError("System::calcSparseMatrices: not with a coordinate map");
  if (nz_ > 0 && s.z.size() != nz_)
    throw ModelError("System::calcSparseMatrices: state has " + std::to_string(s.z.size()) +
                     " auxiliary states, the system has " + std::to_string(nz_));
  const int nr = model_.nr();
  calcSkeletonKinematics(s, ws);
  calcControls(s, ws);
  calcSkeletonMassHere(ws, ws.M_r);
  calcSkeletonForceHere(s, ws, ws.f_r);
  ws.f.setZero(ndof_);
  ws.f.head(nr) = ws.f_r;
  if (!ws.loads.empty()) addExternalLoads(model_, ws.sk, ws.loads, ws.f);
  // the q_r block: the skeleton, joint springs and dampers, and every term whose matrices stay there
  ws.K_r.setZero(nr, nr);
  ws.D_r.setZero(nr, nr);
  if (stiffness) addJointStiffnessDamping(model_, ws.K_r, ws.D_r);
  ForceTerm::Triplets tM, tK, tD;
  for (size_t i = 0; i < terms_.size(); ++i) {
    const TermContext ctx = context(ws, i);
    terms_[i]->addForce(model_, s, ctx, ws.f);
    if (terms_[i]->addSparseMatrices(model_, s, ctx, stiffness, tM, tK, tD)) continue;
    if (!terms_[i]->matricesOnSkeletonOnly())
      throw std::logic_error("System::calcSparseMatrices: term '" + terms_[i]->name() +
                             "' reaches extra coordinates but has no sparse form");
    terms_[i]->addMass(model_, s, ctx, ws.M_r);
    if (stiffness) terms_[i]->addStiffnessDamping(model_, s, ctx, ws.K_r, ws.D_r);
  }
  auto dense = [nr](const MatX& A, ForceTerm::Triplets& t) {
    for (int j = 0; j < nr; ++j)
      for (int i = 0; i < nr; ++i)
        if (A(i, j) != 0.0) t.emplace_back(i, j, A(i, j));
  };
  dense(ws.M_r, tM);
  ws.has_mass = false;  // (ws.M is not this state's)
  M.resize(ndof_, ndof_);
  M.setFromTriplets(tM.begin(), tM.end());
  if (!stiffness) return;
  dense(ws.K_r, tK);
  dense(ws.D_r, tD);
  K.resize(ndof_, ndof_);
  K.setFromTriplets(tK.begin(), tK.end());
  D.resize(ndof_, ndof_);
  D.setFromTriplets(tD.begin(), tD.end());
}

void System::calcStiffnessDamping(const State& s, DynamicsWorkspace& ws) const {
  if (!map_) {
    ws.K.setZero(ndof(), ndof());
    ws.D.setZero(ndof(), ndof());
    addJointStiffnessDamping(model_, ws.K, ws.D);
    bind(ws);
    for (size_t i = 0; i < terms_.size(); ++i) terms_[i]->addStiffnessDamping(model_, s, context(ws, i), ws.K, ws.D);
    return;
  }
  // K_R = J^T K_r J, D_R = J^T D_r J. The derivatives of J_rR and Jdot_rR themselves are left
  // out, as the skeleton leaves out dM/dq and its velocity products: the implicit part covers
  // springs and dampers, the rest stays explicit.
  expandInto(s, ws);
  const int nr = model_.nr();
  ws.K_r.setZero(nr, nr);
  ws.D_r.setZero(nr, nr);
  addJointStiffnessDamping(model_, ws.K_r, ws.D_r);
  bind(ws);
  for (size_t i = 0; i < terms_.size(); ++i)
    terms_[i]->addStiffnessDamping(model_, ws.s_r, context(ws, i), ws.K_r, ws.D_r);
  ws.K.noalias() = ws.J_rR.transpose() * (ws.K_r * ws.J_rR);
  ws.D.noalias() = ws.J_rR.transpose() * (ws.D_r * ws.J_rR);
}

void System::calcConstraints(const State& s, DynamicsWorkspace& ws) const {
  ws.G.setZero(nc_, ndof());
  ws.rhs.setZero(nc_);
  ws.pos_err.setZero(nc_);
  ws.vel_err.setZero(nc_);
  if (!map_) {
    int row = 0;
    for (const auto& c : constraints_) {
      const int m = c->rows();
      // constraints act on q_r (the columns of extra coordinates stay zero) unless they say otherwise
      const int cols = c->actsOnExtraCoordinates() ? ndof() : model_.nr();
      c->calcAcceleration(model_, s, ws.sk, ws.G.block(row, 0, m, cols), ws.rhs.segment(row, m));
      c->calcErrors(model_, s, ws.sk, ws.pos_err.segment(row, m), ws.vel_err.segment(row, m));
      row += m;
    }
  } else {
    // constraints on q_r (reduced or maximal, [D Eq. 4.105]) chained through q_r = g(q_R):
    // G_r qddot_r = G_r J_rR qddot_R + G_r Jdot_rR qdot_R
    ws.G_r.setZero(nc_, model_.nr());
    ws.rhs_r.setZero(nc_);
    int row = 0;
    for (const auto& c : constraints_) {
      const int m = c->rows();
      c->calcAcceleration(model_, ws.s_r, ws.sk, ws.G_r.middleRows(row, m), ws.rhs_r.segment(row, m));
      c->calcErrors(model_, ws.s_r, ws.sk, ws.pos_err.segment(row, m), ws.vel_err.segment(row, m));
      row += m;
    }
    ws.G.noalias() = ws.G_r * ws.J_rR;
    ws.rhs = ws.rhs_r - ws.G_r * (ws.Jdot_rR * s.qdot);
  }
  const auto& st = stabilization;
  if (st.alpha != 0.0 || st.beta != 0.0)
    ws.rhs -= 2.0 * st.alpha * ws.vel_err + st.beta * st.beta * ws.pos_err;
}

VecX System::solveKKT(const MatX& M, const MatX& G, const VecX& a, const VecX& b, VecX* lambda) {
  return solveKKT(M, G, G, a, b, lambda);
}

VecX System::solveKKT(const MatX& M, const MatX& G, const MatX& H, const VecX& a, const VecX& b, VecX* lambda) {
  const int n = static_cast<int>(M.rows());
  const int m = static_cast<int>(G.rows());
  if (m == 0) {
    if (lambda) lambda->resize(0);
    return M.ldlt().solve(a);
  }
  // Schur complement on the SPD M: (G M^-1 H^T) lambda = G M^-1 a - b (symmetric when H = G). Falls
  // back to a full pivoted LU of the KKT matrix if M is not positive definite (massless chains).
  Eigen::LLT<MatX> llt(M);
  if (llt.info() == Eigen::Success) {
    const MatX MinvHt = llt.solve(H.transpose());
    const VecX Minva = llt.solve(a);
    const MatX S = G * MinvHt;
    const VecX lam = S.completeOrthogonalDecomposition().solve(G * Minva - b);
    if (lambda) *lambda = lam;
    return Minva - MinvHt * lam;
  }
  MatX A = MatX::Zero(n + m, n + m);
  A.topLeftCorner(n, n) = M;
  A.topRightCorner(n, m) = H.transpose();
  A.bottomLeftCorner(m, n) = G;
  VecX r(n + m);
  r << a, b;
  const VecX x = A.completeOrthogonalDecomposition().solve(r);
  if (lambda) *lambda = x.tail(m);
  return x.head(n);
}

bool System::forwardArticulated(const State& s, DynamicsWorkspace& ws, VecX& qddot) const {
  if (nz_ > 0 && s.z.size() != nz_)
    throw ModelError("System::forwardDynamics: state has " + std::to_string(s.z.size()) +
                     " auxiliary states, the system has " + std::to_string(nz_));
  bind(ws);
  VecX& tau = ws.fd.tau;
  tau.setZero(model_.nr());
  // the terms (none adds mass) and the loads as generalized forces, through J_mr; a bare
  // skeleton needs no J_mr at all
  if (!terms_.empty() || !ws.loads.empty() || !controllers_.empty()) {
    calcSkeletonKinematics(s, ws);
    calcControls(s, ws);
    if (!ws.loads.empty()) addExternalLoads(model_, ws.sk, ws.loads, tau);
    for (size_t i = 0; i < terms_.size(); ++i) terms_[i]->addForce(model_, s, context(ws, i), tau);
  }
  ws.has_mass = false;
  if (!articulatedBodyForward(model_, s, tau, ws.fd, qddot)) return false;
  if (nz_ > 0) calcStateDerivativesHere(s, ws);
  return true;
}

VecX System::forwardDynamics(const State& s, DynamicsWorkspace& ws) const {
  const ForwardRoute route = plannedForwardRoute();
  VecX qddot;
  if (route == ForwardRoute::Articulated) {
    ws.lambda.resize(0);
    if (forwardArticulated(s, ws, qddot)) {
      ws.last_route = ForwardRoute::Articulated;
      return qddot;
    }
  }
  calcMassAndForce(s, ws);
  // the auxiliary states' rates share this evaluation (the terms' scratch holds it)
  if (nz_ > 0) calcStateDerivativesHere(map_ ? ws.s_r : s, ws);
  if (nc_ == 0) {
    ws.lambda.resize(0);
    // TreeSparse only if the terms kept the tree's pattern and M is positive definite
    if (route == ForwardRoute::TreeSparse) {
      coordinateParents(model_, ws.fd.lambda);
      if (hasTreePattern(ws.M, ws.fd.lambda, ws.fd.stamp) && factorLTDL(ws.M, ws.fd.lambda, ws.fd.LD)) {
        qddot = ws.f;
        solveLTDL(ws.fd.LD, ws.fd.lambda, qddot);
        ws.last_route = ForwardRoute::TreeSparse;
        return qddot;
      }
    }
    ws.last_route = ForwardRoute::Dense;
    return ws.M.ldlt().solve(ws.f);
  }
  ws.last_route = ForwardRoute::Dense;
  calcConstraints(s, ws);
  if (force_rows_) {
    if (map_) throw ModelError("System::forwardDynamics: constraints with force rows (sliding friction) and a coordinate map");
    MatX H = ws.G;
    int row = 0;
    for (const auto& c : constraints_) {
      const int m = c->rows();
      const int cols = c->actsOnExtraCoordinates() ? ndof() : model_.nr();
      if (c->hasForceRows()) c->calcForceRows(model_, s, ws.sk, H.block(row, 0, m, cols));
      row += m;
    }
    return solveKKT(ws.M, ws.G, H, ws.f, ws.rhs, &ws.lambda);
  }
  return solveKKT(ws.M, ws.G, ws.f, ws.rhs, &ws.lambda);
}

VecX System::inverseDynamics(const State& s, const VecX& qddot, DynamicsWorkspace& ws) const {
  calcMassAndForce(s, ws);
  return ws.M * qddot - ws.f;
}

void System::inverseDynamicsRecursive(const State& s, const VecX& qddot, DynamicsWorkspace& ws, VecX& tau) const {
  if (map_ || n_extra_ > 0) {
    tau = inverseDynamics(s, qddot, ws);
    return;
  }
  beginInverseDynamics(s, qddot, ws);
  finishInverseDynamics(s, qddot, ws, tau);
}

void System::beginInverseDynamics(const State& s, const VecX& qddot, DynamicsWorkspace& ws) const {
  if (map_ || n_extra_ > 0)
    throw ModelError("System::beginInverseDynamics: not with a coordinate map or extra coordinates");
  if (nz_ > 0 && s.z.size() != nz_)
    throw ModelError("System::beginInverseDynamics: state has " + std::to_string(s.z.size()) +
                     " auxiliary states, the system has " + std::to_string(nz_));
  recursiveIdForward(model_, s, qddot, ws.rid);
  ws.has_mass = false;
}

void System::finishInverseDynamics(const State& s, const VecX& qddot, DynamicsWorkspace& ws, VecX& tau) const {
  bind(ws);
  RecursiveIdWorkspace& r = ws.rid;
  // external loads: wrenches the joints need not supply, Gamma(x_i)^T R^T f_w [D Eq. 3.14]
  for (const PointForce& p : ws.loads.point_forces) {
    if (p.body < 0) continue;
    const Vec3 f_i = r.E_wi[p.body].topLeftCorner<3, 3>().transpose() * p.force_w;
    r.w[p.body].head<3>() -= p.point_i.cross(f_i);
    r.w[p.body].tail<3>() -= f_i;
  }
  for (const BodyWrench& b : ws.loads.wrenches) {
    if (b.body < 0) continue;
    const Mat3 Rt = r.E_wi[b.body].topLeftCorner<3, 3>().transpose();
    r.w[b.body].head<3>() -= Rt * b.torque_w;
    r.w[b.body].tail<3>() -= Rt * b.force_w;
  }
  // the terms: J_mr and controls only when one of them needs them
  bool need_sk = nu_ > 0, mass_matrix = false;
  for (const auto& t : terms_) {
    need_sk = need_sk || t->idRoute() != TermIdRoute::Wrenches;
    mass_matrix = mass_matrix || t->idRoute() == TermIdRoute::MassMatrix;
  }
  if (need_sk) {
    calcSkeletonKinematics(s, ws);
    calcControls(s, ws);
  }
  const int nr = model_.nr();
  ws.tau_direct.setZero(nr);
  const BodyMotion motion = r.motion();
  for (size_t i = 0; i < terms_.size(); ++i)
    if (terms_[i]->idRoute() != TermIdRoute::MassMatrix)
      terms_[i]->addInverseDynamics(model_, s, qddot, context(ws, i), motion, r.w, ws.tau_direct);
  recursiveIdBackward(model_, s, r, tau);
  tau += ws.tau_direct;
  if (!mass_matrix) return;
  // terms without a recursive form: M_t qddot - f_t in the dynamics-stage buffers
  ws.M.setZero(nr, nr);
  ws.f.setZero(nr);
  for (size_t i = 0; i < terms_.size(); ++i) {
    if (terms_[i]->idRoute() != TermIdRoute::MassMatrix) continue;
    const TermContext ctx = context(ws, i);
    terms_[i]->addMass(model_, s, ctx, ws.M);
    terms_[i]->addForce(model_, s, ctx, ws.f);
  }
  tau.noalias() += ws.M * qddot;
  tau -= ws.f;
}

VecX System::prescribedForces(const DynamicsWorkspace& ws) const {
  VecX tau = VecX::Zero(ndof());
  if (ws.lambda.size() != nc_ || ws.G.rows() != nc_) return tau;
  int row = 0;
  for (const auto& c : constraints_) {
    const int m = c->rows();
    if (c->isPrescribed()) tau.noalias() -= ws.G.middleRows(row, m).transpose() * ws.lambda.segment(row, m);
    row += m;
  }
  return tau;
}

double System::projectPositions(State& s, DynamicsWorkspace& ws, double tol, int max_iter) const {
  if (nc_ == 0) return 0.0;
  const VecX zero = VecX::Zero(ndof());
  for (int it = 0;; ++it) {
    calcMassAndForce(s, ws);
    calcConstraints(s, ws);
    const double err = ws.pos_err.lpNorm<Eigen::Infinity>();
    if (err <= tol || it >= max_iter || !std::isfinite(err)) return err;
    // Newton step on C(q) = 0 of least kinetic metric |dq|_M (redundant rows: minimum norm)
    s.q += solveKKT(ws.M, ws.G, zero, -ws.pos_err, nullptr);
  }
}

double System::projectVelocities(State& s, DynamicsWorkspace& ws) const {
  if (nc_ == 0) return 0.0;
  calcMassAndForce(s, ws);
  calcConstraints(s, ws);
  const VecX dqdot = solveKKT(ws.M, ws.G, VecX::Zero(ndof()), -ws.vel_err, nullptr);
  s.qdot += dqdot;
  return (ws.vel_err + ws.G * dqdot).lpNorm<Eigen::Infinity>();
}

double System::kineticEnergy(const State& s, DynamicsWorkspace& ws) const {
  const State* sk_state = &s;
  if (map_) {
    expandInto(s, ws);
    sk_state = &ws.s_r;
  }
  calcSkeletonKinematics(*sk_state, ws);
  calcControls(*sk_state, ws);
  double T = skeletonKineticEnergy(model_, ws.sk);
  for (size_t i = 0; i < terms_.size(); ++i) T += terms_[i]->kineticEnergy(model_, *sk_state, context(ws, i));
  return T;
}

double System::potentialEnergy(const State& s, DynamicsWorkspace& ws) const {
  const State* sk_state = &s;
  if (map_) {
    expandInto(s, ws);
    sk_state = &ws.s_r;
  }
  calcSkeletonKinematics(*sk_state, ws);
  calcControls(*sk_state, ws);
  double V = skeletonPotentialEnergy(model_, *sk_state, ws.sk);
  if (!ws.loads.empty()) V += externalLoadsPotential(ws.sk, ws.loads);
  for (size_t i = 0; i < terms_.size(); ++i) V += terms_[i]->potentialEnergy(model_, *sk_state, context(ws, i));
  return V;
}

}  // namespace redmax
