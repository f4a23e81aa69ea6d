#pragma once
// The properties every OpenSim Muscle has (Muscle, ActivationFiberLengthMuscle), read from
// MuscleParameters with OpenSim's defaults, and OpenSim's fixed-width pennation model
// (MuscleFixedWidthPennationModel): the fibre keeps its height h = l_opt sin(phi_opt) above the
// tendon, so sin(phi) = h / l_f, capped at the maximum pennation angle, which sets the minimum
// fibre length l_min = h / sin(phi_max) (l_opt / 100 when phi_max = 0) [Millard 2013, Sec. 2.3].
#include <string>

#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill {

struct MuscleProperties {
  double max_isometric_force = 1000.0;  ///< F_max, N
  double optimal_fiber_length = 0.1;    ///< l_opt, m
  double tendon_slack_length = 0.2;     ///< l_s, m
  double pennation_angle_at_optimal = 0.0;  ///< phi_opt, rad
  double max_contraction_velocity = 10.0;   ///< v_max, l_opt/s
  bool ignore_tendon_compliance = false;
  bool ignore_activation_dynamics = false;
  double min_control = 0.0, max_control = 1.0;
  double default_activation = 0.05;
  double default_fiber_length = 0.1;
};

/// Read the Muscle properties; `default_min_control` is the class's (Thelen2003Muscle and
/// Millard2012EquilibriumMuscle: minimum_activation). Throws MuscleParameterError for
/// max_isometric_force < 0, optimal_fiber_length <= 0, tendon_slack_length < 0,
/// max_contraction_velocity <= 0 or pennation_angle_at_optimal outside [0, pi/2).
MuscleProperties readMuscleProperties(const MuscleParameters& p, double default_min_control = 0.0);

/// the Muscle properties as a report lists them
void appendMuscleProperties(const MuscleProperties& m, ParameterList& out);

/// OpenSim's MuscleFixedWidthPennationModel
class FixedWidthPennation {
 public:
  FixedWidthPennation() = default;
  /// throws MuscleParameterError (property "maximum_pennation_angle") outside [0, pi/2]
  FixedWidthPennation(double optimal_fiber_length, double pennation_angle_at_optimal,
                      double maximum_pennation_angle);

  double height() const { return h_; }                   ///< l_opt sin(phi_opt)
  double minFiberLength() const { return l_min_; }       ///< h / sin(phi_max)
  double minFiberLengthAlongTendon() const { return l_min_at_; }  ///< l_min cos(phi_max)
  double clampFiberLength(double l_f) const { return l_f > l_min_ ? l_f : l_min_; }
  /// phi(l_f): asin(h / l_f), phi_max at or below the minimum length, 0 without pennation
  double pennationAngle(double l_f) const;
  /// dphi/dt = -(v_f / l_f) tan(phi)
  double pennationAngularVelocity(double tan_phi, double l_f, double v_f) const;
  /// fibre length whose projection on the tendon is l_MT - l_T (the minimum below it)
  double fiberLength(double l_MT, double l_T) const;
  /// dphi/dl_f = -(h / l_f^2) / sqrt(1 - (h / l_f)^2)
  double dPennationAngleDFiberLength(double l_f) const;

 private:
  double phi_opt_ = 0.0, phi_max_ = 0.0;
  double h_ = 0.0, sin_phi_max_ = 0.0, l_min_ = 0.0, l_min_at_ = 0.0;
};

}  // namespace redmax::hill
