#include "core/muscles/hill/degroote_fregly2016_muscle.hpp"

#include <cmath>
#include <limits>

namespace redmax::hill {
namespace {

// [De Groote 2016, supplement] with OpenSim's values (b11 adjusted so that fal(1) = 1)
constexpr double b1[3] = {0.8150671134243542, 0.433004984392647, 0.1};
constexpr double b2[3] = {1.055033428970575, 0.716775413397760, 1.0};
constexpr double b3[3] = {0.162384573599574, -0.029947116970696, 0.353553390593274};
constexpr double b4[3] = {0.063303448465465, 0.200356847296188, 0.0};
constexpr double kPE = 4.0, c1 = 0.2, c2 = 1.0, c3 = 0.2;
constexpr double d1 = -0.3211346127989808, d2 = -8.149, d3 = -0.374, d4 = 0.8825327733249912;
constexpr double kMinNormFiberLength = 0.2;

double gaussianLike(double x, int k) {
  const double w = b3[k] + b4[k] * x;
  return b1[k] * std::exp(-0.5 * (x - b2[k]) * (x - b2[k]) / (w * w));
}
double gaussianLikeDerivative(double x, int k) {
  const double w = b3[k] + b4[k] * x;
  return b1[k] * std::exp(-(b2[k] - x) * (b2[k] - x) / (2 * w * w)) * (b2[k] - x) * (b3[k] + b2[k] * b4[k]) /
         (w * w * w);
}

[[noreturn]] void bad(const std::string& muscle, const std::string& key, const std::string& what) {
  throw MuscleParameterError(key, "muscle '" + muscle + "': " + key + " " + what);
}

}  // namespace

double DeGrooteFregly2016Curves::activeForceLength(double lceN) const {
  const double x = (lceN - 1.0) / active_force_width_scale + 1.0;
  return gaussianLike(x, 0) + gaussianLike(x, 1) + gaussianLike(x, 2);
}
double DeGrooteFregly2016Curves::activeForceLengthDerivative(double lceN) const {
  const double x = (lceN - 1.0) / active_force_width_scale + 1.0;
  return (1.0 / active_force_width_scale) *
         (gaussianLikeDerivative(x, 0) + gaussianLikeDerivative(x, 1) + gaussianLikeDerivative(x, 2));
}
double DeGrooteFregly2016Curves::passiveForceLength(double lceN) const {
  if (ignore_passive_fiber_force) return 0;
  const double e0 = passive_fiber_strain_at_one_norm_force;
  const double offset = std::exp(kPE * (kMinNormFiberLength - 1.0) / e0);
  return (std::exp(kPE * (lceN - 1.0) / e0) - offset) / (std::exp(kPE) - offset);
}
double DeGrooteFregly2016Curves::passiveForceLengthDerivative(double lceN) const {
  if (ignore_passive_fiber_force) return 0;
  const double e0 = passive_fiber_strain_at_one_norm_force;
  const double offset = std::exp(kPE * (kMinNormFiberLength - 1) / e0);
  return kPE * std::exp(kPE * (lceN - 1) / e0) / (e0 * (std::exp(kPE) - offset));
}
double DeGrooteFregly2016Curves::tendonStiffness() const {
  return std::log((1.0 + c3) / c1) / (1.0 + tendon_strain_at_one_norm_force - c2);
}
double DeGrooteFregly2016Curves::tendonForceLength(double tlN) const {
  return c1 * std::exp(tendonStiffness() * (tlN - c2)) - c3;
}
double DeGrooteFregly2016Curves::tendonForceLengthDerivative(double tlN) const {
  return c1 * tendonStiffness() * std::exp(tendonStiffness() * (tlN - c2));
}
double DeGrooteFregly2016Curves::tendonForceLengthInverse(double fT) const {
  return std::log((1.0 / c1) * (fT + c3)) / tendonStiffness() + c2;
}
double DeGrooteFregly2016Curves::forceVelocity(double vN) {
  const double t = d2 * vN + d3;
  return d1 * std::log(t + std::sqrt(t * t + 1.0)) + d4;
}
double DeGrooteFregly2016Curves::forceVelocityDerivative(double vN) {
  const double t = d2 * vN + d3;
  return d1 * d2 / std::sqrt(t * t + 1.0);
}
double DeGrooteFregly2016Curves::forceVelocityInverse(double fv) {
  return (std::sinh(1.0 / d1 * (fv - d4)) - d3) / d2;
}

DeGrooteFregly2016Muscle::DeGrooteFregly2016Muscle(const MuscleParameters& p) {
  name_ = p.name;
  m_ = readMuscleProperties(p, 0.0);
  tau_act_ = p.get("activation_time_constant", 0.015);
  tau_deact_ = p.get("deactivation_time_constant", 0.060);
  m_.default_activation = p.get("default_activation", 0.5);
  default_tendon_force_ = p.get("default_normalized_tendon_force", 0.5);
  c_.active_force_width_scale = p.get("active_force_width_scale", 1.0);
  beta_ = p.get("fiber_damping", 0.0);
  c_.passive_fiber_strain_at_one_norm_force = p.get("passive_fiber_strain_at_one_norm_force", 0.6);
  c_.tendon_strain_at_one_norm_force = p.get("tendon_strain_at_one_norm_force", 0.049);
  c_.ignore_passive_fiber_force = p.flag("ignore_passive_fiber_force", false);
  smoothing_ = p.get("activation_dynamics_smoothing", 0.1);
  // DeGrooteFregly2016Muscle::extendFinalizeFromProperties
  if (!(tau_act_ > 0)) bad(p.name, "activation_time_constant", "must be > 0");
  if (!(tau_deact_ > 0)) bad(p.name, "deactivation_time_constant", "must be > 0");
  if (!(m_.default_activation > 0)) bad(p.name, "default_activation", "must be > 0");
  if (!(default_tendon_force_ >= 0 && default_tendon_force_ <= 5))
    bad(p.name, "default_normalized_tendon_force", "must be in [0, 5]");
  if (!(c_.active_force_width_scale >= 1)) bad(p.name, "active_force_width_scale", "must be >= 1");
  if (!(beta_ >= 0)) bad(p.name, "fiber_damping", "must be >= 0");
  if (!(c_.passive_fiber_strain_at_one_norm_force > 0))
    bad(p.name, "passive_fiber_strain_at_one_norm_force", "must be > 0");
  if (!(c_.tendon_strain_at_one_norm_force > 0)) bad(p.name, "tendon_strain_at_one_norm_force", "must be > 0");
  if (!(smoothing_ > 0)) bad(p.name, "activation_dynamics_smoothing", "must be > 0");
  if (p.get("tendon_compliance_dynamics_mode", 0) != 0)
    bad(p.name, "tendon_compliance_dynamics_mode",
        "'implicit' is not modelled (its tendon-force derivative is a solver's control); use 'explicit'");
  if (!m_.ignore_activation_dynamics) {
    i_act_ = static_cast<int>(state_names_.size());
    state_names_.push_back("activation");
  }
  if (!m_.ignore_tendon_compliance) {
    i_ft_ = static_cast<int>(state_names_.size());
    state_names_.push_back("normalized_tendon_force");
  }
}

void DeGrooteFregly2016Muscle::defaultState(double* z) const {
  if (i_act_ >= 0) z[i_act_] = m_.default_activation;
  if (i_ft_ >= 0) z[i_ft_] = default_tendon_force_;
}

void DeGrooteFregly2016Muscle::evaluate(double a, double fT, const MusculotendonInput& in, bool explicit_tendon,
                                        Eval& e) const {
  const bool rigid = m_.ignore_tendon_compliance;
  const double l_opt = m_.optimal_fiber_length, l_s = m_.tendon_slack_length, F_max = m_.max_isometric_force;
  const double w = l_opt * std::sin(m_.pennation_angle_at_optimal);
  const double vmax = m_.max_contraction_velocity * l_opt;
  // length: the tendon length from the tendon force (slack length when rigid)
  e.tlN = rigid ? 1.0 : c_.tendonForceLengthInverse(fT);
  e.tendon_length = l_s * e.tlN;
  const double l_at = in.length - e.tendon_length;
  e.fiber_length = std::sqrt(l_at * l_at + w * w);
  e.lceN = e.fiber_length / l_opt;
  e.cos_phi = l_at / e.fiber_length;
  e.sin_phi = w / e.fiber_length;
  e.fpe = c_.passiveForceLength(e.lceN);
  e.fal = c_.activeForceLength(e.lceN);
  // velocity
  if (explicit_tendon && !rigid) {
    // the fibre velocity that makes the fibre carry the tendon force
    e.fv = (fT / e.cos_phi - e.fpe) / (a * e.fal);
    e.vN = c_.forceVelocityInverse(e.fv);
    e.fiber_velocity = e.vN * vmax;
    // along the tendon: d(l cos phi)/dt = d sqrt(l^2 - w^2)/dt = v / cos(phi) at fixed width
    const double v_at = e.fiber_velocity / e.cos_phi;
    e.tendon_velocity_n = (in.speed - v_at) / l_s;
  } else {
    // tendon at rest (rigid, or the equilibrium's zero tendon-force derivative)
    e.tendon_velocity_n = 0.0;
    e.fiber_velocity = in.speed * e.cos_phi;
    e.vN = e.fiber_velocity / vmax;
    e.fv = c_.forceVelocity(e.vN);
  }
  // dynamics
  e.active = F_max * (a * e.fal * e.fv);
  e.passive = F_max * e.fpe + F_max * beta_ * e.vN;
  e.fiber_along = (e.active + e.passive) * e.cos_phi;
  e.tendon_force = rigid ? e.fiber_along : F_max * fT;
}

double DeGrooteFregly2016Muscle::inextensibleTendonActiveFiberForce(const MusculotendonInput& in,
                                                                    double activation) const {
  const double l_opt = m_.optimal_fiber_length;
  const double w = l_opt * std::sin(m_.pennation_angle_at_optimal);
  const double l_at = in.length - m_.tendon_slack_length;  // rigid: the tendon at its slack length
  const double lf = std::sqrt(l_at * l_at + w * w);
  const double cos_phi = l_at / lf;
  const double vN = in.speed * cos_phi / (m_.max_contraction_velocity * l_opt);
  return m_.max_isometric_force * (activation * c_.activeForceLength(lf / l_opt) * c_.forceVelocity(vN));
}

void DeGrooteFregly2016Muscle::calc(const double* z, const MusculotendonInput& in, MuscleOutput& out,
                                    double* zdot) const {
  const double a = i_act_ >= 0 ? z[i_act_] : in.excitation;
  const double fT = i_ft_ >= 0 ? z[i_ft_] : std::numeric_limits<double>::quiet_NaN();
  Eval e;
  evaluate(a, fT, in, true, e);
  out.activation = a;
  out.fiber_length = e.fiber_length;
  out.fiber_velocity = e.fiber_velocity;
  out.pennation_angle = std::asin(e.sin_phi);
  out.tendon_length = e.tendon_length;
  out.normalized_fiber_length = e.lceN;
  out.normalized_fiber_velocity = e.vN;
  out.tendon_force = e.tendon_force;
  out.active_fiber_force = e.active;
  out.passive_fiber_force = e.passive;
  out.passive_fiber_elastic_force = m_.max_isometric_force * e.fpe;  // the rest is damping
  if (i_act_ >= 0) {
    // first-order activation with the time constant switched smoothly by tanh [De Groote 2016, Eq. 2]
    const double u = in.excitation, tf = 0.5 + 1.5 * a;
    const double f = 0.5 * std::tanh(smoothing_ * (u - a));
    const double rate = 1.0 / (tau_act_ * tf) * (f + 0.5) + tf / tau_deact_ * (-f + 0.5);
    zdot[i_act_] = rate * (u - a);
  }
  if (i_ft_ >= 0) zdot[i_ft_] = e.tendon_velocity_n * c_.tendonForceLengthDerivative(e.tlN);
}

double DeGrooteFregly2016Muscle::equilibriumResidual(const MusculotendonInput& in, double a, double fT) const {
  Eval e;
  evaluate(a, fT, in, false, e);
  return fT - e.fiber_along / m_.max_isometric_force;
}

void DeGrooteFregly2016Muscle::equilibrate(const MusculotendonInput& in, double* z) const {
  if (m_.ignore_tendon_compliance) return;
  const double a = i_act_ >= 0 ? z[i_act_] : in.excitation;
  double left = 0.0, right = 5.0;  // OpenSim's bounds on the normalized tendon force
  const auto r = [&](double fT) { return equilibriumResidual(in, a, fT); };
  if (r(left) * r(right) >= 0)
    throw MuscleModelError("DeGrooteFregly2016Muscle '" + name_ +
                           "': the equilibrium residual has the same sign at tendon forces 0 and 5");
  double mid = left, r_left = r(left);
  for (int it = 0; it < 100 && right - left > 1e-10; ++it) {
    mid = 0.5 * (left + right);
    if (r(mid) * r_left < 0) {
      right = mid;
    } else {
      left = mid;
      r_left = r(left);
    }
  }
  z[i_ft_] = mid;
}

std::vector<std::pair<std::string, double>> DeGrooteFregly2016Muscle::parameterList() const {
  ParameterList out;
  appendMuscleProperties(m_, out);
  out.emplace_back("activation_time_constant", tau_act_);
  out.emplace_back("deactivation_time_constant", tau_deact_);
  out.emplace_back("default_activation", m_.default_activation);
  out.emplace_back("default_normalized_tendon_force", default_tendon_force_);
  out.emplace_back("active_force_width_scale", c_.active_force_width_scale);
  out.emplace_back("fiber_damping", beta_);
  out.emplace_back("passive_fiber_strain_at_one_norm_force", c_.passive_fiber_strain_at_one_norm_force);
  out.emplace_back("tendon_strain_at_one_norm_force", c_.tendon_strain_at_one_norm_force);
  out.emplace_back("ignore_passive_fiber_force", c_.ignore_passive_fiber_force ? 1 : 0);
  out.emplace_back("activation_dynamics_smoothing", smoothing_);
  return out;
}

}  // namespace redmax::hill
