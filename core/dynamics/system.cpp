#include "core/dynamics/system.hpp"

#include <Eigen/Dense>

#include "core/dynamics/skeleton_dynamics.hpp"

namespace redmax {

DynamicsWorkspace::DynamicsWorkspace(const Model& model) : sk(model) {
  const int n = model.nr();
  M.setZero(n, n);
  f.setZero(n);
  K.setZero(n, n);
  D.setZero(n, n);
}

System::System(Model model) : model_(std::move(model)) {}

void System::addConstraint(std::shared_ptr<const Constraint> c) {
  nc_ += c->rows();
  constraints_.push_back(std::move(c));
}

State System::defaultState() const {
  State s;
  s.q = model_.defaultQ();
  s.qdot = VecX::Zero(ndof());
  return s;
}

void System::calcMassAndForce(const State& s, DynamicsWorkspace& ws) const {
  calcKinematics(model_, s, ws.sk);
  calcSkeletonMass(model_, ws.sk, ws.M);
  calcSkeletonForce(model_, s, ws.sk, ws.f);
  for (const auto& t : terms_) {
    t->addMass(model_, s, ws.sk, ws.M);
    t->addForce(model_, s, ws.sk, ws.f);
  }
}

void System::calcStiffnessDamping(const State& s, DynamicsWorkspace& ws) const {
  ws.K.setZero(ndof(), ndof());
  ws.D.setZero(ndof(), ndof());
  addJointStiffnessDamping(model_, ws.K, ws.D);
  for (const auto& t : terms_) t->addStiffnessDamping(model_, s, ws.sk, ws.K, ws.D);
}

void System::calcConstraints(const State& s, DynamicsWorkspace& ws) const {
  ws.G.setZero(nc_, ndof());
  ws.rhs.setZero(nc_);
  ws.pos_err.setZero(nc_);
  ws.vel_err.setZero(nc_);
  int row = 0;
  for (const auto& c : constraints_) {
    const int m = c->rows();
    c->calcAcceleration(model_, s, ws.sk, ws.G.middleRows(row, m), ws.rhs.segment(row, m));
    c->calcErrors(model_, s, ws.sk, ws.pos_err.segment(row, m), ws.vel_err.segment(row, m));
    row += m;
  }
  const auto& st = stabilization;
  if (st.alpha != 0.0 || st.beta != 0.0)
    ws.rhs -= 2.0 * st.alpha * ws.vel_err + st.beta * st.beta * ws.pos_err;
}

VecX System::solveKKT(const MatX& M, const MatX& G, const VecX& a, const VecX& b, VecX* lambda) {
  const int n = static_cast<int>(M.rows());
  const int m = static_cast<int>(G.rows());
  if (m == 0) {
    if (lambda) lambda->resize(0);
    return M.ldlt().solve(a);
  }
  // Schur complement on the SPD M: (G M^-1 G^T) lambda = G M^-1 a - b. Falls back to a full
  // pivoted LU of the KKT matrix if M is not positive definite (massless chains).
  Eigen::LLT<MatX> llt(M);
  if (llt.info() == Eigen::Success) {
    const MatX MinvGt = llt.solve(G.transpose());
    const VecX Minva = llt.solve(a);
    const MatX S = G * MinvGt;
    const VecX lam = S.completeOrthogonalDecomposition().solve(G * Minva - b);
    if (lambda) *lambda = lam;
    return Minva - MinvGt * lam;
  }
  MatX A = MatX::Zero(n + m, n + m);
  A.topLeftCorner(n, n) = M;
  A.topRightCorner(n, m) = G.transpose();
  A.bottomLeftCorner(m, n) = G;
  VecX r(n + m);
  r << a, b;
  const VecX x = A.completeOrthogonalDecomposition().solve(r);
  if (lambda) *lambda = x.tail(m);
  return x.head(n);
}

VecX System::forwardDynamics(const State& s, DynamicsWorkspace& ws) const {
  calcMassAndForce(s, ws);
  if (nc_ == 0) {
    ws.lambda.resize(0);
    return ws.M.ldlt().solve(ws.f);
  }
  calcConstraints(s, ws);
  return solveKKT(ws.M, ws.G, ws.f, ws.rhs, &ws.lambda);
}

VecX System::inverseDynamics(const State& s, const VecX& qddot, DynamicsWorkspace& ws) const {
  calcMassAndForce(s, ws);
  return ws.M * qddot - ws.f;
}

double System::kineticEnergy(const State& s, DynamicsWorkspace& ws) const {
  calcKinematics(model_, s, ws.sk);
  double T = skeletonKineticEnergy(model_, ws.sk);
  for (const auto& t : terms_) T += t->kineticEnergy(model_, s, ws.sk);
  return T;
}

double System::potentialEnergy(const State& s, DynamicsWorkspace& ws) const {
  calcKinematics(model_, s, ws.sk);
  double V = skeletonPotentialEnergy(model_, s, ws.sk);
  for (const auto& t : terms_) V += t->potentialEnergy(model_, s, ws.sk);
  return V;
}

}  // namespace redmax
