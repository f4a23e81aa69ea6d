#include "core/muscles/mass_points.hpp"

#include <cmath>

#include "core/muscles/wrap_muscle.hpp"

namespace redmax {

double MassPoints::totalMass() const {
  double m = 0.0;
  for (double x : mass) m += x;
  return m;
}

MassPoints makeMassPoints(double total_mass, double optimal_fiber_length, double tendon_slack_length,
                          const MassPointOptions& options) {
  if (!(total_mass >= 0.0) || !std::isfinite(total_mass))
    throw ModelError("muscle mass must be finite and >= 0, got " + std::to_string(total_mass));
  if (options.count < 1)
    throw ModelError("number of mass points must be >= 1, got " + std::to_string(options.count));
  double a0 = 0.0, a1 = 1.0;
  if (options.region == MassPointOptions::Region::Fibre) {
    if (!(optimal_fiber_length > 0.0) || !std::isfinite(optimal_fiber_length))
      throw ModelError("optimal fibre length must be finite and > 0, got " + std::to_string(optimal_fiber_length));
    if (!(tendon_slack_length >= 0.0) || !std::isfinite(tendon_slack_length))
      throw ModelError("tendon slack length must be finite and >= 0, got " + std::to_string(tendon_slack_length));
    // fibre share of the path, tendon split equally at both ends (header)
    const double phi = optimal_fiber_length / (optimal_fiber_length + tendon_slack_length);
    a0 = 0.5 * (1.0 - phi);
    a1 = 0.5 * (1.0 + phi);
  }
  // centres of N equal sub-intervals, equal masses (midpoint rule for a uniform line density)
  const int n = options.count;
  MassPoints mp;
  mp.alpha.resize(n);
  mp.mass.assign(n, total_mass / n);
  for (int k = 0; k < n; ++k) mp.alpha[k] = a0 + (a1 - a0) * (k + 0.5) / n;
  return mp;
}

MassPoints makeMassPoints(std::vector<double> alpha, std::vector<double> mass) {
  if (alpha.size() != mass.size())
    throw ModelError("mass points: " + std::to_string(alpha.size()) + " alpha values but " +
                     std::to_string(mass.size()) + " masses");
  for (size_t k = 0; k < alpha.size(); ++k) {
    if (!(alpha[k] >= 0.0 && alpha[k] <= 1.0))
      throw ModelError("mass point " + std::to_string(k) + ": alpha " + std::to_string(alpha[k]) +
                       " is not in [0, 1]");
    if (!(mass[k] >= 0.0) || !std::isfinite(mass[k]))
      throw ModelError("mass point " + std::to_string(k) + ": mass must be finite and >= 0");
  }
  MassPoints mp;
  mp.alpha = std::move(alpha);
  mp.mass = std::move(mass);
  return mp;
}

void validateMuscle(const Model& model, const Muscle& muscle) {
  validatePath(model, muscle.path, muscle.name);
  const std::string who = "muscle '" + muscle.name + "': ";
  const MassPoints& mp = muscle.mass_points;
  if (mp.alpha.size() != mp.mass.size())
    throw ModelError(who + "mass points have " + std::to_string(mp.alpha.size()) + " alpha values but " +
                     std::to_string(mp.mass.size()) + " masses");
  if (mp.size() > 0 && pathType(muscle.path) == PathType::III) {
    const std::string why = wrapMassPointsUnsupportedReason(muscle);
    if (!why.empty())
      throw ModelError(who + "has wrap objects (Type III path) and mass points, but " + why +
                       "; keep its mass lumped in the bodies (no mass points)");
  }
  if (muscle.fibre.enabled()) {
    if (pathType(muscle.path) == PathType::III)
      throw ModelError(who + "fibre-following mass placement is not available on wrapping (Type III) paths");
    if (static_cast<int>(muscle.fibre.c.size()) != mp.size())
      throw ModelError(who + "fibre-following placement has " + std::to_string(muscle.fibre.c.size()) +
                       " fibre fractions for " + std::to_string(mp.size()) + " mass points");
    for (double c : muscle.fibre.c)
      if (!(c > 0.0 && c < 1.0)) throw ModelError(who + "fibre fraction " + std::to_string(c) + " is not in (0, 1)");
  }
  for (int k = 0; k < mp.size(); ++k) {
    if (!(mp.alpha[k] >= 0.0 && mp.alpha[k] <= 1.0))
      throw ModelError(who + "mass point " + std::to_string(k) + ": alpha not in [0, 1]");
    if (!(mp.mass[k] >= 0.0) || !std::isfinite(mp.mass[k]))
      throw ModelError(who + "mass point " + std::to_string(k) + ": mass must be finite and >= 0");
  }
}

}  // namespace redmax
