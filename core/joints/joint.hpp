#pragma once
// The closed set of joint types as a std::variant (docs/design.md §5).
// Each alternative is a plain struct with
//   int nq() const;                                        number of coordinates (= velocities)
//   void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;   Q, S, Sdot
// and optionally
//   bool reparameterize(VecJ& q, VecJ& qdot) const;        chart switch (exponential coordinates)
// Every joint here uses qdot = dq/dt, so q integrates as q += h qdot.
//
// Types [D Sec. 4.5]: Fixed, Revolute, Prismatic (basic_joints.hpp); Planar, Translational
// (translational_joints.hpp); SphericalEuler (any of 12 sequences), Universal (euler_joints.hpp);
// SphericalExp (spherical_exp.hpp); Composite (composite.hpp); Free2D, Free3D (free_joints.hpp);
// SplineCurve, SplineSurface (spline_joints.hpp); FunctionBased = OpenSim CustomJoint
// (function_based.hpp, functions in functions.hpp); Ellipsoid (ellipsoid.hpp, OpenSim
// EllipsoidJoint); Reversed (reversed.hpp: any joint used in the opposite direction).
#include <string>
#include <variant>

#include "core/joints/basic_joints.hpp"
#include "core/joints/composite.hpp"
#include "core/joints/ellipsoid.hpp"
#include "core/joints/euler_joints.hpp"
#include "core/joints/free_joints.hpp"
#include "core/joints/function_based.hpp"
#include "core/joints/reversed.hpp"
#include "core/joints/spherical_exp.hpp"
#include "core/joints/spline_joints.hpp"
#include "core/joints/translational_joints.hpp"

namespace redmax {

using JointVariant =
    std::variant<Fixed, Revolute, Prismatic, Planar, Translational, SphericalEuler, Universal,
                 SphericalExp, Composite, Free2D, Free3D, SplineCurve, SplineSurface, FunctionBased,
                 Ellipsoid, Reversed>;

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
  /// Distance from a coordinate singularity in [0, 1] (0 = S has lost rank there): the Euler
  /// gimbal-lock measure |sin q2| or |cos q2|, the exponential-map |sin(th/2)/(th/2)|, the minimum
  /// over a composite's parts; 1 for joints whose coordinates have no singular configuration.
  /// For integrators and solvers to report, e.g. a simulation that ran into gimbal lock.
  double singularityDistance(const VecJ& q) const;
  /// short type name for summaries and errors
  std::string typeName() const;
};

}  // namespace redmax
