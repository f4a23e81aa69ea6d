#include "core/dynamics/id_derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/dynamics/constraints/coordinate_coupler.hpp"
#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/coordinate_actuator_term.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/muscles/muscle_id_tangent.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "core/muscles/path.hpp"
#include "core/dynamics/passive_force_terms.hpp"
#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/geometry/local_difference.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax {
namespace {

bool exactVelocityTerms(const Joint& j) {
  return std::visit(
      [](const auto& x) -> bool {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, FunctionBased>) return !x.simbody_compat;
        else if constexpr (std::is_same_v<T, Reversed>) return !x.inner || exactVelocityTerms(*x.inner);
        else if constexpr (std::is_same_v<T, Composite>) {
          for (const Joint& p : x.parts)
            if (!exactVelocityTerms(p)) return false;
          return true;
        } else {
          return true;
        }
      },
      j.v);
}

// What the tangent needs per body beyond recursiveIdForward's workspace, and the joint-local
// derivatives.
struct BodyData {
  Mat6 Ad_ip, Ad_ij;     // Ad(E_ip) (parent twist into i) and Ad(E_im) (constant)
  Vec6 psi;              // the joint's twist in i, S_i qdot
  Vec3 g_i;              // m R_wi^T g
  Vec6 W;                // wrench the joint transmits (own net wrench + the children's)
  // joint-local, per coordinate c of the joint: dS/dq_c (in M), d(Sdot qdot)/dq_c, /dqdot_c (in M)
  std::vector<Mat6X> dS;
  std::vector<Vec6> dSdq, dSdqd;
};

// dSdot(q, qdot)/dq_c of a joint (in its frame M, 6 x nq): the second derivative of S that no joint
// computes, by the local fourth-order difference of its Sdot
Mat6X jointSdotDerivative(const JointSlot& js, const VecJ& q, const VecJ& qd, int c, JointKinematics& jt) {
  return localDerivative(
      [&](double x) {
        VecJ qm = q;
        qm[c] = x;
        js.joint.calc(qm, qd, jt);
        return Mat6X(jt.Sdot);
      },
      q[c]);
}

}  // namespace

bool jointsHaveExactVelocityTerms(const Model& model, std::string* offending) {
  for (int i = 0; i < model.nb(); ++i)
    if (!exactVelocityTerms(model.joints()[i].joint)) {
      if (offending) *offending = model.bodies()[i].name;
      return false;
    }
  return true;
}

namespace {

// the skeleton's and the given Type I/II muscles' mass points' ID derivatives
void idDerivatives(const Model& model, const State& s, const VecX& qddot, const std::vector<const Muscle*>& muscles,
                   MatX& dtau_dq, MatX& dtau_dqdot) {
  const int nb = model.nb(), nr = model.nr();
  std::vector<BodyData> bd(static_cast<size_t>(nb));
  JointKinematics jt;

  // base pass: recursive Newton-Euler's forward pass (poses, S_i, twists, rates, net wrenches),
  // with the 6 x 6 adjoints the tangent applies several times
  RecursiveIdWorkspace rid(model);
  recursiveIdForward(model, s, qddot, rid);
  for (int i = 0; i < nb; ++i) {
    const JointSlot& js = model.joints()[i];
    BodyData& b = bd[static_cast<size_t>(i)];
    const JointKinematics& jk = rid.jk[i];
    const VecJ q = s.q.segment(js.q_index, js.nq), qd = s.qdot.segment(js.q_index, js.nq);
    b.Ad_ip = AdInv(makeE(rid.R_pi[i], rid.p_pi[i]));
    b.Ad_ij = Ad(makeE(rid.R_im[i], rid.p_im[i]));
    b.psi = rid.S_i[i] * qd;
    b.g_i = rid.E_wi[i].topLeftCorner<3, 3>().transpose() * (model.bodies()[i].mass * model.gravity());
    b.W = rid.w[i];
    // joint-local derivatives
    const int nq = js.nq;
    b.dS.assign(static_cast<size_t>(nq), Mat6X::Zero(6, nq));
    b.dSdq.assign(static_cast<size_t>(nq), Vec6::Zero());
    b.dSdqd.assign(static_cast<size_t>(nq), Vec6::Zero());
    for (int c = 0; c < nq; ++c) {
      VecJ e = VecJ::Zero(nq);
      e[c] = 1.0;
      js.joint.calc(q, e, jt);
      b.dS[static_cast<size_t>(c)] = jt.Sdot;
      b.dSdqd[static_cast<size_t>(c)] = jt.Sdot * qd + jk.Sdot.col(c);
      b.dSdq[static_cast<size_t>(c)] = jointSdotDerivative(js, q, qd, c, jt) * qd;
    }
  }
  // the muscles' mass points: wrenches the bodies must supply for them (core/muscles/muscle_id_tangent.hpp)
  std::vector<BodyWorldMotion> world;
  MuscleIdTangentScratch msc;
  // which coordinates move each muscle: a path point's body below the coordinate's joint, or a
  // moving point on it (the others' derivative along it is zero: skipped)
  std::vector<std::vector<char>> moves(muscles.size(), std::vector<char>(static_cast<size_t>(nr), 0));
  for (size_t m = 0; m < muscles.size(); ++m)
    for (const PathPoint& pt : muscles[m]->path.points) {
      if (pt.kind == PathPointKind::Moving && pt.coordinate >= 0) moves[m][static_cast<size_t>(pt.coordinate)] = 1;
      if (pt.body < 0) continue;
      for (int c = 0; c < nr; ++c)
        if (model.isAncestor(model.coordinates()[c].joint, pt.body)) moves[m][static_cast<size_t>(c)] = 1;
    }
  std::vector<Vec6> mw(static_cast<size_t>(nb), Vec6::Zero()), dmw(static_cast<size_t>(nb), Vec6::Zero());
  VecX mtau = VecX::Zero(nr), dmtau = VecX::Zero(nr);
  const VecX zero = VecX::Zero(nr);
  if (!muscles.empty()) {
    calcBodyWorldMotion(rid.motion(), world);
    for (const Muscle* mu : muscles)
      addMuscleIdShareTangent(*mu, s, qddot, zero, zero, world, nullptr, model.gravity(), mw, mtau, nullptr, nullptr,
                              msc);
    for (int i = 0; i < nb; ++i) bd[static_cast<size_t>(i)].W += mw[static_cast<size_t>(i)];
  }
  for (int i = nb - 1; i >= 0; --i) {
    const int p = model.joints()[i].parent;
    if (p >= 0) bd[static_cast<size_t>(p)].W += bd[static_cast<size_t>(i)].Ad_ip.transpose() * bd[static_cast<size_t>(i)].W;
  }
  std::vector<BodyWorldTangent> world_t(static_cast<size_t>(nb));

  // tangent passes, one per coordinate and one per speed
  dtau_dq.setZero(nr, nr);
  dtau_dqdot.setZero(nr, nr);
  std::vector<Vec6> dPose(static_cast<size_t>(nb)), dphi(static_cast<size_t>(nb)), dphidot(static_cast<size_t>(nb)),
      dW(static_cast<size_t>(nb)), dpsi_pose(static_cast<size_t>(nb));
  std::vector<Mat6X> dS_i(static_cast<size_t>(nb));
  for (int col = 0; col < 2 * nr; ++col) {
    const bool speed = col >= nr;
    const int k = speed ? col - nr : col;
    const int joint_k = model.coordinates()[k].joint;
    for (int i = 0; i < nb; ++i) {
      const JointSlot& js = model.joints()[i];
      BodyData& b = bd[static_cast<size_t>(i)];
      if (!model.isAncestor(joint_k, i)) {
        // a body outside the coordinate's subtree does not move with it
        dPose[static_cast<size_t>(i)].setZero();
        dphi[static_cast<size_t>(i)].setZero();
        dphidot[static_cast<size_t>(i)].setZero();
        dW[static_cast<size_t>(i)].setZero();
        dpsi_pose[static_cast<size_t>(i)].setZero();
        dS_i[static_cast<size_t>(i)].setZero(6, js.nq);
        continue;
      }
      const Body& body = model.bodies()[i];
      const VecJ qd = s.qdot.segment(js.q_index, js.nq), qdd = qddot.segment(js.q_index, js.nq);
      const bool own = k >= js.q_index && k < js.q_index + js.nq;
      const int c = k - js.q_index;
      // the joint's own variation: pose (in i), S_i, psi and acc
      Vec6 dpose = Vec6::Zero(), dpsi = Vec6::Zero(), dacc = Vec6::Zero();
      Mat6X& dSi = dS_i[static_cast<size_t>(i)];
      dSi.setZero(6, js.nq);
      if (own && !speed) {
        dpose = rid.S_i[i].col(c);
        dSi = b.Ad_ij * b.dS[static_cast<size_t>(c)];
        dpsi = dSi * qd;
        dacc = dSi * qdd + b.Ad_ij * b.dSdq[static_cast<size_t>(c)];
      } else if (own && speed) {
        dpsi = rid.S_i[i].col(c);
        dacc = b.Ad_ij * b.dSdqd[static_cast<size_t>(c)];
      }
      dpsi_pose[static_cast<size_t>(i)] = dpose;
      Vec6& dP = dPose[static_cast<size_t>(i)];
      Vec6& dph = dphi[static_cast<size_t>(i)];
      Vec6& dphd = dphidot[static_cast<size_t>(i)];
      if (js.parent >= 0) {
        const size_t p = static_cast<size_t>(js.parent);
        const Vec6 Xphi = b.Ad_ip * rid.phi[p], Xphid = b.Ad_ip * rid.phidot[p];
        const Vec6 Xdphi = b.Ad_ip * dphi[p];
        dP = b.Ad_ip * dPose[p] + dpose;
        // d(Ad_ip x) = Ad_ip dx - ad(dpose) Ad_ip x (E_pi varies as E_pi exp([dpose]))
        const Vec6 dXphi = Xdphi - adTimes(dpose, Xphi);
        dph = dXphi + dpsi;
        dphd = b.Ad_ip * dphidot[p] - adTimes(dpose, Xphid) - adTimes(dpsi, Xphi) - adTimes(b.psi, dXphi) + dacc;
      } else {
        dP = dpose;
        dph = dpsi;
        dphd = dacc;
      }
      // net wrench w = M phidot - ad(phi)^T M phi - (c x g_i; g_i), g_i = m R_wi^T g
      const Vec3 dg = -dP.head<3>().cross(b.g_i);
      Vec6 dgw;
      dgw.head<3>() = body.com.cross(dg);
      dgw.tail<3>() = dg;
      dW[static_cast<size_t>(i)] = body.M * dphd - adTransposeTimes(dph, body.M * rid.phi[i]) -
                                   adTransposeTimes(rid.phi[i], body.M * dph) - dgw;
    }
    if (!muscles.empty()) {
      // the bodies' world motion's derivative from the body-coordinate one (dR = [R dPose_w] R)
      for (int i = 0; i < nb; ++i) {
        const BodyWorldMotion& o = world[static_cast<size_t>(i)];
        BodyWorldTangent& t = world_t[static_cast<size_t>(i)];
        const Vec6& dP = dPose[static_cast<size_t>(i)];
        const Vec6& dph = dphi[static_cast<size_t>(i)];
        const Vec6& dphd = dphidot[static_cast<size_t>(i)];
        t.dtheta = o.R * dP.head<3>();
        t.dp = o.R * dP.tail<3>();
        t.domega = t.dtheta.cross(o.omega) + o.R * dph.head<3>();
        t.dnu = t.dtheta.cross(o.nu) + o.R * dph.tail<3>();
        t.dalpha = t.dtheta.cross(o.alpha) + o.R * dphd.head<3>();
        // bias = R nudot + omega x nu
        t.dbias = t.dtheta.cross(o.bias - o.omega.cross(o.nu)) + o.R * dphd.tail<3>() + t.domega.cross(o.nu) +
                  o.omega.cross(t.dnu);
      }
      VecX dqv = VecX::Zero(nr), dqdv = VecX::Zero(nr);
      (speed ? dqdv : dqv)[k] = 1.0;
      std::fill(dmw.begin(), dmw.end(), Vec6::Zero());  // (mw, mtau: the values again, unused)
      dmtau.setZero();
      for (size_t m = 0; m < muscles.size(); ++m)
        if (moves[m][static_cast<size_t>(k)])
          addMuscleIdShareTangent(*muscles[m], s, qddot, dqv, dqdv, world, &world_t, model.gravity(), mw, mtau, &dmw,
                                  &dmtau, msc);
      for (int i = 0; i < nb; ++i) dW[static_cast<size_t>(i)] += dmw[static_cast<size_t>(i)];
      (speed ? dtau_dqdot : dtau_dq).col(k) += dmtau;
    }
    for (int i = nb - 1; i >= 0; --i) {
      const JointSlot& js = model.joints()[i];
      const BodyData& b = bd[static_cast<size_t>(i)];
      const Vec6& dWi = dW[static_cast<size_t>(i)];
      if (js.nq > 0) {
        const VecJ dt = dS_i[static_cast<size_t>(i)].transpose() * b.W + rid.S_i[i].transpose() * dWi;
        (speed ? dtau_dqdot : dtau_dq).block(js.q_index, k, js.nq, 1) += dt;
      }
      if (js.parent >= 0) {
        // d(Ad_ip^T W) = Ad_ip^T dW - Ad_ip^T ad(dpose)^T W
        dW[static_cast<size_t>(js.parent)] +=
            b.Ad_ip.transpose() * (dWi - adTransposeTimes(dpsi_pose[static_cast<size_t>(i)], b.W));
      }
    }
  }
  // joint springs and dampers: tau -= -k (q - q0) - d qdot
  for (int c = 0; c < nr; ++c) {
    dtau_dq(c, c) += model.coordinates()[c].stiffness;
    dtau_dqdot(c, c) += model.coordinates()[c].damping;
  }
}

// The muscles of a MuscleTerm with mass points, by how their ID derivatives are formed: the
// path-wise ones (Types I and II) by the dual pass inside the skeleton's tangent, the wrapping ones
// (Type III) by a muscle-local difference (addWrappingMuscleIdDerivatives). False with the reason
// when a muscle is neither (fibre-following points, a deformable node) or the term drops its
// quadratic velocity vector.
struct TermMuscles {
  std::vector<const Muscle*> pathwise, wrapping;
};
bool muscleTermSupported(const MuscleTerm& mt, TermMuscles* out, std::string* why) {
  if (!mt.options().quadratic_velocity) {
    if (why) *why = "the term '" + mt.name() + "' without its quadratic velocity vector";
    return false;
  }
  for (const Muscle& mu : mt.muscles()) {
    if (mu.mass_points.size() == 0) continue;
    const char* reason = pathwiseInverseDynamicsRefusal(mu);
    const bool wraps = pathType(mu.path) == PathType::III && !hasNodePoints(mu.path) && !mu.fibre.enabled();
    if (reason && !wraps) {
      if (why) *why = "the mass points of muscle '" + mu.name + "', which " + reason;
      return false;
    }
    if (out) (wraps ? out->wrapping : out->pathwise).push_back(&mu);
  }
  return true;
}

// Whether a muscle's Jdot_ar is the exact time derivative of its J_ar, so that
// Jdot_ar(q, v) = sum_j dJ_ar/dq_j v_j: the smooth model's and the network's (Jets, unless the
// network takes Jdot by the forward difference of [D Eq. 5.58]); not the exact library's
// finite-difference Jacobians.
bool exactWrapJdot(const Muscle& mu) {
  return mu.wrap.model == WrapModel::Smooth || (mu.wrap.model == WrapModel::Neural && !mu.wrap.network_fd_jdot);
}

// The Type III muscles' share of inverse dynamics, sum_a J_ar^T m_a (J_ar qddot + Jdot_ar qdot - g)
// as MuscleTerm forms it (addCompactMuscleIdShare), differentiated along each coordinate that
// moves one of them by the fourth-order local difference (localDerivative): the wrap
// construction's J and Jdot have no written derivatives along q (its Jets carry value, velocity and
// first partials), as the dissertation differences its network Jacobians in time [D Eq. 5.58].
// Along the speeds the share is J^T m (Jdot(q, e_c) qdot + Jdot(q, qdot) e_c), and where Jdot is
// exact (exactWrapJdot) Jdot(q, e_c) = dJ/dq_c, which the same stencil differences beside the
// share: no evaluation of its own (otherwise the speeds take a stencil too).
// A stencil point recomputes the skeleton's kinematics and the muscles that coordinate moves, not
// the step: 4k + 1 muscle evaluations per muscle of k columns. The step is 1e-4, not
// localDerivative's 1e-3: the smooth model's fades bend the share within a few 1e-3 rad (on
// reach_arm.osim's elbow the 1e-3 stencil's truncation was 5.6e-7 of the column, and 1e-4 of the
// gradient), while the share is exact to round-off at each point, so a smaller step costs only
// eps |tau| / h ~ 2e-12.
constexpr double kWrapStep = 1e-4;
void addWrappingMuscleIdDerivatives(const Model& model, const State& s, const VecX& qddot,
                                    const std::vector<const Muscle*>& muscles, MatX& dtau_dq, MatX& dtau_dqdot) {
  if (muscles.empty()) return;
  const int nr = model.nr();
  const size_t nm = muscles.size();
  std::vector<MuscleKinematics> mk(nm);
  std::vector<char> exact(nm);
  for (size_t m = 0; m < nm; ++m) {
    initMuscleKinematics(model, *muscles[m], mk[m]);
    exact[m] = exactWrapJdot(*muscles[m]);
  }
  SkeletonWorkspace sk(model);
  State sp = s;
  VecX qdot_c, qddot_c, fc;
  // J_ar, Jdot_ar and the compact qdot of each muscle at s (the speeds' columns of exact ones)
  std::vector<MatX> J0(nm), Jd0(nm);
  std::vector<VecX> qdot0(nm);
  calcKinematics(model, sp, sk);
  for (size_t m = 0; m < nm; ++m) {
    if (!exact[m]) continue;
    calcMuscleKinematics(model, sp, sk, *muscles[m], mk[m], true);
    J0[m] = mk[m].J_ar;
    Jd0[m] = mk[m].Jdot_ar;
    gatherColumns(s.qdot, mk[m], qdot0[m]);
  }
  std::vector<size_t> moved;
  for (int col = 0; col < 2 * nr; ++col) {
    const bool speed = col >= nr;
    const int c = speed ? col - nr : col;
    moved.clear();
    for (size_t m = 0; m < nm; ++m)
      if (c < static_cast<int>(mk[m].col_of.size()) && mk[m].col_of[static_cast<size_t>(c)] >= 0 &&
          !(speed && exact[m]))
        moved.push_back(m);
    if (moved.empty()) continue;
    // the moved muscles' share at a stencil point, then (along q) the exact ones' J_ar, stacked
    Eigen::Index size = nr;
    if (!speed)
      for (size_t m : moved)
        if (exact[m]) size += J0[m].size();
    VecX& x = speed ? sp.qdot : sp.q;
    const double x0 = x[c];
    auto share = [&](double xc) {
      x[c] = xc;
      calcKinematics(model, sp, sk);
      VecX out(size), tau = VecX::Zero(nr);
      Eigen::Index at = nr;
      for (size_t m : moved) {
        calcMuscleKinematics(model, sp, sk, *muscles[m], mk[m], true);
        gatherColumns(sp.qdot, mk[m], qdot_c);
        gatherColumns(qddot, mk[m], qddot_c);
        fc.setZero(qdot_c.size());
        addCompactMuscleIdShare(muscles[m]->mass_points, mk[m], qdot_c, qddot_c, model.gravity(), true, false, fc);
        scatterAddColumns(fc, mk[m], tau);
        if (!speed && exact[m]) {
          out.segment(at, mk[m].J_ar.size()) = Eigen::Map<const VecX>(mk[m].J_ar.data(), mk[m].J_ar.size());
          at += mk[m].J_ar.size();
        }
      }
      out.head(nr) = tau;
      return out;
    };
    const VecX d = localDerivative(share, x0, kWrapStep);
    x[c] = x0;
    (speed ? dtau_dqdot : dtau_dq).col(c) += d.head(nr);
    if (speed) continue;
    // the exact muscles' speed column c: J^T m (dJ/dq_c qdot + Jdot e_c)
    Eigen::Index at = nr;
    VecX tau = VecX::Zero(nr);
    for (size_t m : moved) {
      if (!exact[m]) continue;
      const Eigen::Map<const MatX> dJ(d.data() + at, J0[m].rows(), J0[m].cols());
      at += J0[m].size();
      const int j = mk[m].col_of[static_cast<size_t>(c)];
      const MassPoints& mp = muscles[m]->mass_points;
      fc.setZero(J0[m].cols());
      for (int a = 0; a < mp.size(); ++a) {
        const Vec3 acc = dJ.middleRows<3>(3 * a) * qdot0[m] + Jd0[m].middleRows<3>(3 * a).col(j);
        fc.noalias() += J0[m].middleRows<3>(3 * a).transpose() * (mp.mass[a] * acc);
      }
      scatterAddColumns(fc, mk[m], tau);
    }
    dtau_dqdot.col(c) += tau;
  }
}

// Central differences of the Hill-type muscles (MuscleForceTerm) alone, muscle by muscle, at s with
// the controls of ws: muscle k's share g_k = (-F_t dl/dq in its columns; its zdot), F_t and zdot
// from its model at (its z, l, ldot, its u), differenced along each coordinate and speed that moves
// its path (the skeleton's kinematics once per stencil point for all of them, then each moved
// muscle's path and model), and along its own states and control (its model alone, at the
// state's path). `out` selects the blocks of d(f; zdot)/d(q, qdot, z, u) wanted (null: not).
struct StateTermColumns {
  MatX* f_q = nullptr;  MatX* f_v = nullptr;  MatX* f_z = nullptr;  MatX* f_u = nullptr;
  MatX* z_q = nullptr;  MatX* z_v = nullptr;  MatX* z_z = nullptr;  MatX* z_u = nullptr;
};
// every block of a StateTermDerivatives (the force's along q and qdot are systemIdDerivatives')
StateTermColumns columnsOf(StateTermDerivatives& d) {
  StateTermColumns c;
  c.f_z = &d.df_dz;
  c.f_u = &d.df_du;
  c.z_q = &d.dzdot_dq;
  c.z_v = &d.dzdot_dv;
  c.z_z = &d.dzdot_dz;
  c.z_u = &d.dzdot_du;
  return c;
}

void differenceStateTerms(const System& sys, const State& s, const DynamicsWorkspace& ws, double step,
                          const StateTermColumns& out) {
  const Model& model = sys.model();
  const int n = sys.ndof(), nz = sys.numStates(), nu = sys.numControls();
  if (out.f_q) out.f_q->setZero(n, n);
  if (out.f_v) out.f_v->setZero(n, n);
  if (out.f_z) out.f_z->setZero(n, nz);
  if (out.f_u) out.f_u->setZero(n, nu);
  if (out.z_q) out.z_q->setZero(nz, n);
  if (out.z_v) out.z_v->setZero(nz, n);
  if (out.z_z) out.z_z->setZero(nz, nz);
  if (out.z_u) out.z_u->setZero(nz, nu);
  // every Hill-type muscle: its term, index, states and control
  struct Hill {
    const MuscleForceTerm* term;
    int k, z0, nzk, u;
    std::vector<char> moves;  // per coordinate: its path's columns
    MuscleForceScratch* sc;   // its term's path scratch
  };
  std::vector<Hill> hills;
  std::vector<std::unique_ptr<MuscleForceScratch>> scratch;  // one per term
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  double l = 0.0, ld = 0.0;
  VecX dl;
  for (size_t i = 0; i < sys.terms().size(); ++i) {
    const auto* mf = dynamic_cast<const MuscleForceTerm*>(sys.terms()[i].get());
    if (!mf) continue;
    scratch.push_back(std::make_unique<MuscleForceScratch>());
    for (int k = 0; k < static_cast<int>(mf->actuated().size()); ++k) {
      const MuscleForceTerm::Actuated& a = mf->actuated()[static_cast<size_t>(k)];
      Hill h{mf, k, sys.stateOffset(i) + a.z_offset, a.model->numStates(), sys.controlOffset(i) + k, {},
             scratch.back().get()};
      MuscleKinematics mk;
      initMuscleKinematics(model, a.muscle.path, mk);
      h.moves.assign(static_cast<size_t>(n), 0);
      for (int c : mk.cols)
        if (c < n) h.moves[static_cast<size_t>(c)] = 1;
      hills.push_back(std::move(h));
    }
  }
  if (hills.empty()) return;
  State sp = s;
  VecX u = ws.controls.size() == nu ? ws.controls : VecX::Zero(nu);
  hill::MuscleOutput mo;
  // muscle h's (f in all n; zdot_h) at sp, u with the skeleton's kinematics in sk; path given or
  // evaluated
  auto evalMuscle = [&](const Hill& h, bool path, VecX& f, Eigen::Ref<VecX> zdot) {
    if (path) h.term->calcPath(model, sp, sk, h.k, *h.sc, l, ld, dl);
    hill::MusculotendonInput in;
    in.length = l;
    in.speed = ld;
    in.excitation = u[h.u];
    h.term->actuated()[static_cast<size_t>(h.k)].model->calc(h.nzk > 0 ? sp.z.data() + h.z0 : nullptr, in, mo,
                                                              zdot.data());
    f.noalias() -= mo.tendon_force * dl.head(n);
  };
  VecX f(n), zdot(nz);
  // along one variable x (a coordinate or speed: kinematics per point, every moved muscle; a state
  // or control: the muscle alone at the state's path), (f; zdot) stacked
  auto column = [&](double& x, const std::vector<size_t>& which, bool kinematics, MatX* f_block, MatX* z_block,
                    int col) {
    const double x0 = x;
    const VecX d = centralDerivative(
        [&](double v) {
          x = v;
          if (kinematics) calcKinematics(model, sp, sk);
          f.setZero();
          zdot.setZero();
          for (size_t j : which) evalMuscle(hills[j], kinematics, f, zdot.segment(hills[j].z0, hills[j].nzk));
          VecX out(n + nz);
          out << f, zdot;
          return out;
        },
        x0, step);
    x = x0;
    if (f_block) f_block->col(col) = d.head(n);
    if (z_block) z_block->col(col) = d.tail(nz);
  };
  // states and controls first, each muscle at the state's path
  if (out.f_z || out.z_z || out.f_u || out.z_u)
    for (size_t j = 0; j < hills.size(); ++j) {
      const Hill& h = hills[j];
      h.term->calcPath(model, sp, sk, h.k, *h.sc, l, ld, dl);
      const std::vector<size_t> one{j};
      if (out.f_z || out.z_z)
        for (int c = h.z0; c < h.z0 + h.nzk; ++c) column(sp.z[c], one, false, out.f_z, out.z_z, c);
      if (out.f_u || out.z_u) column(u[h.u], one, false, out.f_u, out.z_u, h.u);
    }
  // then coordinates and speeds
  std::vector<size_t> moved;
  for (int col = 0; col < 2 * n; ++col) {
    const bool speed = col >= n;
    const int c = speed ? col - n : col;
    if (speed ? !(out.f_v || out.z_v) : !(out.f_q || out.z_q)) continue;
    moved.clear();
    for (size_t j = 0; j < hills.size(); ++j)
      if (hills[j].moves[static_cast<size_t>(c)]) moved.push_back(j);
    if (moved.empty()) continue;
    column(speed ? sp.qdot[c] : sp.q[c], moved, true, speed ? out.f_v : out.f_q, speed ? out.z_v : out.z_q, c);
  }
}

// The terms whose derivatives are written (systemIdDerivatives adds them; none adds K or D, which
// the adjoint's bdf1 route relies on)
bool writtenDerivativesTerm(const ForceTerm& t) {
  return dynamic_cast<const CoordinateActuatorTerm*>(&t) || dynamic_cast<const CoordinateLimitForceTerm*>(&t) ||
         dynamic_cast<const SpringGeneralizedForceTerm*>(&t);
}

// Force terms with no written derivatives that add no mass and have no states (contact, bushings,
// point-to-point springs, point and torque actuators, sampled or impulse loads): their
// generalized force is differenced alone (term-local central differences at `step`, each stencil
// point the skeleton's kinematics and those terms). A term that adds mass or has states of its
// own is not one of them.
bool differencedForceTerm(const ForceTerm& t) {
  if (writtenDerivativesTerm(t) || dynamic_cast<const MuscleForceTerm*>(&t) || dynamic_cast<const MuscleTerm*>(&t))
    return false;
  return !t.addsMass() && t.numStates() == 0;
}

void addDifferencedForceTerms(const System& sys, const State& s, const DynamicsWorkspace& ws, double step,
                              MatX& dtau_dq, MatX& dtau_dqdot) {
  const Model& model = sys.model();
  const int n = sys.ndof(), nu = sys.numControls();
  std::vector<size_t> terms;
  for (size_t i = 0; i < sys.terms().size(); ++i)
    if (differencedForceTerm(*sys.terms()[i])) terms.push_back(i);
  if (terms.empty()) return;
  SkeletonWorkspace sk(model);
  std::vector<std::unique_ptr<TermScratch>> scratch;
  for (size_t i : terms) scratch.push_back(sys.terms()[i]->makeScratch(model));
  std::uint64_t evaluation = 0;
  State sp = s;
  const VecX u = ws.controls.size() == nu ? ws.controls : VecX::Zero(nu);
  auto force = [&]() {
    calcKinematics(model, sp, sk);
    ++evaluation;
    VecX f = VecX::Zero(n);
    for (size_t j = 0; j < terms.size(); ++j) {
      TermContext ctx(sk, scratch[j].get(), evaluation);
      ctx.z_offset = sys.stateOffset(terms[j]);
      ctx.u_offset = sys.controlOffset(terms[j]);
      if (nu > 0) ctx.controls = &u;
      sys.terms()[terms[j]]->addForce(model, sp, ctx, f);
    }
    return f;
  };
  for (int col = 0; col < 2 * n; ++col) {
    const bool speed = col >= n;
    double& x = speed ? sp.qdot[col - n] : sp.q[col];
    const double x0 = x;
    (speed ? dtau_dqdot : dtau_dq).col(speed ? col - n : col) -= centralDerivative(
        [&](double v) {
          x = v;
          return force();
        },
        x0, step);
    x = x0;
  }
}

}  // namespace

void skeletonIdDerivatives(const Model& model, const State& s, const VecX& qddot, MatX& dtau_dq, MatX& dtau_dqdot) {
  idDerivatives(model, s, qddot, {}, dtau_dq, dtau_dqdot);
}

bool systemIdDerivativesAvailable(const System& sys, std::string* why) {
  auto refuse = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (sys.coordinateMap()) return refuse("a coordinate map (hyper-reduced coordinates)");
  if (sys.numExtraCoordinates() > 0) return refuse("extra coordinates (deformables)");
  std::string joint;
  if (!jointsHaveExactVelocityTerms(sys.model(), &joint))
    return refuse("the Simbody-compatible velocity terms of the joint of body '" + joint + "'");
  // the terms with written or local derivatives; none adds K or D (the adjoint's bdf1 route
  // relies on it)
  for (const auto& t : sys.terms()) {
    if (writtenDerivativesTerm(*t) || dynamic_cast<const MuscleForceTerm*>(t.get()) || differencedForceTerm(*t))
      continue;
    if (const auto* mt = dynamic_cast<const MuscleTerm*>(t.get())) {
      if (!muscleTermSupported(*mt, nullptr, why)) return false;
      continue;
    }
    return refuse("the term '" + t->name() + "' (it adds mass or has states of its own, without written derivatives)");
  }
  return true;
}

std::string systemIdDerivativesLocalDifferences(const System& sys) {
  TermMuscles muscles;
  std::string hill;
  for (const auto& t : sys.terms()) {
    if (const auto* mt = dynamic_cast<const MuscleTerm*>(t.get())) muscleTermSupported(*mt, &muscles, nullptr);
    if (const auto* mf = dynamic_cast<const MuscleForceTerm*>(t.get()); mf && !mf->actuated().empty()) {
      const size_t n = mf->actuated().size();
      hill = "the forces and states of " + std::to_string(n) + " Hill-type muscle" + (n > 1 ? "s" : "") + " ('" +
             mf->actuated().front().muscle.name + "'" + (n > 1 ? ", ..." : "") +
             ") by central differences of their term";
    }
  }
  std::string text;
  if (!muscles.wrapping.empty()) {
    const size_t n = muscles.wrapping.size();
    text = "the mass points of " + std::to_string(n) + " wrapping (Type III) muscle" + (n > 1 ? "s" : "") + " ('" +
           muscles.wrapping.front()->name + "'" + (n > 1 ? ", ..." : "") + ") by muscle-local fourth-order differences";
  }
  if (!hill.empty()) text += (text.empty() ? "" : "; ") + hill;
  std::string others;
  for (const auto& t : sys.terms())
    if (differencedForceTerm(*t)) others += (others.empty() ? "'" : ", '") + t->name() + "'";
  if (!others.empty()) text += (text.empty() ? "" : "; ") + std::string("the forces of ") + others + " by central differences of their terms";
  return text;
}

bool systemIdDerivatives(const System& sys, const State& s, const VecX& qddot, const DynamicsWorkspace& ws,
                         MatX& dtau_dq, MatX& dtau_dqdot, std::string* why, double term_step,
                         StateTermDerivatives* state_terms) {
  if (!ws.loads.empty()) {
    if (why) *why = "external loads";
    return false;
  }
  if (!systemIdDerivativesAvailable(sys, why)) return false;
  TermMuscles muscles;
  for (const auto& t : sys.terms())
    if (const auto* mt = dynamic_cast<const MuscleTerm*>(t.get())) muscleTermSupported(*mt, &muscles, nullptr);
  idDerivatives(sys.model(), s, qddot, muscles.pathwise, dtau_dq, dtau_dqdot);
  addWrappingMuscleIdDerivatives(sys.model(), s, qddot, muscles.wrapping, dtau_dq, dtau_dqdot);
  // the terms' share of tau is -f_t: dtau += -df_t/dq, -df_t/dqdot
  for (const auto& t : sys.terms()) {
    if (const auto* cl = dynamic_cast<const CoordinateLimitForceTerm*>(t.get())) {
      for (const CoordinateLimitForceTerm::Limit& l : cl->limits()) {
        double dq = 0.0, dqd = 0.0;
        CoordinateLimitForceTerm::forceDerivatives(l, s.q[l.coordinate], s.qdot[l.coordinate], dq, dqd);
        dtau_dq(l.coordinate, l.coordinate) -= dq;
        dtau_dqdot(l.coordinate, l.coordinate) -= dqd;
      }
    } else if (const auto* sg = dynamic_cast<const SpringGeneralizedForceTerm*>(t.get())) {
      for (const SpringGeneralizedForceTerm::Spring& sp : sg->springs()) {
        dtau_dq(sp.coordinate, sp.coordinate) += sp.stiffness;
        dtau_dqdot(sp.coordinate, sp.coordinate) += sp.viscosity;
      }
    }
    // CoordinateActuatorTerm: optimal_force * u does not depend on q or qdot
  }
  // Hill-type muscles: term-local differences (stateTermDerivatives)
  if (std::any_of(sys.terms().begin(), sys.terms().end(),
                  [](const auto& t) { return dynamic_cast<const MuscleForceTerm*>(t.get()) != nullptr; })) {
    MatX df_dq, df_dv;
    StateTermColumns cols = state_terms ? columnsOf(*state_terms) : StateTermColumns{};
    cols.f_q = &df_dq;
    cols.f_v = &df_dv;
    differenceStateTerms(sys, s, ws, term_step, cols);
    dtau_dq -= df_dq;
    dtau_dqdot -= df_dv;
  }
  // the other force terms without written derivatives: term-local differences
  addDifferencedForceTerms(sys, s, ws, term_step, dtau_dq, dtau_dqdot);
  return true;
}

void stateTermDerivatives(const System& sys, const State& s, const DynamicsWorkspace& ws, double step,
                          StateTermDerivatives& out) {
  differenceStateTerms(sys, s, ws, step, columnsOf(out));
}

bool constraintRowDerivativesAvailable(const System& sys, std::string* why) {
  for (const auto& c : sys.constraints())
    if (c->actsOnExtraCoordinates()) {
      if (why) *why = "the constraint '" + c->name() + "' on extra coordinates (deformables)";
      return false;
    }
  return true;
}

void constraintRowDerivatives(const System& sys, const State& s, const VecX& w, const VecX& lambda,
                              ConstraintRowDerivatives& out) {
  const int n = sys.ndof(), nc = sys.numConstraintRows();
  out.dGw_dq.setZero(nc, n);
  out.dGTl_dq.setZero(n, n);
  out.drhs_dq.setZero(nc, n);
  out.drhs_dv.setZero(nc, n);
  out.dverr_dq.setZero(nc, n);
  out.dverr_dv.setZero(nc, n);
  MatX dperr_dq = MatX::Zero(nc, n);
  int r = 0;
  FunctionValue fv, ft;
  SkeletonWorkspace sk(sys.model());
  for (const auto& c : sys.constraints()) {
    if (!dynamic_cast<const PrescribedCoordinate*>(c.get()) && !dynamic_cast<const CoordinateCoupler*>(c.get())) {
      // points, welds, prescribed points: the rows differenced alone (fourth order, local), G w,
      // G^T lambda and the errors along q, the rhs and the errors along qdot
      const int m = c->rows();
      const Model& model = sys.model();
      const VecX lr = lambda.segment(r, m);
      State sp = s;
      MatX G(m, n);
      VecX rhs(m), perr(m), verr(m);
      auto rows = [&]() {
        calcKinematics(model, sp, sk);
        G.setZero();
        rhs.setZero();
        c->calcAcceleration(model, sp, sk, G, rhs);
        c->calcErrors(model, sp, sk, perr, verr);
        VecX out(4 * m + n);
        out << G * w, rhs, verr, perr, G.transpose() * lr;
        return out;
      };
      for (int j = 0; j < 2 * n; ++j) {
        const bool speed = j >= n;
        const int col = speed ? j - n : j;
        double& x = speed ? sp.qdot[col] : sp.q[col];
        const double x0 = x;
        const VecX d = localDerivative(
            [&](double v) {
              x = v;
              return rows();
            },
            x0);
        x = x0;
        if (!speed) {
          out.dGw_dq.block(r, col, m, 1) = d.head(m);
          out.drhs_dq.block(r, col, m, 1) = d.segment(m, m);
          out.dverr_dq.block(r, col, m, 1) = d.segment(2 * m, m);
          dperr_dq.block(r, col, m, 1) = d.segment(3 * m, m);
          out.dGTl_dq.col(col) += d.tail(n);
        } else {
          out.drhs_dv.block(r, col, m, 1) = d.segment(m, m);
          out.dverr_dv.block(r, col, m, 1) = d.segment(2 * m, m);
        }
      }
      r += m;
      continue;
    }
    if (const auto* pc = dynamic_cast<const PrescribedCoordinate*>(c.get())) {
      // G = -e_k^T and rhs = -qddot_p(t) are constant in the state; pos_err = q_p(t) - q_k,
      // vel_err = qdot_p(t) - qdot_k
      out.dverr_dv(r, pc->coordinate()) = -1.0;
      dperr_dq(r, pc->coordinate()) = -1.0;
      r += pc->rows();
      continue;
    }
    const auto& cc = dynamic_cast<const CoordinateCoupler&>(*c);
    const std::vector<int>& I = cc.independent();
    const int m = static_cast<int>(I.size()), d = cc.dependent();
    const double sc = cc.scale();
    VecJ x(m), xd(m), wI(m);
    for (int k = 0; k < m; ++k) {
      x[k] = s.q[I[k]];
      xd[k] = s.qdot[I[k]];
      wI[k] = w[I[k]];
    }
    evaluateWithArguments(cc.function(), x, 2, fv);
    const VecJ Hxd = fv.hessian * xd, Hw = fv.hessian * wI;
    for (int k = 0; k < m; ++k) {
      const int col = I[k];
      out.dGw_dq(r, col) += sc * Hw[k];
      for (int j = 0; j < m; ++j) out.dGTl_dq(I[j], col) += lambda[r] * sc * fv.hessian(j, k);
      out.dverr_dq(r, col) += sc * Hxd[k];
      out.dverr_dv(r, col) += sc * fv.gradient[k];
      dperr_dq(r, col) += sc * fv.gradient[k];
      out.drhs_dv(r, col) += -2.0 * sc * Hxd[k];
      // rhs along q_k: -scale xdot^T (dHess/dx_k) xdot, the Hessian differenced (local)
      const double t = localDerivative(
          [&](double v) {
            VecJ xm = x;
            xm[k] = v;
            evaluateWithArguments(cc.function(), xm, 2, ft);
            return xd.dot(ft.hessian * xd);
          },
          x[k]);
      out.drhs_dq(r, col) += -sc * t;
    }
    out.dverr_dv(r, d) += -1.0;
    dperr_dq(r, d) += -1.0;
    r += cc.rows();
  }
  // System::calcConstraints' stabilization: rhs -= 2 alpha vel_err + beta^2 pos_err
  const StabilizationOptions& st = sys.stabilization;
  if (st.alpha != 0.0 || st.beta != 0.0) {
    out.drhs_dq -= 2.0 * st.alpha * out.dverr_dq + st.beta * st.beta * dperr_dq;
    out.drhs_dv -= 2.0 * st.alpha * out.dverr_dv;
  }
}

MatX jacobianDerivative(const Model& model, const State& s, int c) {
  State sc = s;
  sc.qdot.setZero();
  sc.qdot[c] = 1.0;
  SkeletonWorkspace ws(model);
  calcKinematics(model, sc, ws);
  return ws.Jdot_mr;
}

void jacobianDerivatives(const Model& model, const State& s, int c, MatX& dJ, MatX& dJdot) {
  SkeletonWorkspace ws(model);
  calcKinematics(model, s, ws);
  const int nb = model.nb();
  dJ.setZero(model.nm(), model.nr());
  dJdot.setZero(model.nm(), model.nr());
  const int jc = model.coordinates()[c].joint;
  JointKinematics jt;
  for (int i = 0; i < nb; ++i) {
    if (!model.isAncestor(jc, i)) continue;  // outside the coordinate's subtree nothing moves
    const JointSlot& js = model.joints()[i];
    const int r = 6 * i;
    const VecJ q = s.q.segment(js.q_index, js.nq), qd = s.qdot.segment(js.q_index, js.nq);
    // the joint's own variation: dS = Sdot(q, e_c'), dSdot by a fourth-order difference, the
    // pose variation in body i and that of psi_i = Ad_ij S qdot
    Vec6 dpose = Vec6::Zero(), dpsi = Vec6::Zero();
    if (i == jc) {
      const int cc = c - js.q_index;
      VecJ e = VecJ::Zero(js.nq);
      e[cc] = 1.0;
      js.joint.calc(q, e, jt);
      const Mat6X dS = ws.Ad_ij[i] * jt.Sdot;
      dJ.block(r, js.q_index, 6, js.nq) = dS;
      dJdot.block(r, js.q_index, 6, js.nq) = ws.Ad_ij[i] * jointSdotDerivative(js, q, qd, cc, jt);
      dpose = ws.J_mr.block(r, c, 6, 1);
      dpsi = dS * qd;
    }
    if (js.parent < 0) continue;
    const int p = js.parent, rp = 6 * p;
    const Mat6& Ad = ws.Ad_ip[i];
    const Mat6 dAd = -ad(dpose) * Ad;                              // d Ad_ip
    const Mat6 Addot = -ad(ws.psi[i]) * Ad;                        // Addot_ip
    const Mat6 dAddot = -ad(dpsi) * Ad - ad(ws.psi[i]) * dAd;      // d Addot_ip
    for (int a : model.ancestors(p)) {
      const JointSlot& sa = model.joints()[a];
      if (sa.nq == 0) continue;
      const auto Jp = ws.J_mr.block(rp, sa.q_index, 6, sa.nq);
      const auto Jdp = ws.Jdot_mr.block(rp, sa.q_index, 6, sa.nq);
      const MatX dJp = dJ.block(rp, sa.q_index, 6, sa.nq), dJdp = dJdot.block(rp, sa.q_index, 6, sa.nq);
      dJ.block(r, sa.q_index, 6, sa.nq) = dAd * Jp + Ad * dJp;
      dJdot.block(r, sa.q_index, 6, sa.nq) = dAddot * Jp + Addot * dJp + dAd * Jdp + Ad * dJdp;
    }
  }
}

}  // namespace redmax
