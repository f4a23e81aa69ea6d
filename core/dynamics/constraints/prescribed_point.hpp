#pragma once
// Prescribed points: maximal-coordinate inverse dynamics [D Sec. 4.6.5, Eq. 4.109-4.110]. A point
// x_i fixed in body i follows a given world trajectory x_p(t); the three multipliers are the world
// force that the prescription applies at the point.
//
// Sign convention (as PrescribedCoordinate). The System solves M qddot = f - G^T lambda. With
//   C = x_p(t) - p(q),   G = dC/dq = -J,   J = R_i Gamma(x_i) J_i   (body_point.hpp)
// we get -G^T lambda = J^T lambda: lambda is the world force acting on the body at the point. The
// acceleration row -J qddot = rhs with rhs = a_bias - xddot_p(t) says p's acceleration
// J qddot + a_bias equals xddot_p(t) [D Eq. 4.100-4.101 with a moving target]. Errors: pos_err =
// x_p - p, vel_err = xdot_p - pdot, which the System's Baumgarte terms use as for any constraint.
#include <functional>

#include "core/dynamics/constraint.hpp"

namespace redmax {

namespace detail {
struct PointKinematics;
}

/// A point trajectory at one time: position, velocity, acceleration (world frame).
struct PointSample {
  Vec3 x = Vec3::Zero(), v = Vec3::Zero(), a = Vec3::Zero();
};
using PointTrajectory = std::function<PointSample(double t)>;

class PrescribedPoint final : public Constraint {
 public:
  /// body in [0, nb); point in body coordinates; trajectory non-empty. Throws ModelError.
  PrescribedPoint(const Model& model, int body, const Vec3& point, PointTrajectory trajectory,
                  std::string name = "");

  std::string name() const override { return name_; }
  int rows() const override { return 3; }
  bool isPrescribed() const override { return true; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override;
  /// pos_err = x_p(t) - p, vel_err = xdot_p(t) - pdot (world)
  void calcErrors(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override;

  int body() const { return body_; }
  const Vec3& point() const { return x_; }
  PointSample target(double t) const { return traj_(t); }

 private:
  // the point's kinematics into p and the target at s.t
  PointSample evaluate(const Model& model, const State& s, const SkeletonWorkspace& ws,
                       detail::PointKinematics& p) const;
  std::string name_;
  int body_;
  Vec3 x_;
  PointTrajectory traj_;
  int nb_, nr_;
};

}  // namespace redmax
