#pragma once
// What OpenSim's ActivationFiberLengthMuscle_Deprecated gives its subclasses
// (Thelen2003Muscle_Deprecated, Schutte1993Muscle_Deprecated): its pennation (calcPennation),
// the isometric equilibrium iteration both subclasses code alike (computeIsometricForce, with
// their own curves) and the generic rigid-tendon force (calcInextensibleTendonActiveFiberForce).
#include <functional>

#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/hill/muscle_properties.hpp"

namespace redmax::hill {

/// calcPennation: asin(l_opt sin(phi_opt) / l_f); 0 below eps or for a non-positive ratio, pi/2
/// from a ratio of 1 up
double deprecatedPennation(double l_f, double l_opt, double phi_opt);

/// a subclass's normalized curves as computeIsometricForce evaluates them
struct IsometricCurves {
  std::function<double(double)> active;   ///< of the normalized fibre length
  std::function<double(double)> passive;  ///< of the normalized fibre length
  /// tendon force / F_max at a tendon length (m), and the value whose F_max / l_s is the
  /// tendon's stiffness estimate (the curve at the same strain, unclamped in Schutte's code)
  std::function<double(double)> tendon_force, tendon_stiffness;
  /// without a tendon (l_s ~ 0): Thelen clamps the passive force at 0, Schutte does not
  bool clamp_passive_without_tendon = true;
};

/// computeIsometricForce at activation a: the secant/stiffness iteration to
/// |F_T - F_M cos(phi)| <= 0.01 N, 100 iterations, never an error (as OpenSim); the tendon force
/// (N) it ends at; the fibre length goes to *fiber_length
double deprecatedIsometricForce(const MuscleProperties& m, double length, double a, const IsometricCurves& c,
                                double* fiber_length);

/// calcInextensibleTendonActiveFiberForce: the isometric force times the generic force-velocity
/// factor 1.8 - 1.8 / (1 + exp((0.04 - v) / 0.18)), v = -cos(phi_opt) speed / (v_max l_opt)
double deprecatedInextensibleForce(const MuscleProperties& m, const MusculotendonInput& in, double activation,
                                   const IsometricCurves& c);

}  // namespace redmax::hill
