#pragma once
// The closed set of joint types as a std::variant (STYLE.md "Joints: std::variant, not virtual").
// Each alternative is a plain struct with
//   int nq() const;                                        number of coordinates (= velocities)
//   void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;   Q, S, Sdot
// and optionally
//   bool reparameterize(VecJ& q, VecJ& qdot) const;        chart switch (exponential coordinates)
// Every joint here uses qdot = dq/dt, so q integrates as q += h qdot.
#include <string>
#include <variant>

#include "core/joints/basic_joints.hpp"

namespace redmax {

using JointVariant = std::variant<Fixed, Revolute, Prismatic>;

/// A joint of any type. Value semantics: copying a Model copies its joints.
struct Joint {
  JointVariant v;

  Joint() : v(Fixed{}) {}
  template <class T>
  Joint(T j) : v(std::move(j)) {}  // NOLINT: implicit from any alternative

  int nq() const;
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
  /// switch coordinate chart if the joint needs it (e.g. |q| near 2 pi for exponential
  /// coordinates [D Sec. 4.5.8]); updates q and qdot so the motion is unchanged. Returns true
  /// when it changed them.
  bool reparameterize(VecJ& q, VecJ& qdot) const;
  /// short type name for summaries and errors
  std::string typeName() const;
};

}  // namespace redmax
