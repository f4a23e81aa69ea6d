#pragma once
// Bilateral constraints on reduced or maximal coordinates, enforced through the KKT systems of
// [D Sec. 4.6.4-4.6.5]. A constraint states, at the acceleration level,
//     G(q) qddot = rhs(q, qdot, t)      (rhs already contains -Gdot qdot and prescribed terms)
// and reports its position and velocity errors for stabilisation and projection.
// Maximal-coordinate constraints (G_m) multiply by J_mr themselves, so every G here is in q_r,
// except for constraints that say they act on the System's extra coordinates.
#include <string>

#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

class Constraint {
 public:
  virtual ~Constraint() = default;
  virtual std::string name() const = 0;
  virtual int rows() const = 0;
  /// G (rows x ndof) and the acceleration-level right-hand side (rows); needs Stage::Velocity
  virtual void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&,
                                Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const = 0;
  /// position error C(q, t) and velocity error (rows each); zero when satisfied
  virtual void calcErrors(const Model&, const State&, const SkeletonWorkspace&,
                          Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const = 0;
  /// true if the constraint prescribes motion (hybrid dynamics [D Eq. 4.109]): its multipliers
  /// are the torques needed to realise the prescribed motion
  virtual bool isPrescribed() const { return false; }
  /// true if G has columns for the System's extra coordinates too (e.g. a deformable node tied to
  /// a body, core/deformable/node_constraint.hpp): calcAcceleration then gets a rows x ndof block
  /// and the State's q includes the extra coordinates (not combinable with a coordinate map)
  virtual bool actsOnExtraCoordinates() const { return false; }
  /// true if the multipliers act through rows H other than G: M qddot = f - H^T lambda while
  /// G qddot = rhs still holds (sliding Coulomb friction, whose force is tied to the normal
  /// multiplier: core/dynamics/unilateral/held_contacts.hpp). The System then solves the
  /// non-symmetric KKT system.
  virtual bool hasForceRows() const { return false; }
  /// H (rows x the same columns as G); called only when hasForceRows(); needs Stage::Velocity
  virtual void calcForceRows(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> H) const {
    (void)H;
  }
};

}  // namespace redmax
