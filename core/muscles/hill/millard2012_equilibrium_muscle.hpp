#pragma once
// OpenSim's Millard2012EquilibriumMuscle [Millard 2013]: quintic-Bezier active and passive
// force-length, force-velocity and tendon force-length curves; an elastic tendon with the fibre
// length as state (or a rigid tendon, ignore_tendon_compliance), an optional fibre damping
// (fiber_damping >= 0.001: the damped model, whose fibre velocity solves the damped equilibrium
// by Newton; below it the classic Hill model, whose velocity comes from the inverse force-velocity
// curve), first-order activation (or activation = excitation, ignore_activation_dynamics).
// States: activation (unless ignored), fiber_length (unless the tendon is rigid), in that order.
#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/hill/muscle_properties.hpp"
#include "core/muscles/hill/parameters.hpp"
#include "core/muscles/hill/smooth_segmented_function.hpp"
#include "core/muscles/hill/thelen2003_muscle.hpp"

namespace redmax::hill {

/// the four curves' XML properties, after OpenSim's defaults and the model's adjustments
struct Millard2012CurveParameters {
  // ActiveForceLengthCurve
  double min_norm_active_fiber_length = 0.47 - 0.0259, transition_norm_fiber_length = 0.73;
  double max_norm_active_fiber_length = 1.8123, shallow_ascending_slope = 0.8616, minimum_value = 0.1;
  // ForceVelocityCurve
  double concentric_slope_at_vmax = 0.0, concentric_slope_near_vmax = 0.25, isometric_slope = 5.0;
  double eccentric_slope_at_vmax = 0.0, eccentric_slope_near_vmax = 0.15;
  double max_eccentric_velocity_force_multiplier = 1.4, concentric_curviness = 0.6, eccentric_curviness = 0.9;
  // FiberForceLengthCurve (stiffnesses and curviness: 2/(e1 - e0), 0.2, 0.75 when all absent)
  double fpe_strain_at_zero_force = 0.0, fpe_strain_at_one_norm_force = 0.7;
  double fpe_stiffness_at_low_force = 0.2, fpe_stiffness_at_one_norm_force = 2.0 / 0.7, fpe_curviness = 0.75;
  // TendonForceLengthCurve (1.375/e0, 2/3, 0.5 when all absent)
  double tendon_strain_at_one_norm_force = 0.049, tendon_stiffness_at_one_norm_force = 1.375 / 0.049;
  double tendon_norm_force_at_toe_end = 2.0 / 3.0, tendon_curviness = 0.5;
};

class Millard2012EquilibriumMuscle final : public MuscleWithProperties {
 public:
  /// reads OpenSim 4's properties with its defaults, applies the adjustments of
  /// extendFinalizeFromProperties (classic model: minimum_value >= 0.1 and slopes at v_max >=
  /// half those near it; damped or rigid: minimum_value and the slopes at v_max 0) and throws
  /// MuscleParameterError where OpenSim's checks fail
  explicit Millard2012EquilibriumMuscle(const MuscleParameters& p);

  std::string className() const override { return "Millard2012EquilibriumMuscle"; }
  const std::vector<std::string>& stateNames() const override { return state_names_; }
  void defaultState(double* z) const override;
  void calc(const double* z, const MusculotendonInput& in, MuscleOutput& out, double* zdot) const override;
  /// OpenSim's computeFiberEquilibrium (static: the fibre at rest): Newton on l_f with halving
  /// steps to max(1e-8 F_max, 10 SignificantReal), 200 iterations; the fibre stops at its
  /// minimum length. Nothing to do for a rigid tendon.
  void equilibrate(const MusculotendonInput& in, double* z) const override;
  std::vector<std::pair<std::string, double>> parameterList() const override;
  /// rigid tendon: l_f from the pennation model, v_f = speed cos(phi); 0 at or below
  /// minFiberLength(), else F_max a fal(lceN) fv(vN) cos(phi') with a clamped to
  /// [minimum_activation, 1] and, as OpenSim's calcActiveFiberForceAlongTendon does, phi'
  /// the pennation model evaluated at the normalized fibre length lceN
  double inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const override;

  const Millard2012CurveParameters& curveParameters() const { return cp_; }
  const SmoothSegmentedFunction& activeForceLengthCurve() const { return fal_; }
  const SmoothSegmentedFunction& forceVelocityCurve() const { return fv_; }
  const SmoothSegmentedFunction& forceVelocityInverseCurve() const { return fv_inv_; }
  const SmoothSegmentedFunction& fiberForceLengthCurve() const { return fpe_; }
  const SmoothSegmentedFunction& tendonForceLengthCurve() const { return fse_; }
  const FixedWidthPennation& pennation() const { return pen_; }
  /// max(SignificantReal, min_norm_active_fiber_length l_opt, the pennation model's minimum)
  double minFiberLength() const { return l_min_; }
  bool damped() const { return damped_; }
  double fiberDamping() const { return beta_; }

 private:
  double activationOf(const double* z, double excitation) const;

  Millard2012CurveParameters cp_;
  double beta_ = 0.1, maximum_pennation_angle_ = 0.0, l_min_ = 0.0;
  bool damped_ = true;
  FixedWidthPennation pen_;
  FirstOrderActivation act_;
  SmoothSegmentedFunction fal_, fv_, fv_inv_, fpe_, fse_;
  std::vector<std::string> state_names_;
  int i_act_ = -1, i_len_ = -1;  ///< indices into z, -1 when the state is absent
};

}  // namespace redmax::hill
