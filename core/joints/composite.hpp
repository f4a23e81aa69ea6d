#pragma once
// Composite joint [D Sec. 4.5.9]: Q = Q_1 Q_2 ... Q_N, a chain of joints with massless bodies
// in between. Parts may themselves be composites (Q = Q_1 (Q_2 Q_3) is the same joint as
// Q_1 Q_2 Q_3). Generalising [D Eq. 4.48-4.52] to N parts, with T_k = Q_{k+1} ... Q_N:
//   S    = ( Ad(T_1^-1) S_1, ..., Ad(T_{N-1}^-1) S_{N-1}, S_N )
// computed left to right: on appending part k, the columns so far become Ad(Q_k^-1) S and
//   Sdot <- Ad(Q_k^-1) Sdot - ad(S_k qdot_k) Ad(Q_k^-1) S                     [D Eq. 4.52]
// q is the parts' coordinates concatenated in order; at most 6 in all.
#include <vector>

#include "core/joints/joint_kinematics.hpp"

namespace redmax {

struct Joint;

struct Composite {
  std::vector<Joint> parts;

  Composite();
  /// throws JointError if the parts have more than 6 coordinates in all
  explicit Composite(std::vector<Joint> parts);

  int nq() const;
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
  /// passes the chart switch to every part (e.g. an exponential-coordinate part)
  bool reparameterize(VecJ& q, VecJ& qdot) const;
  /// smallest singularityDistance of the parts (their own coordinate singularities only, not
  /// configurations where the parts' motions happen to align)
  double singularityDistance(const VecJ& q) const;
};

}  // namespace redmax
