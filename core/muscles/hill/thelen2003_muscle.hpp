#pragma once
// OpenSim's Thelen2003Muscle (4.x: Millard's re-implementation with the fixed-width pennation
// model, clamped first-order activation and an extrapolated force-velocity inverse) and
// Thelen2003Muscle_Deprecated (the 1.x-3.x code the arm26 ForwardTool standard was made with).
// States (activation, fiber_length) in that order; docs/muscle_dynamics.md gives the equations.
#include "core/muscles/hill/deprecated_muscle.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/hill/muscle_properties.hpp"
#include "core/muscles/hill/parameters.hpp"
#include "core/muscles/hill/thelen2003_curves.hpp"

namespace redmax::hill {

/// OpenSim's MuscleFirstOrderActivationDynamicModel: a in [a_min, 1],
/// da/dt = (u - a) / tau with tau = tau_a (0.5 + 1.5 a) when u > a, tau_d / (0.5 + 1.5 a) else
/// [Thelen 2003, Eq. 6, 7].
struct FirstOrderActivation {
  double activation_time_constant = 0.015, deactivation_time_constant = 0.050;
  double minimum_activation = 0.01;
  double clamp(double a) const;
  double derivative(double a, double u) const;
};

class Thelen2003Muscle final : public MuscleWithProperties {
 public:
  /// reads OpenSim 4's properties with its defaults; throws MuscleParameterError as
  /// Thelen2003Muscle::extendFinalizeFromProperties does
  explicit Thelen2003Muscle(const MuscleParameters& p);

  std::string className() const override { return "Thelen2003Muscle"; }
  const std::vector<std::string>& stateNames() const override;
  void defaultState(double* z) const override;
  void calc(const double* z, const MusculotendonInput& in, MuscleOutput& out, double* zdot) const override;
  /// OpenSim's initMuscleState: Newton on l_f with halving steps, tolerance max(1e-8 F_max,
  /// 10 SignificantReal), 20 iterations, velocity split by the stiffnesses; the fibre stops at
  /// its minimum length
  void equilibrate(const MusculotendonInput& in, double* z) const override;
  std::vector<std::pair<std::string, double>> parameterList() const override;
  /// rigid tendon: l_f from the fixed-width pennation, v_f = speed cos(phi), then
  /// F_max a fal fv cos(phi) with a clamped to [minimum_activation, 1] and fv from the
  /// force-velocity inverse (calcfvInv, 1e-6, 100 iterations); 0 at or below the minimum length
  double inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const override;

  const Thelen2003Curves& curves() const { return c_; }
  const FixedWidthPennation& pennation() const { return pen_; }
  const FirstOrderActivation& activationModel() const { return act_; }

 private:
  Thelen2003Curves c_;
  double maximum_pennation_angle_;
  FixedWidthPennation pen_;
  FirstOrderActivation act_;
};

class Thelen2003MuscleDeprecated final : public MuscleWithProperties {
 public:
  explicit Thelen2003MuscleDeprecated(const MuscleParameters& p);

  std::string className() const override { return "Thelen2003Muscle_Deprecated"; }
  const std::vector<std::string>& stateNames() const override;
  /// OpenSim's ActivationFiberLengthMuscle_Deprecated has no default_activation or
  /// default_fiber_length property: both default to 0
  void defaultState(double* z) const override;
  void calc(const double* z, const MusculotendonInput& in, MuscleOutput& out, double* zdot) const override;
  /// OpenSim's computeIsometricForce: secant/stiffness iteration to |F_T - F_M cos phi| <= 0.01 N,
  /// 100 iterations; it never reports failure (neither does OpenSim)
  void equilibrate(const MusculotendonInput& in, double* z) const override;
  std::vector<std::pair<std::string, double>> parameterList() const override;
  /// ActivationFiberLengthMuscle_Deprecated's: the isometric tendon force of the equilibrium
  /// iteration (computeIsometricForce) at `activation` times the generic force-velocity factor
  /// 1.8 - 1.8 / (1 + exp((0.04 - v) / 0.18)), v = -cos(phi_opt) speed / (v_max l_opt)
  double inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const override;

  const Thelen2003DeprecatedCurves& curves() const { return c_; }

 private:
  /// the 2.x pennation: asin(l_opt sin(phi_opt) / l_f), 0 and pi/2 at its ends
  double pennation(double l_f, double l_opt) const;
  /// the curves computeIsometricForce iterates on (deprecated_muscle.hpp)
  IsometricCurves isometricCurves() const;

  Thelen2003DeprecatedCurves c_;
  double tau_act_ = 0.01, tau_deact_ = 0.04, Vmax_ = 10.0, Vmax0_ = 5.0;
};

}  // namespace redmax::hill
