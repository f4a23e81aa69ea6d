#include "core/skeleton/kinematics.hpp"

namespace redmax {

SkeletonWorkspace::SkeletonWorkspace(const Model& model) {
  const int nb = model.nb();
  jk.resize(nb);
  for (int i = 0; i < nb; ++i) jk[i].resize(model.joints()[i].nq);
  E_wi.assign(nb, Mat4::Identity());
  Ad_ip.assign(nb, Mat6::Identity());
  Ad_ij.resize(nb);
  for (int i = 0; i < nb; ++i) Ad_ij[i] = AdInv(model.joints()[i].E_mi);  // E_im = E_mi^-1
  J_mr.setZero(model.nm(), model.nr());
  phi.assign(nb, Vec6::Zero());
  psi.assign(nb, Vec6::Zero());
  Jdot_mr.setZero(model.nm(), model.nr());
}

void calcKinematics(const Model& model, const State& state, SkeletonWorkspace& ws) {
  const int nb = model.nb();
  for (int i = 0; i < nb; ++i) {
    const JointSlot& s = model.joints()[i];
    const VecJ q = state.q.segment(s.q_index, s.nq);
    const VecJ qd = state.qdot.segment(s.q_index, s.nq);
    JointKinematics& jk = ws.jk[i];
    s.joint.calc(q, qd, jk);

    // pose of body i in its parent: E_pi = E_pf Q E_mi   [D Eq. 4.5]
    const Mat4 E_pi = s.E_pf * jk.Q * s.E_mi;
    ws.E_wi[i] = s.parent >= 0 ? Mat4(ws.E_wi[s.parent] * E_pi) : E_pi;
    ws.Ad_ip[i] = AdInv(E_pi);

    // diagonal blocks: J(i,i) = Ad_ij S, Jdot(i,i) = Ad_ij Sdot  [D Alg. 2 lines 2-3]
    const int r = 6 * i;
    const int c = s.q_index;
    ws.J_mr.block(r, c, 6, s.nq).noalias() = ws.Ad_ij[i] * jk.S;
    ws.Jdot_mr.block(r, c, 6, s.nq).noalias() = ws.Ad_ij[i] * jk.Sdot;

    // relative twist of i w.r.t. its parent, in i: psi = Ad_ij S qdot
    ws.psi[i].noalias() = ws.J_mr.block(r, c, 6, s.nq) * qd;

    if (s.parent < 0) {
      ws.phi[i] = ws.psi[i];
      continue;
    }
    // twist recursion phi_i = Ad_ip phi_p + psi_i  [D Eq. 4.8]
    const int p = s.parent;
    ws.phi[i].noalias() = ws.Ad_ip[i] * ws.phi[p];
    ws.phi[i] += ws.psi[i];

    // off-diagonal blocks over the ancestors of the parent [D Alg. 2 lines 5-8]:
    //   J(i,a) = Ad_ip J(p,a),   Jdot(i,a) = Addot_ip J(p,a) + Ad_ip Jdot(p,a),
    // with Addot_ip = -ad(psi_i) Ad_ip because E_ip = E_pi^-1 and dE_pi/dt = E_pi [psi_i].
    const Mat6 Addot_ip = -ad(ws.psi[i]) * ws.Ad_ip[i];
    const int rp = 6 * p;
    for (int a : model.ancestors(p)) {
      const JointSlot& sa = model.joints()[a];
      if (sa.nq == 0) continue;
      const auto Jp = ws.J_mr.block(rp, sa.q_index, 6, sa.nq);
      const auto Jdp = ws.Jdot_mr.block(rp, sa.q_index, 6, sa.nq);
      ws.J_mr.block(r, sa.q_index, 6, sa.nq).noalias() = ws.Ad_ip[i] * Jp;
      ws.Jdot_mr.block(r, sa.q_index, 6, sa.nq).noalias() = Addot_ip * Jp + ws.Ad_ip[i] * Jdp;
    }
  }
  ws.stage = Stage::Velocity;
}

void calcBodyPoses(const Model& model, const VecX& q, std::vector<Mat4>& E_wi) {
  E_wi.resize(model.nb());
  JointKinematics jk;
  const VecJ zero = VecJ::Zero(6);
  for (int i = 0; i < model.nb(); ++i) {
    const JointSlot& s = model.joints()[i];
    s.joint.calc(q.segment(s.q_index, s.nq), zero.head(s.nq), jk);
    const Mat4 E_pi = s.E_pf * jk.Q * s.E_mi;
    E_wi[i] = s.parent >= 0 ? Mat4(E_wi[s.parent] * E_pi) : E_pi;
  }
}

Vec3 pointPosition(const SkeletonWorkspace& ws, int body, const Vec3& x_i) {
  return transformPoint(ws.E_wi[body], x_i);
}

Vec3 pointVelocity(const SkeletonWorkspace& ws, int body, const Vec3& x_i) {
  // [D Eq. 3.13]: xdot_w = R_i Gamma(x_i) phi_i
  return ws.E_wi[body].topLeftCorner<3, 3>() * (Gamma(x_i) * ws.phi[body]);
}

void pointJacobian(const Model& model, const SkeletonWorkspace& ws, int body, const Vec3& x_i,
                   Eigen::Ref<MatX> J) {
  J.setZero();
  const Mat3x6 RG = ws.E_wi[body].topLeftCorner<3, 3>() * Gamma(x_i);
  for (int a : model.ancestors(body)) {
    const JointSlot& sa = model.joints()[a];
    if (sa.nq == 0) continue;
    J.middleCols(sa.q_index, sa.nq).noalias() = RG * ws.J_mr.block(6 * body, sa.q_index, 6, sa.nq);
  }
}

int reparameterizeJoints(const Model& model, State& state) {
  int count = 0;
  for (const JointSlot& s : model.joints()) {
    if (s.nq == 0) continue;
    VecJ q = state.q.segment(s.q_index, s.nq);
    VecJ qd = state.qdot.segment(s.q_index, s.nq);
    if (s.joint.reparameterize(q, qd)) {
      state.q.segment(s.q_index, s.nq) = q;
      state.qdot.segment(s.q_index, s.nq) = qd;
      ++count;
    }
  }
  return count;
}

}  // namespace redmax
