#pragma once
// Pure translation joints [D Sec. 4.5.3, 4.5.4]. S is constant, so Sdot = 0.
#include "core/joints/joint_kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

/// Translation in the joint x-y plane: Q = (I, (q1, q2, 0)), S = (0; e_x e_y)
/// [D Eq. 4.25-4.26]. q = (x, y) in metres, expressed in F (= M, no rotation).
struct Planar {
  static constexpr int kNq = 2;
  int nq() const { return 2; }
  void calc(const VecJ& q, const VecJ&, JointKinematics& out) const {
    out.resize(2);
    out.Q = makeTranslation(Vec3(q[0], q[1], 0.0));
    out.S(3, 0) = 1.0;
    out.S(4, 1) = 1.0;
  }
};

/// Free translation: Q = (I, q), S = (0; I) [D Eq. 4.27-4.28]. q in metres, expressed in F.
struct Translational {
  static constexpr int kNq = 3;
  int nq() const { return 3; }
  void calc(const VecJ& q, const VecJ&, JointKinematics& out) const {
    out.resize(3);
    out.Q = makeTranslation(Vec3(q[0], q[1], q[2]));
    out.S.bottomRows<3>().setIdentity();
  }
};

}  // namespace redmax
