#pragma once
// One-axis and zero-axis joints [D Sec. 4.5.1, 4.5.2, 4.5.7]. Their S is constant, so Sdot = 0.
#include "core/joints/joint_kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

/// Rigid attachment: Q = I, S is 6 x 0 [D Sec. 4.5.1].
struct Fixed {
  static constexpr int kNq = 0;
  int nq() const { return 0; }
  void calc(const VecJ&, const VecJ&, JointKinematics& out) const {
    out.resize(0);
    out.Q.setIdentity();
  }
};

/// Rotation about a unit axis given in the joint frame: Q = exp([S q]), S = (axis; 0) [D Eq. 4.41].
struct Revolute {
  static constexpr int kNq = 1;
  Vec3 axis = Vec3::UnitZ();
  int nq() const { return 1; }
  void calc(const VecJ& q, const VecJ&, JointKinematics& out) const {
    out.resize(1);
    out.Q = makeE(rotationAxisAngle(axis, q[0]), Vec3::Zero());
    out.S.col(0) << axis, Vec3::Zero();
  }
};

/// Translation along a unit axis: Q = (I, a q), S = (0; a) [D Eq. 4.23-4.24].
struct Prismatic {
  static constexpr int kNq = 1;
  Vec3 axis = Vec3::UnitX();
  int nq() const { return 1; }
  void calc(const VecJ& q, const VecJ&, JointKinematics& out) const {
    out.resize(1);
    out.Q = makeTranslation(axis * q[0]);
    out.S.col(0) << Vec3::Zero(), axis;
  }
};

}  // namespace redmax
