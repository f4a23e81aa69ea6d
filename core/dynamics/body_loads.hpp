#pragma once
// External point forces and wrenches applied to bodies (e.g. ground reaction forces). A world
// force f_w at body point x_i gives the body wrench Gamma(x_i)^T R_i^T f_w [D Eq. 3.14];
// generalized force J_mr^T of the stacked wrenches.
//
// Two ways in: loads that change every evaluation (measured ground reactions in inverse dynamics)
// are an input of the evaluation, DynamicsWorkspace::loads, set by the caller next to the State;
// loads that belong to the system itself (a constant push) are a BodyLoads term.
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

/// A set of external loads; loads on the world (body -1) do nothing.
struct ExternalLoads {
  std::vector<PointForce> point_forces;
  std::vector<BodyWrench> wrenches;
  bool empty() const { return point_forces.empty() && wrenches.empty(); }
  void clear() {
    point_forces.clear();
    wrenches.clear();
  }
};

/// add the generalized force of a wrench on `body` (body frame: torque then force through the
/// origin) to f, J_mr^T w [D Eq. 3.14]; nothing for the world (body < 0). Needs Stage::Position.
void addBodyWrench(const Model& model, const SkeletonWorkspace& ws, int body, const Vec6& wrench_i, VecX& f);
/// the same for a world force at a body point (body frame) and for a pure world torque
void addPointForce(const Model& model, const SkeletonWorkspace& ws, int body, const Vec3& point_i,
                   const Vec3& force_w, VecX& f);
void addBodyTorque(const Model& model, const SkeletonWorkspace& ws, int body, const Vec3& torque_w, VecX& f);

/// add the generalized force of `loads` to f (nr or more entries; needs Stage::Position)
void addExternalLoads(const Model& model, const SkeletonWorkspace& ws, const ExternalLoads& loads, VecX& f);
/// potential of constant world forces: -sum f_w . x_w (torques have no potential in general;
/// they contribute nothing here), so that energy bookkeeping closes for constant forces
double externalLoadsPotential(const SkeletonWorkspace& ws, const ExternalLoads& loads);

/// Loads owned by the system (the same at every evaluation).
class BodyLoads final : public ForceTerm, public ExternalLoads {
 public:
  std::string name() const override { return "body_loads"; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  /// externalLoadsPotential
  double potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const override;
};

}  // namespace redmax
