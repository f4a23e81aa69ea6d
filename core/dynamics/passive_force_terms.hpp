#pragma once
// OpenSim's passive force elements as ForceTerms (docs/forward.md §3), in SI units (the
// converter turns CoordinateLimitForce's degrees into radians):
//   CoordinateLimitForce    f = -K_up(q) (q - q_up) + K_lo(q) (q_lo - q) - c (s_up + s_lo) qdot
//                           K_up = K_upper s_up, s_up = step((q - q_up) / w); K_lo = K_lower s_lo,
//                           s_lo = step((q_lo - q) / w); step(x) = x^3 (10 - 15 x + 6 x^2) on
//                           [0, 1] (SimTK::Function::Step), w the transition. OpenSim writes the
//                           damping factor as K_up/K_upper + K_lo/K_lower, i.e. s_up + s_lo
//                           (here also defined for a zero stiffness). V: OpenSim's
//                           computePotentialEnergy, the integral of the elastic part.
//   SpringGeneralizedForce  f = -k (q - q_rest) - c qdot;  V = k (q - q_rest)^2 / 2
//   PointToPointSpring      tension k (L - L0) pulling the two body points together
//                           (SimTK::Force::TwoPointLinearSpring);  V = k (L - L0)^2 / 2
//   BushingForce            SimTK::Force::LinearBushing between frame F (on body1) and M (on
//                           body2): q = (body-fixed x-y-z angles of M in F, position of M's origin
//                           in F), f = -(k .* q + c .* qdot); applied as the wrenches whose power
//                           is f . qdot (below);  V = sum k_i q_i^2 / 2
// All are explicit (addStiffnessDamping adds nothing); the potentials let a simulation's energy
// bookkeeping close.
#include <string>
#include <vector>

#include "core/dynamics/force_term.hpp"

namespace redmax {

class CoordinateLimitForceTerm final : public ForceTerm {
 public:
  struct Limit {
    std::string name;
    int coordinate = -1;  ///< skeleton coordinate (q_r)
    double upper_limit = 0.0, lower_limit = 0.0;          ///< rad or m
    double upper_stiffness = 0.0, lower_stiffness = 0.0;  ///< N m/rad or N/m, >= 0
    double damping = 0.0;                                 ///< N m s/rad or N s/m, >= 0
    double transition = 0.0;                              ///< rad or m, > 0
  };
  /// throws ModelError for a coordinate outside the model, negative stiffness or damping, a
  /// transition that is not positive, non-finite values
  CoordinateLimitForceTerm(const Model& model, std::vector<Limit> limits);
  std::string name() const override { return "coordinate_limit_forces"; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  double potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const override;
  const std::vector<Limit>& limits() const { return limits_; }
  /// the generalized force of one limit at (q, qdot), and its potential at q
  static double force(const Limit& l, double q, double qdot);
  /// d force / dq and d force / dqdot at (q, qdot), analytic (the adjoint's step Jacobians,
  /// core/dynamics/id_derivatives.hpp)
  static void forceDerivatives(const Limit& l, double q, double qdot, double& dq, double& dqdot);
  static double potential(const Limit& l, double q);

 private:
  std::vector<Limit> limits_;
};

class SpringGeneralizedForceTerm final : public ForceTerm {
 public:
  struct Spring {
    std::string name;
    int coordinate = -1;
    double stiffness = 0.0, rest_length = 0.0, viscosity = 0.0;
  };
  /// throws ModelError for a coordinate outside the model, negative or non-finite parameters
  SpringGeneralizedForceTerm(const Model& model, std::vector<Spring> springs);
  std::string name() const override { return "spring_generalized_forces"; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  double potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const override;
  const std::vector<Spring>& springs() const { return springs_; }

 private:
  std::vector<Spring> springs_;
};

class PointToPointSpringTerm final : public ForceTerm {
 public:
  struct Spring {
    std::string name;
    int body1 = -1, body2 = -1;  ///< core bodies; -1: ground
    Vec3 point1 = Vec3::Zero(), point2 = Vec3::Zero();  ///< in body1's, body2's frame
    double stiffness = 0.0, rest_length = 0.0;
  };
  /// throws ModelError for a body outside the model, both ends on one body, negative or
  /// non-finite parameters
  PointToPointSpringTerm(const Model& model, std::vector<Spring> springs);
  std::string name() const override { return "point_to_point_springs"; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  double potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const override;
  const std::vector<Spring>& springs() const { return springs_; }
  /// spring k's current length at sk (Stage::Position)
  double length(const SkeletonWorkspace& sk, int k) const;

 private:
  std::vector<Spring> springs_;
};

class BushingForceTerm final : public ForceTerm {
 public:
  struct Bushing {
    std::string name;
    int body1 = -1, body2 = -1;  ///< core bodies; -1: ground
    Mat4 X_1F = Mat4::Identity(), X_2M = Mat4::Identity();  ///< frames F, M in their bodies
    Vec6 stiffness = Vec6::Zero();  ///< rotational x, y, z (N m/rad), translational (N/m), >= 0
    Vec6 damping = Vec6::Zero();    ///< the same order (N m s/rad, N s/m), >= 0
  };
  /// throws ModelError for a body outside the model, both frames on one body, negative or
  /// non-finite parameters
  BushingForceTerm(const Model& model, std::vector<Bushing> bushings);
  std::string name() const override { return "bushing_forces"; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override;
  double potentialEnergy(const Model& model, const State& s, const TermContext& ctx) const override;
  const std::vector<Bushing>& bushings() const { return bushings_; }
  /// bushing k's deflection q (angles, then position of M in F) at sk (Stage::Position), and with
  /// Stage::Velocity its rate qdot
  void calcDeflection(const SkeletonWorkspace& sk, int k, Vec6& q, Vec6* qdot) const;

 private:
  std::vector<Bushing> bushings_;
};

}  // namespace redmax
