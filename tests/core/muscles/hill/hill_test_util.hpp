#pragma once
// Helpers for the Hill-model suites: central differences and relative comparisons.
#include <cmath>
#include <functional>

#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill::test {

/// (f(x + h) - f(x - h)) / 2h
inline double centralDifference(const std::function<double(double)>& f, double x, double h = 1e-6) {
  return (f(x + h) - f(x - h)) / (2 * h);
}

/// |a - b| <= tol (1 + |b|)   (STYLE.md: safe against a zero reference)
inline bool nearRel(double a, double b, double tol) { return std::abs(a - b) <= tol * (1 + std::abs(b)); }

// arm26's TRIlong (Applications/Forward/tests/resources/arm26.osim)
inline MuscleParameters triLong() {
  MuscleParameters p;
  p.name = "TRIlong";
  p.set("max_isometric_force", 798.52);
  p.set("optimal_fiber_length", 0.134);
  p.set("tendon_slack_length", 0.143);
  p.set("pennation_angle_at_optimal", 0.20943951);
  p.set("max_contraction_velocity", 10);
  p.set("activation_time_constant", 0.01);
  p.set("deactivation_time_constant", 0.04);
  p.set("Vmax", 10);
  p.set("Vmax0", 5);
  p.set("FmaxTendonStrain", 0.033);
  p.set("FmaxMuscleStrain", 0.6);
  p.set("KshapeActive", 0.5);
  p.set("KshapePassive", 4);
  p.set("damping", 0.05);
  p.set("Af", 0.3);
  p.set("Flen", 1.8);
  return p;
}

}  // namespace redmax::hill::test
