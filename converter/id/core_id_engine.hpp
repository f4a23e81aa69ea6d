#pragma once
// The core (REDMAX) engine of the inverse-dynamics tool: tau = M qddot - f [D Eq. 4.18] with
// gravity and the external loads as a BodyLoads term, constraints ignored (OpenSim's
// calcResidualForceIgnoringConstraints).
//
// OpenSim compatibility for Ball/Free/Ellipsoid joints (IdEngineOptions::rates_as_u). OpenSim puts
// the data's Euler-angle rates into Simbody's u, which Simbody reads as the angular velocity of M
// in F (expressed in F). The core keeps qdot = dq/dt and reproduces this by a change of velocity
// variables per marked joint (block-diagonal, so it is exact for the whole tree):
//   u = T(q) qdot,  T = blockdiag(R, R) S  (free: [w_F; v_F])   or  T = R S_w  (ball, ellipsoid: w_F)
//   udot = T qddot + Tdot qdot,  Tdot = blockdiag(R[w], R[w]) S + blockdiag(R, R) Sdot
// with R = R_FM(q), S and Sdot the joint's twist map in M [D Eq. 4.29] and w = S_w qdot.
// Given OpenSim's u and udot the engine solves qdot = T^-1 u, qddot = T^-1 (udot - Tdot qdot),
// runs the core inverse dynamics, and returns tau_u = T^-T tau_qdot (power balance
// tau_u . u = tau_qdot . qdot). The result is the generalized force OpenSim writes, computed from
// the core's exact dynamics.
#include <memory>
#include <vector>

#include "converter/id/id_engine.hpp"
#include "core/dynamics/system.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/joints/joint.hpp"

namespace redmax::osim {

/// OpenSim's speed map of one joint marked rates_as_u: u = T(q) qdot (nu x nq; nu = 6 for a free
/// joint, 3 for ball and ellipsoid, nq for a Composite whose first part is such a joint, the rest
/// identity) and, if Tdot is given, its time derivative along qdot. A Reversed joint uses its inner
/// joint's map (u keeps its meaning under Simbody's Direction::Reverse). Throws IdEngineError for
/// any other joint type.
void calcOpenSimSpeedMap(const Joint& joint, const VecJ& q, const VecJ& qdot, MatJ& T, MatJ* Tdot);

/// true if calcOpenSimSpeedMap accepts the joint
bool hasOpenSimSpeedMap(const Joint& joint);

class CoreIdEngine final : public IdEngine {
 public:
  /// Throws IdEngineError if a marked joint has no OpenSim speed map, or the options do not
  /// match the model's joints.
  explicit CoreIdEngine(Model model, IdEngineOptions options = {});
  /// With inertial musculotendons: a MuscleTerm over `muscles` (core/dynamics/muscle_term.hpp)
  /// joins the System when any of them carries mass points, so tau gains the muscles' inertia,
  /// quadratic velocity and gravity terms [D Eq. 5.7]. The term works in the core's qdot = dq/dt
  /// convention like the rest of the system, so the rates_as_u change of variables applies
  /// unchanged. Also throws ModelError for a muscle that does not fit the model.
  CoreIdEngine(Model model, std::vector<Muscle> muscles, IdEngineOptions options = {});
  std::string name() const override { return "core"; }
  void calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                             const std::vector<IdLoadSample>& loads, VecX& tau) override;

  const Model& model() const { return system_.model(); }
  const System& system() const { return system_; }
  /// sum of the muscles' mass points (kg); 0 without muscle mass
  double muscleMass() const { return muscle_mass_; }
  /// (qdot, qddot) in the core's own convention for the last frame solved (equal to (v, vdot)
  /// without marked joints)
  const State& lastState() const { return state_; }
  const VecX& lastQddot() const { return qddot_; }

 private:
  System system_;
  std::shared_ptr<BodyLoads> loads_;
  DynamicsWorkspace ws_;
  IdEngineOptions options_;
  std::vector<int> marked_;  // marked joint slots
  std::vector<Mat4> E_wi_;
  State state_;
  VecX qddot_;
  std::vector<MatJ> T_;  // per marked joint (for mapping tau back)
  double muscle_mass_ = 0.0;
};

}  // namespace redmax::osim
