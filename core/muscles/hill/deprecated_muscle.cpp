#include "core/muscles/hill/deprecated_muscle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace redmax::hill {
namespace {
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kRoundoff = 2e-13;  // SimmMacros.h ROUNDOFF_ERROR
}  // namespace

double deprecatedPennation(double l_f, double l_opt, double phi_opt) {
  if (l_f < kEps) return 0.0;
  const double value = l_opt * std::sin(phi_opt) / l_f;
  if (std::isnan(value) || value <= 0.0) return 0.0;
  if (value >= 1.0) return M_PI / 2.0;
  return std::asin(value);
}

double deprecatedIsometricForce(const MuscleProperties& m, double length, double a, const IsometricCurves& c,
                                double* fiber_length_out) {
  const double l_opt = m.optimal_fiber_length, l_s = m.tendon_slack_length;
  const double F_max = m.max_isometric_force, pen_opt = m.pennation_angle_at_optimal;
  double& z1 = *fiber_length_out;
  if (l_opt < kRoundoff) {
    z1 = 0.0;
    return 0.0;
  }
  const double width = l_opt * std::sin(pen_opt);
  double fiber_length, tendon_length, cos_factor;
  if (l_s < kRoundoff) {
    // no tendon: the fibre spans the path
    const double cos_factor0 = std::cos(std::atan(width / length));
    z1 = length / cos_factor0;
    const double active = std::max(0.0, c.active(z1 / l_opt) * a);
    const double p = c.passive(z1 / l_opt);
    const double passive = c.clamp_passive_without_tendon ? std::max(0.0, p) : p;
    return (active + passive) * F_max * cos_factor0;
  }
  if (length < l_s) {
    z1 = width;
    return 0.0;
  }
  // the tendon and pennation at fiber_length; a tendon shorter than its slack length is slack,
  // the fibre takes the rest (OpenSim floors it at the width only before the iteration)
  const auto place = [&](bool floor_at_width) {
    cos_factor = std::cos(deprecatedPennation(fiber_length, l_opt, pen_opt));
    tendon_length = length - fiber_length * cos_factor;
    if (tendon_length < l_s) {
      tendon_length = l_s;
      cos_factor = std::cos(std::atan(width / (length - tendon_length)));
      fiber_length = (length - tendon_length) / cos_factor;
      if (floor_at_width && fiber_length < width) fiber_length = width;
    }
  };
  fiber_length = l_opt;
  place(true);

  double old_fiber_length = 0.0, error_force = 0.0, tendon_force = 0.0;
  for (int i = 0; i < 100; ++i) {
    double active = c.active(fiber_length / l_opt) * a;
    if (active < 0.0) active = 0.0;
    double passive = c.passive(fiber_length / l_opt);
    if (passive < 0.0) passive = 0.0;
    const double fiber_force = (active + passive) * F_max * cos_factor;
    tendon_force = c.tendon_force(tendon_length) * F_max;
    double old_error_force = error_force;
    error_force = tendon_force - fiber_force;
    if (std::abs(error_force) <= 0.01) break;  // OpenSim's ERROR_LIMIT, N
    if (i == 0) old_error_force = error_force;
    const auto sign = [](double x) { return x >= 0.0 ? 1 : -1; };
    if (sign(error_force) != sign(old_error_force)) {
      // a sign change: interpolate between the last two lengths
      const double percent = std::abs(error_force) / (std::abs(error_force) + std::abs(old_error_force));
      const double tmp = old_fiber_length;
      old_fiber_length = fiber_length;
      fiber_length = fiber_length + percent * (tmp - fiber_length);
    } else {
      // a step by the summed stiffnesses (tendon stiffness floored by a 1200 MPa / 32 MPa model)
      double tendon_stiffness = c.tendon_stiffness(tendon_length) * F_max / l_s;
      const double min_tendon_stiffness = (active + passive) * 1200.0 * F_max / (32.0 * l_s);
      if (tendon_stiffness < min_tendon_stiffness) tendon_stiffness = min_tendon_stiffness;
      const double fiber_stiffness =
          F_max / l_opt * (c.active(fiber_length / l_opt) + c.passive(fiber_length / l_opt));
      double change = std::abs(error_force / (fiber_stiffness / cos_factor + tendon_stiffness));
      if (std::abs(change / l_opt) > 0.5) change = 0.5 * l_opt;
      old_fiber_length = fiber_length;
      fiber_length += error_force > 0.0 ? change : -change;
    }
    place(false);
  }
  z1 = fiber_length;
  return tendon_force;
}

double deprecatedInextensibleForce(const MuscleProperties& m, const MusculotendonInput& in, double activation,
                                   const IsometricCurves& c) {
  double fiber_length = 0.0;
  const double isometric = deprecatedIsometricForce(m, in.length, activation, c, &fiber_length);
  // the base class's generic curve at unit activation and length
  const double v =
      -std::cos(m.pennation_angle_at_optimal) * in.speed / (m.max_contraction_velocity * m.optimal_fiber_length);
  const double fv = 1.8 - 1.8 / (1.0 + std::exp((0.04 - v) / 0.18));
  return isometric * fv;
}

}  // namespace redmax::hill
