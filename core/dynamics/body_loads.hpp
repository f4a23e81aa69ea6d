#pragma once
// External point forces and wrenches applied to bodies (e.g. ground reaction forces), as a
// ForceTerm. A world force f_w at body point x_i gives the body wrench Gamma(x_i)^T R_i^T f_w
// [D Eq. 3.14]; generalized force J_mr^T of the stacked wrenches.
#include <vector>

#include "core/dynamics/force_term.hpp"

namespace redmax {

struct PointForce {
  int body = -1;
  Vec3 point_i = Vec3::Zero();   // application point, body frame
  Vec3 force_w = Vec3::Zero();   // force, world frame
};

struct BodyWrench {
  int body = -1;
  Vec3 torque_w = Vec3::Zero();  // pure torque, world frame
  Vec3 force_w = Vec3::Zero();   // force through the body origin, world frame
};

/// Loads that the caller sets before each evaluation (not owned by the State: they are inputs).
class BodyLoads final : public ForceTerm {
 public:
  std::string name() const override { return "body_loads"; }
  void addForce(const Model& model, const State& s, const SkeletonWorkspace& ws, VecX& f) const override;
  /// potential of constant world forces: -sum f_w . x_w (torques have no potential in general;
  /// they contribute nothing here), so that energy bookkeeping closes for constant forces
  double potentialEnergy(const Model& model, const State& s, const SkeletonWorkspace& ws) const override;

  std::vector<PointForce> point_forces;
  std::vector<BodyWrench> wrenches;
};

}  // namespace redmax
