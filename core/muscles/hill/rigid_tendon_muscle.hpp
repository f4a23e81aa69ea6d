#pragma once
// OpenSim's RigidTendonMuscle and Schutte1993Muscle_Deprecated: muscles whose curves are Function
// properties (curve.hpp), each absent one OpenSim's default SimmSpline. docs/muscle_dynamics.md §2.5.
#include "core/muscles/hill/curve.hpp"
#include "core/muscles/hill/deprecated_muscle.hpp"
#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/hill/muscle_properties.hpp"
#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill {

/// RigidTendonMuscle: no states; the control is the activation (not clamped, as OpenSim's
/// getControl); the tendon stays at its slack length, the fibre of fixed width
/// w = l_opt sin(phi_opt) spans the rest: l_f = sqrt(max(0, l_MT - l_s)^2 + w^2) (l_f = the rest
/// and no pennation when w <= SqrtEps), v_f = the path's lengthening speed (OpenSim's, not
/// projected), F_T = F_max (a fal(l_f / l_opt) fv(v_f / (v_max l_opt)) + clamp(fpe, 0, 10)) cos(phi).
class RigidTendonMuscle final : public MuscleWithProperties {
 public:
  explicit RigidTendonMuscle(const MuscleParameters& p);

  std::string className() const override { return "RigidTendonMuscle"; }
  const std::vector<std::string>& stateNames() const override;
  void defaultState(double*) const override {}
  void calc(const double* z, const MusculotendonInput& in, MuscleOutput& out, double* zdot) const override;
  /// OpenSim's computeInitialFiberEquilibrium is empty for this class: nothing to do
  void equilibrate(const MusculotendonInput&, double*) const override {}
  std::vector<std::pair<std::string, double>> parameterList() const override;
  /// Muscle's: F_max a fal fv cos(phi) at this class's own (rigid) fibre length and velocity
  double inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const override;

  const Curve& activeForceLength() const { return *fal_; }
  const Curve& passiveForceLength() const { return *fpe_; }
  const Curve& forceVelocity() const { return *fv_; }

 private:
  struct Kinematics {
    double l_f, cos_phi, lceN, vN;
  };
  Kinematics kinematics(const MusculotendonInput& in) const;
  CurvePtr fal_, fpe_, fv_;
};

/// Schutte1993Muscle_Deprecated (OpenSim's computeActuation, calcTendonForce,
/// calcNonzeroPassiveForce, calcFiberVelocity, computeIsometricForce): states activation and
/// fiber_length, time normalized by time_scale:
///   da/dt = (u - a)(activation1 u + activation2) / time_scale when u >= a, else
///           (u - a) activation2 / time_scale (a unclamped);
///   tendon: strain e = (l_T - l_s) / l_s, force 0 for e < 0, else the tendon curve at e;
///   passive: the passive curve, or exp(8 (lceN - 1)) / exp(4) when the file gives none (OpenSim's
///   getValueIsDefault); active: the curve, clamped at 0;
///   fibre velocity from Fv = max(0, F_T / cos(phi) - F_PE) through Schutte's damped inverse
///   force-velocity (kv 0.15, slope 0.13, fmax 1.4), in l_opt / time_scale per second;
///   at 90 degrees pennation the Deprecated stiff-tendon velocity (as Thelen2003Muscle_Deprecated).
class Schutte1993MuscleDeprecated final : public MuscleWithProperties {
 public:
  explicit Schutte1993MuscleDeprecated(const MuscleParameters& p);

  std::string className() const override { return "Schutte1993Muscle_Deprecated"; }
  const std::vector<std::string>& stateNames() const override;
  /// ActivationFiberLengthMuscle_Deprecated has no default_* properties: both 0
  void defaultState(double* z) const override;
  void calc(const double* z, const MusculotendonInput& in, MuscleOutput& out, double* zdot) const override;
  /// computeIsometricForce (deprecated_muscle.hpp): within 0.01 N, 100 iterations, never an error
  void equilibrate(const MusculotendonInput& in, double* z) const override;
  std::vector<std::pair<std::string, double>> parameterList() const override;
  double inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const override;

  /// normalized tendon force at strain e (0 below 0)
  double tendonForce(double strain) const;
  /// normalized passive force at lceN (the curve, or the exponential)
  double passiveForce(double lceN) const;
  /// normalized fibre velocity (l_opt per time_scale) from the velocity-dependent force
  double fiberVelocity(double a, double active, double Fv) const;

 private:
  IsometricCurves isometricCurves() const;
  CurvePtr tendon_, active_, passive_;  // passive_ null: OpenSim's exponential
  double time_scale_ = 0.1, activation1_ = 7.667, activation2_ = 1.459854, damping_ = 0.1;
};

}  // namespace redmax::hill
