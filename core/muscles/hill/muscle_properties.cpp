#include "core/muscles/hill/muscle_properties.hpp"

#include <cmath>
#include <limits>

namespace redmax::hill {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// SimTK::SignificantReal = eps^(7/8)
const double kSignificantReal = std::pow(kEps, 0.875);

[[noreturn]] void bad(const MuscleParameters& p, const std::string& key, const std::string& what) {
  throw MuscleParameterError(key, "muscle '" + p.name + "': " + key + " " + what);
}

}  // namespace

MuscleProperties readMuscleProperties(const MuscleParameters& p, double default_min_control) {
  MuscleProperties m;
  m.max_isometric_force = p.get("max_isometric_force", m.max_isometric_force);
  m.optimal_fiber_length = p.get("optimal_fiber_length", m.optimal_fiber_length);
  m.tendon_slack_length = p.get("tendon_slack_length", m.tendon_slack_length);
  m.pennation_angle_at_optimal = p.get("pennation_angle_at_optimal", m.pennation_angle_at_optimal);
  m.max_contraction_velocity = p.get("max_contraction_velocity", m.max_contraction_velocity);
  m.ignore_tendon_compliance = p.flag("ignore_tendon_compliance", false);
  m.ignore_activation_dynamics = p.flag("ignore_activation_dynamics", false);
  m.min_control = p.get("min_control", default_min_control);
  m.max_control = p.get("max_control", 1.0);
  m.default_activation = p.get("default_activation", 0.05);
  // OpenSim constructs default_fiber_length from the default optimal_fiber_length (0.1)
  m.default_fiber_length = p.get("default_fiber_length", 0.1);

  // values no OpenSim muscle can work with
  if (!(m.max_isometric_force >= 0) || !std::isfinite(m.max_isometric_force))
    bad(p, "max_isometric_force", "must be finite and >= 0");
  if (!(m.optimal_fiber_length > 0) || !std::isfinite(m.optimal_fiber_length))
    bad(p, "optimal_fiber_length", "must be finite and > 0");
  if (!(m.tendon_slack_length >= 0) || !std::isfinite(m.tendon_slack_length))
    bad(p, "tendon_slack_length", "must be finite and >= 0");
  if (!(m.max_contraction_velocity > 0) || !std::isfinite(m.max_contraction_velocity))
    bad(p, "max_contraction_velocity", "must be finite and > 0");
  // MuscleFixedWidthPennationModel::extendFinalizeFromProperties
  if (!(m.pennation_angle_at_optimal >= 0 &&
        m.pennation_angle_at_optimal <= M_PI / 2 - kSignificantReal))
    bad(p, "pennation_angle_at_optimal", "must be in [0, pi/2)");
  if (!(m.min_control <= m.max_control)) bad(p, "min_control", "must not exceed max_control");
  return m;
}

void appendMuscleProperties(const MuscleProperties& m, ParameterList& out) {
  out.emplace_back("max_isometric_force", m.max_isometric_force);
  out.emplace_back("optimal_fiber_length", m.optimal_fiber_length);
  out.emplace_back("tendon_slack_length", m.tendon_slack_length);
  out.emplace_back("pennation_angle_at_optimal", m.pennation_angle_at_optimal);
  out.emplace_back("max_contraction_velocity", m.max_contraction_velocity);
  out.emplace_back("ignore_tendon_compliance", m.ignore_tendon_compliance ? 1 : 0);
  out.emplace_back("ignore_activation_dynamics", m.ignore_activation_dynamics ? 1 : 0);
  out.emplace_back("min_control", m.min_control);
  out.emplace_back("max_control", m.max_control);
}

FixedWidthPennation::FixedWidthPennation(double l_opt, double phi_opt, double phi_max)
    : phi_opt_(phi_opt), phi_max_(phi_max) {
  if (!(phi_max >= 0 && phi_max <= M_PI / 2))
    throw MuscleParameterError("maximum_pennation_angle", "maximum_pennation_angle must be in [0, pi/2]");
  h_ = l_opt * std::sin(phi_opt);
  sin_phi_max_ = std::sin(phi_max);
  l_min_ = phi_max > kSignificantReal ? h_ / sin_phi_max_ : l_opt * 0.01;
  l_min_at_ = l_min_ * std::cos(phi_max);
}

double FixedWidthPennation::pennationAngle(double l_f) const {
  if (!(phi_opt_ > kEps)) return 0.0;
  if (!(l_f > l_min_)) return phi_max_;
  const double s = h_ / l_f;
  return s < sin_phi_max_ ? std::asin(s) : phi_max_;
}

double FixedWidthPennation::pennationAngularVelocity(double tan_phi, double l_f, double v_f) const {
  if (!(phi_opt_ > kEps)) return 0.0;
  if (!(l_f > 0)) throw MuscleModelError("pennation model: fibre length must be > 0");
  return -(v_f / l_f) * tan_phi;
}

double FixedWidthPennation::fiberLength(double l_MT, double l_T) const {
  const double at = l_MT - l_T;
  return at >= l_min_at_ ? std::sqrt(h_ * h_ + at * at) : l_min_;
}

double FixedWidthPennation::dPennationAngleDFiberLength(double l_f) const {
  const double r = h_ / l_f;
  return (-r / l_f) / std::sqrt(1.0 - r * r);
}

}  // namespace redmax::hill
