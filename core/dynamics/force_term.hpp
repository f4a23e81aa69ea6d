#pragma once
// Extension points of the equations of motion. Later layers (muscle mass points, external loads,
// deformables) add to the reduced mass matrix and force without touching joint code [D Eq. 4.76,
// 4.82, 5.7]: each ForceTerm adds its share of
//   M_r qddot = f_r,    and for linearly implicit integrators K_r = -df_r/dq, D_r = -df_r/dqdot.
#include <string>

#include "core/skeleton/kinematics.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  virtual std::string name() const = 0;
  /// add this term's inertia to M (ndof x ndof); needs Stage::Velocity
  virtual void addMass(const Model&, const State&, const SkeletonWorkspace&, MatX& M) const {}
  /// add this term's generalized force (including its quadratic-velocity part) to f (ndof)
  virtual void addForce(const Model&, const State&, const SkeletonWorkspace&, VecX& f) const = 0;
  /// add K = -df/dq and D = -df/dqdot (ndof x ndof); default: explicit term (adds nothing)
  virtual void addStiffnessDamping(const Model&, const State&, const SkeletonWorkspace&, MatX& K,
                                   MatX& D) const {}
  /// add Mdot(q, qdot) qdot of this term's inertia to Mdot_v (ndof), where Mdot = sum_j dM/dq_j
  /// qdot_j; needs Stage::Velocity at s. Used by the variational (symplectic) integrator, whose
  /// momentum equation needs dL/dq = f + Mdot qdot. Default: a central difference of addMass along
  /// qdot, (M(q + e qdot) - M(q - e qdot)) qdot / (2 e) with |e qdot|_inf = 6e-6 (about
  /// cbrt(machine epsilon): relative error ~1e-10), evaluated in a scratch SkeletonWorkspace; a
  /// term whose addMass adds nothing at s costs one addMass call. Override it analytically where
  /// the mass matrix is known in closed form.
  virtual void addMassDotTimesVelocity(const Model& model, const State& s, const SkeletonWorkspace& sk,
                                       VecX& Mdot_v) const {
    const int n = static_cast<int>(Mdot_v.size());
    MatX M = MatX::Zero(n, n);
    addMass(model, s, sk, M);
    const double vmax = s.qdot.size() > 0 ? s.qdot.lpNorm<Eigen::Infinity>() : 0.0;
    if (M.isZero(0.0) || !(vmax > 0.0)) return;
    const double e = 6e-6 / vmax;
    SkeletonWorkspace scratch(model);
    State sp = s, sm = s;
    sp.q += e * s.qdot;
    sm.q -= e * s.qdot;
    MatX Mp = MatX::Zero(n, n), Mm = MatX::Zero(n, n);
    calcKinematics(model, sp, scratch);
    addMass(model, sp, scratch, Mp);
    calcKinematics(model, sm, scratch);
    addMass(model, sm, scratch, Mm);
    Mdot_v.noalias() += ((Mp - Mm) * s.qdot) / (2.0 * e);
  }
  virtual double kineticEnergy(const Model&, const State&, const SkeletonWorkspace&) const { return 0.0; }
  virtual double potentialEnergy(const Model&, const State&, const SkeletonWorkspace&) const { return 0.0; }
};

}  // namespace redmax
