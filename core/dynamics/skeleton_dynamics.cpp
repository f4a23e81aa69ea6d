#include "core/dynamics/skeleton_dynamics.hpp"

#include <vector>

namespace redmax {

void calcSkeletonMass(const Model& model, const SkeletonWorkspace& ws, MatX& M_r) {
  const int nr = model.nr();
  M_r.setZero(nr, nr);
  // sum over bodies of J_i^T M_i J_i, restricted to the columns of i's ancestors: gather those
  // columns into one compact 6 x k block so each body costs one product, then scatter back
  // (one small product per ancestor pair was cubic in chain length)
  Eigen::Matrix<double, 6, Eigen::Dynamic> Jc(6, nr), MJc(6, nr);
  MatX Mc(nr, nr);
  std::vector<int> cols;
  cols.reserve(nr);
  for (int i = 0; i < model.nb(); ++i) {
    cols.clear();
    for (int a : model.ancestors(i)) {
      const JointSlot& sa = model.joints()[a];
      for (int k = 0; k < sa.nq; ++k) cols.push_back(sa.q_index + k);
    }
    const int k = static_cast<int>(cols.size());
    if (k == 0) continue;
    for (int c = 0; c < k; ++c) Jc.col(c) = ws.J_mr.block<6, 1>(6 * i, cols[c]);
    MJc.leftCols(k).noalias() = model.bodies()[i].M * Jc.leftCols(k);
    Mc.topLeftCorner(k, k).noalias() = Jc.leftCols(k).transpose() * MJc.leftCols(k);
    for (int c = 0; c < k; ++c)
      for (int r = 0; r < k; ++r) M_r(cols[r], cols[c]) += Mc(r, c);
  }
}

void calcMaximalForce(const Model& model, const SkeletonWorkspace& ws, VecX& f_m) {
  f_m.resize(model.nm());
  for (int i = 0; i < model.nb(); ++i) {
    const Body& b = model.bodies()[i];
    const Vec6& phi = ws.phi[i];
    // Coriolis [D Eq. 3.21]
    Vec6 f = ad(phi).transpose() * (b.M * phi);
    // gravity at the COM, in body coordinates [D Eq. 3.22] with the general inertia
    const Vec3 g_i = ws.E_wi[i].topLeftCorner<3, 3>().transpose() * (b.mass * model.gravity());
    f += Gamma(b.com).transpose() * g_i;
    f_m.segment<6>(6 * i) = f;
  }
}

void calcSkeletonForce(const Model& model, const State& state, const SkeletonWorkspace& ws, VecX& f_r) {
  const int nr = model.nr();
  f_r.setZero(nr);
  for (int i = 0; i < model.nb(); ++i) {
    const Body& b = model.bodies()[i];
    const auto Ji = ws.J_mr.middleRows<6>(6 * i);
    const auto Jdi = ws.Jdot_mr.middleRows<6>(6 * i);
    const Vec6& phi = ws.phi[i];
    Vec6 f = ad(phi).transpose() * (b.M * phi);
    const Vec3 g_i = ws.E_wi[i].topLeftCorner<3, 3>().transpose() * (b.mass * model.gravity());
    f += Gamma(b.com).transpose() * g_i;
    // quadratic velocity vector -M_m Jdot_mr qdot [D Eq. 4.18]
    f.noalias() -= b.M * (Jdi * state.qdot.head(nr));
    for (int a : model.ancestors(i)) {
      const JointSlot& sa = model.joints()[a];
      if (sa.nq == 0) continue;
      f_r.segment(sa.q_index, sa.nq).noalias() += Ji.middleCols(sa.q_index, sa.nq).transpose() * f;
    }
  }
  // joint springs and dampers [D Eq. 4.75, 4.77]
  for (int k = 0; k < nr; ++k) {
    const Coordinate& c = model.coordinates()[k];
    f_r[k] += -c.stiffness * (state.q[k] - c.rest_value) - c.damping * state.qdot[k];
  }
}

void addJointStiffnessDamping(const Model& model, MatX& K_r, MatX& D_r) {
  for (int k = 0; k < model.nr(); ++k) {
    K_r(k, k) += model.coordinates()[k].stiffness;
    D_r(k, k) += model.coordinates()[k].damping;
  }
}

RecursiveIdWorkspace::RecursiveIdWorkspace(const Model& model) {
  const int nb = model.nb();
  jk.resize(nb);
  S_i.resize(nb);
  R_im.resize(nb);
  p_im.resize(nb);
  for (int i = 0; i < nb; ++i) {
    const int nq = model.joints()[i].nq;
    jk[i].resize(nq);
    S_i[i].setZero(6, nq);
    const Mat4 E_im = inverseE(model.joints()[i].E_mi);
    R_im[i] = E_im.topLeftCorner<3, 3>();
    p_im[i] = E_im.topRightCorner<3, 1>();
  }
  R_pi.assign(nb, Mat3::Identity());
  p_pi.assign(nb, Vec3::Zero());
  E_wi.assign(nb, Mat4::Identity());
  phi.assign(nb, Vec6::Zero());
  phidot.assign(nb, Vec6::Zero());
  w.assign(nb, Vec6::Zero());
}

void recursiveIdForward(const Model& model, const State& state, const VecX& qddot, RecursiveIdWorkspace& ws) {
  // body acceleration (body coordinates), from phi_i = Ad_ip phi_p + psi_i with
  // dAd_ip/dt = -ad(psi_i) Ad_ip:
  //   phidot_i = Ad_ip phidot_p - ad(psi_i) Ad_ip phi_p + Ad_ij (S qddot + Sdot qdot)
  // The adjoints act through their rotations and translations (adjointTimes & co.): a 6 x 6
  // adjoint costs 36 multiplies per product plus its construction, the (R, p) form about 24.
  const int nb = model.nb();
  for (int i = 0; i < nb; ++i) {
    const JointSlot& s = model.joints()[i];
    JointKinematics& jk = ws.jk[i];
    s.joint.calc(state.q.segment(s.q_index, s.nq), state.qdot.segment(s.q_index, s.nq), jk);
    // E_pi = E_pf Q E_mi as rotation and translation
    const Mat3 R_fm = s.E_pf.topLeftCorner<3, 3>() * jk.Q.topLeftCorner<3, 3>();
    const Vec3 p_fm = s.E_pf.topLeftCorner<3, 3>() * jk.Q.topRightCorner<3, 1>() + s.E_pf.topRightCorner<3, 1>();
    Mat3& R_pi = ws.R_pi[i];
    Vec3& p_pi = ws.p_pi[i];
    R_pi.noalias() = R_fm * s.E_mi.topLeftCorner<3, 3>();
    p_pi.noalias() = R_fm * s.E_mi.topRightCorner<3, 1>();
    p_pi += p_fm;
    const Mat3& R_im = ws.R_im[i];
    const Vec3& p_im = ws.p_im[i];
    auto& S_i = ws.S_i[i];
    for (int c = 0; c < s.nq; ++c) S_i.col(c) = adjointTimes(R_im, p_im, jk.S.col(c));
    const auto qd = state.qdot.segment(s.q_index, s.nq);
    const auto qdd = qddot.segment(s.q_index, s.nq);
    Vec6 psi = Vec6::Zero(), acc = Vec6::Zero();
    if (s.nq > 0) {
      psi.noalias() = S_i * qd;
      acc.noalias() = S_i * qdd;
      acc += adjointTimes(R_im, p_im, jk.Sdot * qd);
    }
    if (s.parent >= 0) {
      const int p = s.parent;
      const auto R_wp = ws.E_wi[p].topLeftCorner<3, 3>();
      ws.E_wi[i].topLeftCorner<3, 3>().noalias() = R_wp * R_pi;
      ws.E_wi[i].topRightCorner<3, 1>().noalias() = R_wp * p_pi;
      ws.E_wi[i].topRightCorner<3, 1>() += ws.E_wi[p].topRightCorner<3, 1>();
      const Vec6 phi_pi = adjointInvTimes(R_pi, p_pi, ws.phi[p]);
      ws.phi[i] = phi_pi + psi;
      ws.phidot[i] = adjointInvTimes(R_pi, p_pi, ws.phidot[p]) - adTimes(psi, phi_pi) + acc;
    } else {
      ws.E_wi[i].topLeftCorner<3, 3>() = R_pi;
      ws.E_wi[i].topRightCorner<3, 1>() = p_pi;
      ws.phi[i] = psi;
      ws.phidot[i] = acc;
    }
    // net wrench the body needs minus what gravity and Coriolis give [D Eq. 3.21]:
    // w = M phidot - ad(phi)^T M phi - Gamma(c)^T R^T m g, Gamma(c)^T f = (c x f; f)
    const Body& b = model.bodies()[i];
    const Vec3 g_i = ws.E_wi[i].topLeftCorner<3, 3>().transpose() * (b.mass * model.gravity());
    const Vec6 Mphi = b.M * ws.phi[i];
    Vec6& w = ws.w[i];
    w.noalias() = b.M * ws.phidot[i];
    w -= adTransposeTimes(ws.phi[i], Mphi);
    w.head<3>() -= b.com.cross(g_i);
    w.tail<3>() -= g_i;
  }
}

void recursiveIdBackward(const Model& model, const State& state, RecursiveIdWorkspace& ws, VecX& tau) {
  tau.resize(model.nr());
  for (int i = model.nb() - 1; i >= 0; --i) {
    const JointSlot& s = model.joints()[i];
    if (s.nq > 0) tau.segment(s.q_index, s.nq).noalias() = ws.S_i[i].transpose() * ws.w[i];
    // transmit to the parent: wrenches map with Ad^T
    if (s.parent >= 0) ws.w[s.parent] += adjointInvTransposeTimes(ws.R_pi[i], ws.p_pi[i], ws.w[i]);
  }
  for (int k = 0; k < model.nr(); ++k) {
    const Coordinate& c = model.coordinates()[k];
    tau[k] -= -c.stiffness * (state.q[k] - c.rest_value) - c.damping * state.qdot[k];
  }
}

void inverseDynamicsRecursive(const Model& model, const State& state, const VecX& qddot,
                              RecursiveIdWorkspace& ws, VecX& tau) {
  recursiveIdForward(model, state, qddot, ws);
  recursiveIdBackward(model, state, ws, tau);
}

VecX inverseDynamicsRecursive(const Model& model, const State& state, const VecX& qddot) {
  RecursiveIdWorkspace ws(model);
  VecX tau;
  inverseDynamicsRecursive(model, state, qddot, ws, tau);
  return tau;
}

double skeletonKineticEnergy(const Model& model, const SkeletonWorkspace& ws) {
  double T = 0.0;
  for (int i = 0; i < model.nb(); ++i) T += 0.5 * ws.phi[i].dot(model.bodies()[i].M * ws.phi[i]);
  return T;
}

double skeletonPotentialEnergy(const Model& model, const State& state, const SkeletonWorkspace& ws) {
  double V = 0.0;
  for (int i = 0; i < model.nb(); ++i) {
    const Body& b = model.bodies()[i];
    V -= b.mass * model.gravity().dot(transformPoint(ws.E_wi[i], b.com));
  }
  for (int k = 0; k < model.nr(); ++k) {
    const Coordinate& c = model.coordinates()[k];
    const double d = state.q[k] - c.rest_value;
    V += 0.5 * c.stiffness * d * d;
  }
  return V;
}

}  // namespace redmax
