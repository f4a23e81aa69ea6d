#include "core/dynamics/structured_forward.hpp"

#include <cmath>

#include <Eigen/Cholesky>

namespace redmax {

const char* forwardRouteName(ForwardRoute r) {
  switch (r) {
    case ForwardRoute::Auto: return "auto";
    case ForwardRoute::Dense: return "dense";
    case ForwardRoute::TreeSparse: return "tree_sparse";
    case ForwardRoute::Articulated: return "articulated";
  }
  return "?";
}

void StructuredForwardWorkspace::resize(const Model& model) {
  const int nb = model.nb();
  if (static_cast<int>(Ic.size()) == nb && static_cast<int>(jk.size()) == nb) return;
  Ic.assign(nb, Mat6::Zero());
  jk.resize(nb);
  Ad_ij.resize(nb);
  S.resize(nb);
  U.resize(nb);
  Dinv.resize(nb);
  u.resize(nb);
  for (int i = 0; i < nb; ++i) {
    const int nq = model.joints()[i].nq;
    jk[i].resize(nq);
    Ad_ij[i] = AdInv(model.joints()[i].E_mi);  // E_im = E_mi^-1
    S[i].setZero(6, nq);
    U[i].setZero(6, nq);
    Dinv[i].setZero(nq, nq);
    u[i].setZero(nq);
  }
  X.assign(nb, Mat6::Identity());
  E_wi.assign(nb, Mat4::Identity());
  phi.assign(nb, Vec6::Zero());
  c.assign(nb, Vec6::Zero());
  pA.assign(nb, Vec6::Zero());
  a.assign(nb, Vec6::Zero());
  IA.assign(nb, Mat6::Zero());
}

void calcSkeletonMassCrba(const Model& model, const SkeletonWorkspace& sk, StructuredForwardWorkspace& fw, MatX& M_r) {
  fw.resize(model);
  const int nb = model.nb();
  M_r.setZero(model.nr(), model.nr());
  // composite inertias, leaves first: Ic_p += X_i^T Ic_i X_i (X_i = Ad_ip maps p's twists to i)
  for (int i = 0; i < nb; ++i) fw.Ic[i] = model.bodies()[i].M;
  for (int i = nb - 1; i >= 0; --i) {
    const int p = model.joints()[i].parent;
    if (p >= 0) fw.Ic[p].noalias() += sk.Ad_ip[i].transpose() * (fw.Ic[i] * sk.Ad_ip[i]);
  }
  // M(i, i) = S_i^T Ic_i S_i; the wrench F = Ic_i S_i carried to each ancestor j gives M(j, i)
  Mat6X F;
  for (int i = 0; i < nb; ++i) {
    const JointSlot& si = model.joints()[i];
    if (si.nq == 0) continue;
    const auto Si = sk.J_mr.block(6 * i, si.q_index, 6, si.nq);
    F.noalias() = fw.Ic[i] * Si;
    M_r.block(si.q_index, si.q_index, si.nq, si.nq).noalias() = Si.transpose() * F;
    for (int j = i; model.joints()[j].parent >= 0;) {
      F = sk.Ad_ip[j].transpose() * F;  // to the parent's frame (wrenches map with Ad^T)
      j = model.joints()[j].parent;
      const JointSlot& sj = model.joints()[j];
      if (sj.nq == 0) continue;
      const auto Sj = sk.J_mr.block(6 * j, sj.q_index, 6, sj.nq);
      auto Mji = M_r.block(sj.q_index, si.q_index, sj.nq, si.nq);
      Mji.noalias() = Sj.transpose() * F;
      M_r.block(si.q_index, sj.q_index, si.nq, sj.nq) = Mji.transpose();
    }
  }
}

void coordinateParents(const Model& model, std::vector<int>& lambda) {
  lambda.assign(model.nr(), -1);
  // the last coordinate on the path root..i is that of the nearest joint with coordinates
  auto last = [&](int i) {
    for (; i >= 0; i = model.joints()[i].parent)
      if (model.joints()[i].nq > 0) return model.joints()[i].q_index + model.joints()[i].nq - 1;
    return -1;
  };
  for (int i = 0; i < model.nb(); ++i) {
    const JointSlot& s = model.joints()[i];
    int prev = last(s.parent);
    for (int k = 0; k < s.nq; ++k) {
      lambda[s.q_index + k] = prev;
      prev = s.q_index + k;
    }
  }
}

bool hasTreePattern(const MatX& M, const std::vector<int>& lambda, std::vector<int>& stamp) {
  const int n = static_cast<int>(lambda.size());
  stamp.assign(n, -1);
  for (int k = 0; k < n; ++k) {
    if (lambda[k] >= k) return false;  // not parents-first
    for (int j = lambda[k]; j >= 0; j = lambda[j]) stamp[j] = k;
    for (int j = 0; j < k; ++j)
      if (stamp[j] != k && M(k, j) != 0.0) return false;
  }
  return true;
}

bool factorLTDL(const MatX& M, const std::vector<int>& lambda, MatX& LD) {
  // RBDA Table 6.3 on the lower triangle, last coordinate first: the fill of eliminating k stays
  // among k's ancestors, which already are non-zeros of the pattern
  const int n = static_cast<int>(lambda.size());
  LD.resize(n, n);
  LD.triangularView<Eigen::Lower>() = M.triangularView<Eigen::Lower>();
  for (int k = n - 1; k >= 0; --k) {
    const double d = LD(k, k);
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    for (int i = lambda[k]; i >= 0; i = lambda[i]) {
      const double a = LD(k, i) / d;
      for (int j = i; j >= 0; j = lambda[j]) LD(i, j) -= a * LD(k, j);
      LD(k, i) = a;
    }
  }
  return true;
}

void solveLTDL(const MatX& LD, const std::vector<int>& lambda, VecX& x) {
  const int n = static_cast<int>(lambda.size());
  // L^T y = x, descendants (higher indices) first
  for (int i = n - 1; i >= 0; --i)
    for (int j = lambda[i]; j >= 0; j = lambda[j]) x[j] -= LD(i, j) * x[i];
  for (int i = 0; i < n; ++i) x[i] /= LD(i, i);
  // L z = y, ancestors first
  for (int i = 0; i < n; ++i)
    for (int j = lambda[i]; j >= 0; j = lambda[j]) x[i] -= LD(i, j) * x[j];
}

bool articulatedBodyForward(const Model& model, const State& s, const VecX& tau, StructuredForwardWorkspace& fw,
                            VecX& qddot) {
  fw.resize(model);
  const int nb = model.nb();
  // pass 1, root first: poses, twists, velocity-product accelerations c_i and bias forces
  //   phi_i = X_i phi_p + S_i qdot_i,  c_i = -ad(psi_i) X_i phi_p + Ad_ij Sdot qdot_i
  //   pA_i = -ad(phi_i)^T M_i phi_i - Gamma(com)^T R^T m g      (as recursiveIdForward)
  for (int i = 0; i < nb; ++i) {
    const JointSlot& sl = model.joints()[i];
    JointKinematics& jk = fw.jk[i];
    sl.joint.calc(s.q.segment(sl.q_index, sl.nq), s.qdot.segment(sl.q_index, sl.nq), jk);
    const Mat4 E_pi = sl.E_pf * jk.Q * sl.E_mi;
    fw.X[i] = AdInv(E_pi);
    fw.S[i].noalias() = fw.Ad_ij[i] * jk.S;
    const auto qd = s.qdot.segment(sl.q_index, sl.nq);
    const Vec6 psi = fw.S[i] * qd;
    fw.c[i].noalias() = fw.Ad_ij[i] * (jk.Sdot * qd);
    if (sl.parent >= 0) {
      const int p = sl.parent;
      fw.E_wi[i].noalias() = fw.E_wi[p] * E_pi;
      const Vec6 phi_pi = fw.X[i] * fw.phi[p];
      fw.phi[i] = phi_pi + psi;
      fw.c[i].noalias() -= ad(psi) * phi_pi;
    } else {
      fw.E_wi[i] = E_pi;
      fw.phi[i] = psi;
    }
    const Body& b = model.bodies()[i];
    const Vec3 g_i = fw.E_wi[i].topLeftCorner<3, 3>().transpose() * (b.mass * model.gravity());
    fw.IA[i] = b.M;
    fw.pA[i].noalias() = -(ad(fw.phi[i]).transpose() * (b.M * fw.phi[i]));
    fw.pA[i].noalias() -= Gamma(b.com).transpose() * g_i;
  }
  // pass 2, leaves first: articulated inertias and bias forces handed to the parents
  for (int i = nb - 1; i >= 0; --i) {
    const JointSlot& sl = model.joints()[i];
    const int nq = sl.nq;
    Mat6 Ia = fw.IA[i];
    Vec6 pa = fw.pA[i];
    if (nq > 0) {
      fw.U[i].noalias() = fw.IA[i] * fw.S[i];
      const MatJ D = fw.S[i].transpose() * fw.U[i];
      Eigen::LLT<MatJ> llt(D);
      if (llt.info() != Eigen::Success) return false;
      fw.Dinv[i] = llt.solve(MatJ::Identity(nq, nq));
      if (!fw.Dinv[i].allFinite()) return false;
      VecJ& ui = fw.u[i];
      for (int k = 0; k < nq; ++k) {
        const int r = sl.q_index + k;
        const Coordinate& co = model.coordinates()[r];
        ui[k] = -co.stiffness * (s.q[r] - co.rest_value) - co.damping * s.qdot[r];
        if (tau.size() > 0) ui[k] += tau[r];
      }
      ui.noalias() -= fw.S[i].transpose() * fw.pA[i];
      if (sl.parent < 0) continue;
      const Mat6X UDinv = fw.U[i] * fw.Dinv[i];
      Ia.noalias() -= UDinv * fw.U[i].transpose();
      pa.noalias() += UDinv * ui;
    }
    if (sl.parent < 0) continue;
    pa.noalias() += Ia * fw.c[i];
    const int p = sl.parent;
    fw.IA[p].noalias() += fw.X[i].transpose() * (Ia * fw.X[i]);
    fw.pA[p].noalias() += fw.X[i].transpose() * pa;
  }
  // pass 3, root first: accelerations (the world does not accelerate; gravity is a force above)
  qddot.resize(model.nr());
  for (int i = 0; i < nb; ++i) {
    const JointSlot& sl = model.joints()[i];
    Vec6 ap = fw.c[i];
    if (sl.parent >= 0) ap.noalias() += fw.X[i] * fw.a[sl.parent];
    if (sl.nq > 0) {
      auto qdd = qddot.segment(sl.q_index, sl.nq);
      VecJ r = fw.u[i];
      r.noalias() -= fw.U[i].transpose() * ap;
      qdd.noalias() = fw.Dinv[i] * r;
      ap.noalias() += fw.S[i] * qdd;
    }
    fw.a[i] = ap;
  }
  return true;
}

}  // namespace redmax
