#include "core/deformable/deformable_term.hpp"

#include <string>

#include "core/deformable/node_constraint.hpp"
#include "core/dynamics/system.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

DeformableTerm::DeformableTerm(const Model& model, DeformableBody body, std::vector<NodeBinding> nodes,
                               DeformableTermOptions options)
    : body_(std::move(body)), nodes_(std::move(nodes)), options_(options) {
  if (static_cast<int>(nodes_.size()) != body_.numNodes())
    throw ModelError("DeformableTerm: " + std::to_string(nodes_.size()) + " node bindings for " +
                     std::to_string(body_.numNodes()) + " nodes");
  if (body_.mass.size() != body_.rest.size()) throw ModelError("DeformableTerm: one mass per node expected");
  if (body_.node_mass.nonZeros() > 0 &&
      (body_.node_mass.rows() != body_.numNodes() || body_.node_mass.cols() != body_.numNodes()))
    throw ModelError("DeformableTerm: the node mass matrix is not N x N");
  Mx_ = nodeMassMatrix(body_);
  for (size_t n = 0; n < nodes_.size(); ++n) {
    const NodeBinding& b = nodes_[n];
    if (b.kind == NodeBinding::Kind::Body) {
      if (b.index < 0 || b.index >= model.nb())
        throw ModelError("DeformableTerm: node " + std::to_string(n) + " attached to body " + std::to_string(b.index) +
                         " of a model with " + std::to_string(model.nb()));
      has_body_nodes_ = true;
    } else if (b.kind == NodeBinding::Kind::Free && b.index < model.nr()) {
      throw ModelError("DeformableTerm: free node " + std::to_string(n) + " at coordinate " + std::to_string(b.index) +
                       ", inside the skeleton's " + std::to_string(model.nr()));
    }
  }
}

std::unique_ptr<TermScratch> DeformableTerm::makeScratch(const Model&) const {
  return std::make_unique<DeformableScratch>();
}

DeformableScratch& DeformableTerm::evaluate(const Model& model, const State& s, const TermContext& ctx,
                                            bool stiffness, DeformableScratch& local) const {
  auto* slot = dynamic_cast<DeformableScratch*>(ctx.scratch);
  DeformableScratch& sc = slot ? *slot : local;
  stiffness = stiffness || body_.rayleigh_stiffness != 0.0;  // the damping force needs K_x
  if (slot && ctx.evaluation != 0 && sc.evaluation == ctx.evaluation && (sc.has_K || !stiffness)) return sc;
  sc.evaluation = 0;
  const int N = body_.numNodes(), nr = model.nr();
  const SkeletonWorkspace& sk = ctx.sk;
  sc.x.resize(3 * N);
  sc.v.resize(3 * N);
  sc.J.resize(N);
  sc.Jdot.resize(N);
  const VecX qdot_r = s.qdot.head(nr);
  for (int n = 0; n < N; ++n) {
    const NodeBinding& b = nodes_[n];
    switch (b.kind) {
      case NodeBinding::Kind::Free:
        sc.x.segment<3>(3 * n) = s.q.segment<3>(b.index);
        sc.v.segment<3>(3 * n) = s.qdot.segment<3>(b.index);
        break;
      case NodeBinding::Kind::World:
        sc.x.segment<3>(3 * n) = b.point;
        sc.v.segment<3>(3 * n).setZero();
        break;
      case NodeBinding::Kind::Body: {
        // J_a = R Gamma(X) J_i [D Eq. 4.90], Jdot_a = R ([omega] Gamma(X) J_i + Gamma(X) Jdot_i) [D Eq. 4.91]
        sc.J[n].resize(3, nr);
        pointJacobian(model, sk, b.index, b.point, sc.J[n]);
        const Mat3 R = sk.E_wi[b.index].topLeftCorner<3, 3>();
        const Mat3x6 G = Gamma(b.point);
        const auto Ji = sk.J_mr.middleRows<6>(6 * b.index);
        const auto Jdi = sk.Jdot_mr.middleRows<6>(6 * b.index);
        sc.Jdot[n].noalias() = R * (skew(sk.phi[b.index].head<3>()) * (G * Ji) + G * Jdi);
        sc.x.segment<3>(3 * n) = transformPoint(sk.E_wi[b.index], b.point);
        sc.v.segment<3>(3 * n) = sc.J[n] * qdot_r;
        break;
      }
    }
  }
  evalElastic(body_, sc.x, stiffness, sc.el);
  sc.has_K = stiffness;
  // node forces: elastic, Rayleigh damping -(alpha M + beta K) v, gravity
  sc.F = sc.el.f;
  if (body_.rayleigh_mass != 0.0) sc.F.noalias() -= body_.rayleigh_mass * (Mx_ * sc.v);
  if (options_.gravity)
    for (int n = 0; n < N; ++n) sc.F.segment<3>(3 * n) += body_.mass[n] * model.gravity();  // M_x g: row sums
  if (body_.rayleigh_stiffness != 0.0) sc.F.noalias() -= body_.rayleigh_stiffness * (sc.el.K * sc.v);
  sc.evaluation = slot ? ctx.evaluation : 0;
  return sc;
}

void DeformableTerm::mapForce(const VecX& F, Eigen::Ref<VecX> f, const DeformableScratch& sc, int nr) const {
  for (int n = 0; n < body_.numNodes(); ++n) {
    const NodeBinding& b = nodes_[n];
    if (b.kind == NodeBinding::Kind::Free) f.segment<3>(b.index) += F.segment<3>(3 * n);
    else if (b.kind == NodeBinding::Kind::Body) f.head(nr).noalias() += sc.J[n].transpose() * F.segment<3>(3 * n);
  }
}

// J_MR^T A J_MR entry by entry: each non-zero a of A between node coordinates (i, j) lands on the
// coordinates the two nodes' rows map to: free-free one entry, free-attached a row or column of
// J_a over q_r, attached-attached the q_r block (world nodes nothing)
template <class FreeFree, class FreeBody, class BodyFree, class BodyBody>
void DeformableTerm::forEachMappedEntry(const SparseMat& A, const DeformableScratch& sc, FreeFree&& ff, FreeBody&& fb,
                                        BodyFree&& bf, BodyBody&& bb) const {
  using Kind = NodeBinding::Kind;
  for (int col = 0; col < A.outerSize(); ++col) {
    const int nj = col / 3, cj = col % 3;
    const NodeBinding& bj = nodes_[nj];
    if (bj.kind == Kind::World) continue;
    for (SparseMat::InnerIterator it(A, col); it; ++it) {
      const int ni = static_cast<int>(it.row()) / 3, ci = static_cast<int>(it.row()) % 3;
      const NodeBinding& bi = nodes_[ni];
      const double a = it.value();
      if (bi.kind == Kind::World) continue;
      if (bi.kind == Kind::Free && bj.kind == Kind::Free) ff(bi.index + ci, bj.index + cj, a);
      else if (bi.kind == Kind::Free) fb(bi.index + ci, sc.J[nj].row(cj), a);
      else if (bj.kind == Kind::Free) bf(sc.J[ni].row(ci), bj.index + cj, a);
      else bb(sc.J[ni].row(ci), sc.J[nj].row(cj), a);
    }
  }
}

void DeformableTerm::mapMatrix(const SparseMat& A, MatX& out, const DeformableScratch& sc, int nr) const {
  forEachMappedEntry(
      A, sc, [&](int i, int j, double a) { out(i, j) += a; },
      [&](int i, const auto& Jj, double a) { out.row(i).head(nr) += a * Jj; },
      [&](const auto& Ji, int j, double a) { out.col(j).head(nr) += a * Ji.transpose(); },
      [&](const auto& Ji, const auto& Jj, double a) { out.topLeftCorner(nr, nr).noalias() += a * Ji.transpose() * Jj; });
}

void DeformableTerm::mapMatrix(const SparseMat& A, Triplets& out, const DeformableScratch& sc, int nr) const {
  MatX rr = MatX::Zero(nr, nr);  // attached-attached pairs all land in the q_r block
  forEachMappedEntry(
      A, sc, [&](int i, int j, double a) { out.emplace_back(i, j, a); },
      [&](int i, const auto& Jj, double a) {
        for (int k = 0; k < nr; ++k)
          if (Jj[k] != 0.0) out.emplace_back(i, k, a * Jj[k]);
      },
      [&](const auto& Ji, int j, double a) {
        for (int k = 0; k < nr; ++k)
          if (Ji[k] != 0.0) out.emplace_back(k, j, a * Ji[k]);
      },
      [&](const auto& Ji, const auto& Jj, double a) { rr.noalias() += a * Ji.transpose() * Jj; });
  if (!has_body_nodes_) return;
  for (int j = 0; j < nr; ++j)
    for (int i = 0; i < nr; ++i)
      if (rr(i, j) != 0.0) out.emplace_back(i, j, rr(i, j));
}

SparseMat DeformableTerm::dampingMatrix(const DeformableScratch& sc) const {
  const int n3 = 3 * body_.numNodes();
  SparseMat D(n3, n3);
  if (body_.rayleigh_stiffness != 0.0) D = body_.rayleigh_stiffness * sc.el.K;
  if (body_.rayleigh_mass != 0.0) D += body_.rayleigh_mass * Mx_;
  return D;
}

void DeformableTerm::addMass(const Model& model, const State& s, const TermContext& ctx, MatX& M) const {
  DeformableScratch local;
  const DeformableScratch& sc = evaluate(model, s, ctx, false, local);
  mapMatrix(Mx_, M, sc, model.nr());
}

VecX DeformableTerm::nodeBiasAcceleration(const DeformableScratch& sc, const VecX& qdot_r) const {
  VecX a = VecX::Zero(3 * body_.numNodes());
  for (int n = 0; n < body_.numNodes(); ++n)
    if (nodes_[n].kind == NodeBinding::Kind::Body) a.segment<3>(3 * n).noalias() = sc.Jdot[n] * qdot_r;
  return a;
}

void DeformableTerm::addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const {
  DeformableScratch local;
  const DeformableScratch& sc = evaluate(model, s, ctx, false, local);
  const int nr = model.nr();
  mapForce(sc.F, f, sc, nr);
  // quadratic velocity vector of the attached nodes, -m J_a^T Jdot_a qdot [D Eq. 4.95]
  if (!options_.quadratic_velocity || !has_body_nodes_) return;
  // (with consistent mass a free node sharing a tet with attached ones takes its share too)
  mapForce(-(Mx_ * nodeBiasAcceleration(sc, s.qdot.head(nr))), f, sc, nr);
}

void DeformableTerm::addStiffnessDamping(const Model& model, const State& s, const TermContext& ctx, MatX& K,
                                         MatX& D) const {
  DeformableScratch local;
  const DeformableScratch& sc = evaluate(model, s, ctx, true, local);
  const int nr = model.nr();
  mapMatrix(sc.el.K, K, sc, nr);
  const SparseMat Dx = dampingMatrix(sc);
  mapMatrix(Dx, D, sc, nr);
  forEachAttachedStiffnessColumn(model, s, ctx, sc, Dx, static_cast<int>(K.rows()),
                                 [&](int k, const VecX& col) { K.col(k) += col; });
}

template <class Add>
void DeformableTerm::forEachAttachedStiffnessColumn(const Model& model, const State& s, const TermContext& ctx,
                                                    const DeformableScratch& sc, const SparseMat& Dx, int ndof,
                                                    Add&& add) const {
  if (!has_body_nodes_) return;
  // dJ_a/dq_k: the kinematics at (q, qdot = e_k) give Jdot_mr = dJ_mr/dq_k, and dR/dq_k = R [omega_k]
  const int nr = model.nr();
  const int N = body_.numNodes();
  SkeletonWorkspace tmp(model);
  State sk_state;
  sk_state.q = s.q.head(nr);
  const VecX qdot_r = s.qdot.head(nr);
  VecX dv(3 * N), col(ndof);
  for (int k = 0; k < nr; ++k) {
    sk_state.qdot = VecX::Unit(nr, k);
    calcKinematics(model, sk_state, tmp);
    dv.setZero();
    col.setZero();
    bool any = false;
    for (int n = 0; n < N; ++n) {
      const NodeBinding& b = nodes_[n];
      if (b.kind != NodeBinding::Kind::Body) continue;
      const auto Ji = ctx.sk.J_mr.middleRows<6>(6 * b.index);
      const Vec3 omega_k = Ji.col(k).head<3>();
      if (omega_k.isZero(0.0) && Ji.col(k).tail<3>().isZero(0.0) &&
          tmp.Jdot_mr.middleRows<6>(6 * b.index).isZero(0.0))
        continue;  // coordinate k does not move this body
      const Mat3 R = ctx.sk.E_wi[b.index].topLeftCorner<3, 3>();
      const Mat3x6 G = Gamma(b.point);
      const MatX dJ = R * (skew(omega_k) * (G * Ji) + G * tmp.Jdot_mr.middleRows<6>(6 * b.index));
      // geometric stiffness of the node's force: K(:, k) -= dJ^T f_a
      col.head(nr).noalias() -= dJ.transpose() * sc.F.segment<3>(3 * n);
      dv.segment<3>(3 * n) = dJ * qdot_r;
      any = true;
    }
    if (!any) continue;
    // the damping force -D_x v through v's dependence on q: K(:, k) += J_MR^T D_x dv
    if (Dx.nonZeros() != 0) mapForce(Dx * dv, col, sc, nr);
    add(k, col);
  }
}

bool DeformableTerm::addSparseMatrices(const Model& model, const State& s, const TermContext& ctx, bool stiffness,
                                       Triplets& M, Triplets& K, Triplets& D) const {
  DeformableScratch local;
  const DeformableScratch& sc = evaluate(model, s, ctx, stiffness, local);
  const int nr = model.nr();
  mapMatrix(Mx_, M, sc, nr);
  if (!stiffness) return true;
  mapMatrix(sc.el.K, K, sc, nr);
  const SparseMat Dx = dampingMatrix(sc);
  mapMatrix(Dx, D, sc, nr);
  forEachAttachedStiffnessColumn(model, s, ctx, sc, Dx, static_cast<int>(s.q.size()), [&](int k, const VecX& col) {
    for (int i = 0; i < col.size(); ++i)
      if (col[i] != 0.0) K.emplace_back(i, k, col[i]);
  });
  return true;
}

void DeformableTerm::addMassDotTimesVelocity(const Model& model, const State& s, const TermContext& ctx,
                                             VecX& Mdot_v) const {
  if (!has_body_nodes_) return;
  DeformableScratch local;
  const DeformableScratch& sc = evaluate(model, s, ctx, false, local);
  const int nr = model.nr();
  // d/dt (J_MR^T M_x J_MR) qdot = Jdot_MR^T M_x v + J_MR^T M_x Jdot_MR qdot (v = J_MR qdot: node velocities)
  const VecX Mv = Mx_ * sc.v;
  for (int n = 0; n < body_.numNodes(); ++n)
    if (nodes_[n].kind == NodeBinding::Kind::Body)
      Mdot_v.head(nr).noalias() += sc.Jdot[n].transpose() * Mv.segment<3>(3 * n);
  mapForce(Mx_ * nodeBiasAcceleration(sc, s.qdot.head(nr)), Mdot_v, sc, nr);
}

double DeformableTerm::kineticEnergy(const Model& model, const State& s, const TermContext& ctx) const {
  DeformableScratch local;
  const DeformableScratch& sc = evaluate(model, s, ctx, false, local);
  return 0.5 * sc.v.dot(Mx_ * sc.v);
}

double DeformableTerm::potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const {
  DeformableScratch local;
  const DeformableScratch& sc = evaluate(model, s, ctx, false, local);
  double V = sc.el.energy;
  if (options_.gravity)
    for (int n = 0; n < body_.numNodes(); ++n) V -= body_.mass[n] * model.gravity().dot(sc.x.segment<3>(3 * n));
  return V;
}

VecX DeformableTerm::nodePositions(const Model& model, const State& s, const TermContext& ctx) const {
  const int N = body_.numNodes();
  VecX x(3 * N);
  for (int n = 0; n < N; ++n) {
    const NodeBinding& b = nodes_[n];
    if (b.kind == NodeBinding::Kind::Free) x.segment<3>(3 * n) = s.q.segment<3>(b.index);
    else if (b.kind == NodeBinding::Kind::World) x.segment<3>(3 * n) = b.point;
    else x.segment<3>(3 * n) = transformPoint(ctx.sk.E_wi[b.index], b.point);
  }
  return x;
}

void DeformableTerm::setRestState(State& s) const {
  for (int n = 0; n < body_.numNodes(); ++n) {
    const NodeBinding& b = nodes_[n];
    if (b.kind != NodeBinding::Kind::Free) continue;
    s.q.segment<3>(b.index) = body_.rest[n];
    s.qdot.segment<3>(b.index).setZero();
  }
}

void DeformableTerm::setRestState(const Model& model, State& s, int follow) const {
  if (follow < 0 || follow >= model.nb()) throw ModelError("DeformableTerm::setRestState: no body " + std::to_string(follow));
  std::vector<Mat4> E0;
  calcBodyPoses(model, model.defaultQ(), E0);
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  const Mat4 E0_inv = inverseE(E0[follow]);
  for (int n = 0; n < body_.numNodes(); ++n) {
    const NodeBinding& b = nodes_[n];
    if (b.kind != NodeBinding::Kind::Free) continue;
    const Vec3 X = transformPoint(E0_inv, body_.rest[n]);
    s.q.segment<3>(b.index) = pointPosition(sk, follow, X);
    s.qdot.segment<3>(b.index) = pointVelocity(sk, follow, X);
  }
}

std::shared_ptr<const DeformableTerm> addDeformableBody(System& sys, DeformableBody body,
                                                        const std::vector<NodeAttachment>& attach,
                                                        DeformableTermOptions options, AttachBy attach_by) {
  const Model& model = sys.model();
  const int N = body.numNodes();
  std::vector<NodeBinding> nodes(N);
  std::vector<char> attached(N, 0);
  std::vector<Mat4> E_wi;
  calcBodyPoses(model, model.defaultQ(), E_wi);
  for (const NodeAttachment& a : attach) {
    if (a.node < 0 || a.node >= N) throw ModelError("addDeformableBody: attachment of node " + std::to_string(a.node) +
                                                    " of " + std::to_string(N));
    if (a.body < -1 || a.body >= model.nb())
      throw ModelError("addDeformableBody: attachment to body " + std::to_string(a.body) + " of " +
                       std::to_string(model.nb()));
    NodeBinding& b = nodes[a.node];
    if (a.body < 0) {
      b.kind = NodeBinding::Kind::World;
      b.point = body.rest[a.node];
    } else {
      b.kind = NodeBinding::Kind::Body;
      b.index = a.body;
      b.point = transformPoint(inverseE(E_wi[a.body]), body.rest[a.node]);
    }
    attached[a.node] = 1;
  }
  // with constraints, body-attached nodes keep coordinates of their own and are tied afterwards
  std::vector<NodeBinding> tied(N);
  if (attach_by == AttachBy::Constraint)
    for (int n = 0; n < N; ++n)
      if (nodes[n].kind == NodeBinding::Kind::Body) {
        tied[n] = nodes[n];
        attached[n] = 0;
      }
  int free = 0;
  for (int n = 0; n < N; ++n) free += attached[n] ? 0 : 1;
  int next = sys.addExtraCoordinates(3 * free);
  for (int n = 0; n < N; ++n)
    if (!attached[n]) {
      nodes[n].kind = NodeBinding::Kind::Free;
      nodes[n].index = next;
      next += 3;
    }
  auto term = std::make_shared<const DeformableTerm>(model, std::move(body), nodes, options);
  sys.addTerm(term);
  for (int n = 0; n < N; ++n)
    if (tied[n].kind == NodeBinding::Kind::Body)
      sys.addConstraint(std::make_shared<NodeConstraint>(model, nodes[n].index, tied[n].index, tied[n].point,
                                                         "node_" + std::to_string(n) + "_on_body_" +
                                                             std::to_string(tied[n].index)));
  return term;
}

PathPoint musclePointAtNode(const DeformableTerm& term, int node, std::string name) {
  const auto& nodes = term.nodes();
  if (node < 0 || node >= static_cast<int>(nodes.size()))
    throw ModelError("musclePointAtNode: node " + std::to_string(node) + " of a body with " +
                     std::to_string(nodes.size()) + " nodes");
  const NodeBinding& b = nodes[static_cast<size_t>(node)];
  switch (b.kind) {
    case NodeBinding::Kind::Free: return makeNodePoint(b.index, std::move(name));
    case NodeBinding::Kind::Body: return makeFixedPoint(b.index, b.point, std::move(name));
    case NodeBinding::Kind::World: break;
  }
  return makeFixedPoint(-1, b.point, std::move(name));
}

}  // namespace redmax
