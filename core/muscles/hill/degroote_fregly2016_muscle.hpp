#pragma once
// OpenSim's DeGrooteFregly2016Muscle [De Groote et al. 2016]: analytic curves (a sum of three
// Gaussian-like terms for the active force-length, an exponential passive curve offset to zero
// at 0.2 l_opt, an exponential tendon, an asinh-shaped force-velocity with a closed-form inverse),
// fixed-width pennation without a maximum angle, tanh-smoothed activation dynamics, and the
// normalized tendon force as the elastic tendon's state (explicit tendon dynamics).
// States: activation (unless ignore_activation_dynamics), normalized_tendon_force (unless
// ignore_tendon_compliance), in that order.
#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/hill/muscle_properties.hpp"
#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill {

/// the curves, as functions of normalized quantities
struct DeGrooteFregly2016Curves {
  double active_force_width_scale = 1.0;
  double passive_fiber_strain_at_one_norm_force = 0.6;
  double tendon_strain_at_one_norm_force = 0.049;
  bool ignore_passive_fiber_force = false;

  double activeForceLength(double lceN) const;
  double activeForceLengthDerivative(double lceN) const;
  double passiveForceLength(double lceN) const;
  double passiveForceLengthDerivative(double lceN) const;
  /// kT = ln((1 + c3)/c1) / (1 + e0 - c2): the tendon curve passes through (1 + e0, 1)
  double tendonStiffness() const;
  double tendonForceLength(double tlN) const;
  double tendonForceLengthDerivative(double tlN) const;
  double tendonForceLengthInverse(double fT) const;
  static double forceVelocity(double vN);
  static double forceVelocityDerivative(double vN);
  static double forceVelocityInverse(double fv);
};

class DeGrooteFregly2016Muscle final : public MuscleWithProperties {
 public:
  /// OpenSim 4's properties and checks; tendon_compliance_dynamics_mode is 0 (explicit) or 1
  /// (implicit, whose tendon-force derivative is a control: not modelled, refused)
  explicit DeGrooteFregly2016Muscle(const MuscleParameters& p);

  std::string className() const override { return "DeGrooteFregly2016Muscle"; }
  const std::vector<std::string>& stateNames() const override { return state_names_; }
  void defaultState(double* z) const override;
  void calc(const double* z, const MusculotendonInput& in, MuscleOutput& out, double* zdot) const override;
  /// OpenSim's computeInitialFiberEquilibrium: bisection on the normalized tendon force in
  /// [0, 5] to 1e-10 with the tendon at rest (the path's speed goes to the fibre); throws when the
  /// equilibrium residual has the same sign at both ends
  void equilibrate(const MusculotendonInput& in, double* z) const override;
  std::vector<std::pair<std::string, double>> parameterList() const override;
  /// rigid tendon at its slack length: F_max a fal fv along the fibre (OpenSim returns
  /// MuscleDynamicsInfo::activeFiberForce, not its projection on the tendon), v_f = speed cos(phi)
  double inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const override;

  const DeGrooteFregly2016Curves& curves() const { return c_; }
  /// the equilibrium residual fT - F_M cos(phi) / F_max at tendon force fT, tendon at rest
  double equilibriumResidual(const MusculotendonInput& in, double activation, double fT) const;

 private:
  struct Eval {
    double fiber_length, lceN, cos_phi, sin_phi, tendon_length, tlN, fal, fpe;
    double fiber_velocity, vN, fv, tendon_velocity_n;
    double active, passive, fiber_along, tendon_force;
  };
  void evaluate(double a, double fT, const MusculotendonInput& in, bool explicit_tendon, Eval& e) const;

  DeGrooteFregly2016Curves c_;
  double tau_act_ = 0.015, tau_deact_ = 0.060, default_tendon_force_ = 0.5, beta_ = 0.0, smoothing_ = 0.1;
  std::vector<std::string> state_names_;
  int i_act_ = -1, i_ft_ = -1;
};

}  // namespace redmax::hill
