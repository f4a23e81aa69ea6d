#pragma once
// A joint used in the opposite direction (Simbody's Direction::Reverse, which OpenSim applies when
// the multibody tree reaches a joint's child before its parent; docs/opensim_compatibility.md §3.1). The
// coordinates keep their meaning; the tree's inboard body carries the joint's M frame and the
// outboard body its F frame, so the joint transform is inverted:
//   Q'(q) = Q(q)^-1.
// Differentiating Q' = Q^-1 gives Q'^-1 Q'dot = -Qdot Q^-1 = -Q (Q^-1 Qdot) Q^-1, so the twist of
// the new child frame (F) relative to the new parent frame (M), expressed in F, is
//   S'    = -Ad(Q) S                                                          [D Eq. 3.15]
//   Sdot' = -Addot(Q) S - Ad(Q) Sdot = -Ad(Q) (ad(S qdot) S + Sdot)           [D Eq. 3.19-3.20]
// (d/dt Ad(Q) = Ad(Q) ad(phi) with phi = S qdot the twist of M in F, expressed in M).
#include <memory>

#include "core/joints/joint_kinematics.hpp"

namespace redmax {

struct Joint;

struct Reversed {
  /// the joint as defined in the file (shared and immutable, so copies stay cheap)
  std::shared_ptr<const Joint> inner;

  /// reverses a Fixed joint (the default alternative needs a default constructor)
  Reversed();
  explicit Reversed(Joint joint);

  int nq() const;
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
  /// the inner joint's chart switch: it keeps Q, hence Q^-1, and the motion
  bool reparameterize(VecJ& q, VecJ& qdot) const;
  /// the inner joint's (S' = -Ad(Q) S has the rank of S)
  double singularityDistance(const VecJ& q) const;
};

}  // namespace redmax
