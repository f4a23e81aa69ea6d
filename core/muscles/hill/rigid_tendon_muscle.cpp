#include "core/muscles/hill/rigid_tendon_muscle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace redmax::hill {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
const double kSqrtEps = std::sqrt(kEps);
constexpr double kRoundoff = 2e-13;  // SimmMacros.h ROUNDOFF_ERROR

[[noreturn]] void bad(const std::string& muscle, const std::string& key, const std::string& what) {
  throw MuscleParameterError(key, "muscle '" + muscle + "': " + key + " " + what);
}

// OpenSim's default curves (constructProperties of both classes): SimmSplines through these
const std::vector<double> kActiveX = {-5.307692, -4.307692, -1.923077, -0.884615, -0.269231, 0.230769, 0.461538,
                                      0.52725,   0.62875,   0.71875,   0.86125,   1.045,     1.2175,   1.43875,
                                      1.5,       1.615385,  2.0,       2.961538,  3.692308,  5.461538, 9.901902};
const std::vector<double> kActiveY = {0.012188, 0.021899, 0.036466, 0.052493, 0.075312, 0.114158, 0.157859,
                                      0.226667, 0.636667, 0.856667, 0.95,     0.993333, 0.77,     0.246667,
                                      0.193821, 0.133252, 0.072683, 0.044417, 0.036341, 0.021899, 0.007332};
const std::vector<double> kPassiveX = {-5.0, 0.998, 0.999, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.601, 1.602, 5.0};
const std::vector<double> kPassiveY = {0.0, 0.0, 0.0, 0.0, 0.035, 0.12, 0.26, 0.55, 1.17, 2.0, 2.0, 2.0, 2.0};
const std::vector<double> kForceVelocityX = {
    -1.001, -1.0, -0.95, -0.9, -0.85, -0.8, -0.75, -0.7, -0.65, -0.6, -0.55, -0.5, -0.45, -0.4,
    -0.35,  -0.3, -0.25, -0.2, -0.15, -0.1, -0.05, 0.0,  0.05,  0.1,  0.15,  0.2,  0.25,  0.3,
    0.35,   0.4,  0.45,  0.5,  0.55,  0.6,  0.65,  0.7,  0.75,  0.8,  0.85,  0.9,  0.95,  1.0};
const std::vector<double> kForceVelocityY = {
    0.0,      0.0,      0.010417, 0.021739, 0.034091, 0.047619, 0.0625,   0.078947, 0.097222, 0.117647, 0.140625,
    0.166667, 0.196429, 0.230769, 0.270833, 0.318182, 0.375,    0.444444, 0.53125,  0.642857, 0.791667, 1.0,
    1.482014, 1.601571, 1.655791, 1.686739, 1.706751, 1.720753, 1.731099, 1.739055, 1.745365, 1.75049,
    1.754736, 1.758312, 1.761364, 1.763999, 1.766298, 1.768321, 1.770115, 1.771717, 1.773155, 1.774455};
const std::vector<double> kTendonX = {-10.0,   -0.002,  -0.001, 0.0,    0.00131, 0.00281, 0.00431, 0.00581, 0.00731,
                                      0.00881, 0.0103,  0.0118, 0.0123, 9.2,     9.201,   9.202,   20.0};
const std::vector<double> kTendonY = {0.0,   0.0,   0.0,   0.0,   0.0108, 0.0257, 0.0435, 0.0652, 0.0915,
                                      0.123, 0.161, 0.208, 0.227, 345.0,  345.0,  345.0,  345.0};

const std::vector<std::string>& noStates() {
  static const std::vector<std::string> names;
  return names;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// RigidTendonMuscle

RigidTendonMuscle::RigidTendonMuscle(const MuscleParameters& p) {
  name_ = p.name;
  m_ = readMuscleProperties(p, 0.0);
  fal_ = p.curveOr("active_force_length_curve", kActiveX, kActiveY);
  fpe_ = p.curveOr("passive_force_length_curve", kPassiveX, kPassiveY);
  fv_ = p.curveOr("force_velocity_curve", kForceVelocityX, kForceVelocityY);
}

const std::vector<std::string>& RigidTendonMuscle::stateNames() const { return noStates(); }

RigidTendonMuscle::Kinematics RigidTendonMuscle::kinematics(const MusculotendonInput& in) const {
  // calcMuscleLengthInfo, calcFiberVelocityInfo
  const double l_opt = m_.optimal_fiber_length;
  const double width = l_opt * std::sin(m_.pennation_angle_at_optimal);
  const double along = std::max(0.0, in.length - m_.tendon_slack_length);
  Kinematics k{};
  if (width > kSqrtEps) {
    k.l_f = std::sqrt(along * along + width * width);
    k.cos_phi = along / k.l_f;
  } else {
    k.l_f = along;
    k.cos_phi = 1.0;
  }
  k.lceN = k.l_f / l_opt;
  k.vN = in.speed / (l_opt * m_.max_contraction_velocity);
  return k;
}

void RigidTendonMuscle::calc(const double*, const MusculotendonInput& in, MuscleOutput& out, double*) const {
  const Kinematics k = kinematics(in);
  const double F_max = m_.max_isometric_force;
  const double a = in.excitation;  // getControl
  const double fal = fal_->value(k.lceN);
  const double fpe = std::clamp(fpe_->value(k.lceN), 0.0, 10.0);
  const double fv = fv_->value(k.vN);
  out.activation = a;
  out.fiber_length = k.l_f;
  out.fiber_velocity = in.speed;
  out.pennation_angle = std::acos(k.cos_phi);
  out.tendon_length = m_.tendon_slack_length;
  out.normalized_fiber_length = k.lceN;
  out.normalized_fiber_velocity = k.vN;
  out.active_fiber_force = F_max * a * fal * fv;
  out.passive_fiber_force = F_max * fpe;
  out.passive_fiber_elastic_force = out.passive_fiber_force;
  out.tendon_force = (out.active_fiber_force + out.passive_fiber_force) * k.cos_phi;
}

double RigidTendonMuscle::inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const {
  const Kinematics k = kinematics(in);
  return m_.max_isometric_force * activation * fal_->value(k.lceN) * fv_->value(k.vN) * k.cos_phi;
}

std::vector<std::pair<std::string, double>> RigidTendonMuscle::parameterList() const {
  ParameterList out;
  appendMuscleProperties(m_, out);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Schutte1993Muscle_Deprecated

Schutte1993MuscleDeprecated::Schutte1993MuscleDeprecated(const MuscleParameters& p) {
  name_ = p.name;
  m_ = readMuscleProperties(p, 0.0);
  time_scale_ = p.get("time_scale", time_scale_);
  activation1_ = p.get("activation1", activation1_);
  activation2_ = p.get("activation2", activation2_);
  damping_ = p.get("damping", damping_);
  // OpenSim checks none of these; these are the values whose equations divide by zero or whose
  // activation would not settle
  if (!(time_scale_ > 0) || !std::isfinite(time_scale_)) bad(p.name, "time_scale", "must be finite and > 0");
  if (!(damping_ > 0) || !std::isfinite(damping_)) bad(p.name, "damping", "must be finite and > 0");
  if (!(activation2_ > 0) || !std::isfinite(activation2_)) bad(p.name, "activation2", "must be finite and > 0");
  if (!(activation1_ >= 0) || !std::isfinite(activation1_)) bad(p.name, "activation1", "must be finite and >= 0");
  if (m_.ignore_activation_dynamics)
    bad(p.name, "ignore_activation_dynamics", "is not implemented by OpenSim's Schutte1993Muscle_Deprecated");
  if (m_.ignore_tendon_compliance)
    bad(p.name, "ignore_tendon_compliance", "is not implemented by OpenSim's Schutte1993Muscle_Deprecated");
  tendon_ = p.curveOr("tendon_force_length_curve", kTendonX, kTendonY);
  active_ = p.curveOr("active_force_length_curve", kActiveX, kActiveY);
  if (auto it = p.curves.find("passive_force_length_curve"); it != p.curves.end()) passive_ = it->second;
}

const std::vector<std::string>& Schutte1993MuscleDeprecated::stateNames() const {
  static const std::vector<std::string> names = {"activation", "fiber_length"};
  return names;
}

void Schutte1993MuscleDeprecated::defaultState(double* z) const {
  z[0] = 0.0;
  z[1] = 0.0;
}

double Schutte1993MuscleDeprecated::tendonForce(double strain) const {
  return strain < 0.0 ? 0.0 : tendon_->value(strain);
}

double Schutte1993MuscleDeprecated::passiveForce(double lceN) const {
  return passive_ ? passive_->value(lceN) : std::exp(8.0 * (lceN - 1.0)) / std::exp(4.0);
}

double Schutte1993MuscleDeprecated::fiberVelocity(double a, double active, double Fv) const {
  const double kv = 0.15, slope_k = 0.13, fmax = 1.4, d = damping_;
  const double Fa = a * active;
  if (Fv < -d) return Fv / d;
  if (Fv < Fa) {
    const double c = kv * (Fv - Fa) / d;
    const double b = -kv * (Fv / kv + Fa + d) / d;
    return (-b - std::sqrt(b * b - 4 * c)) / 2.0;
  }
  const double c = -(slope_k * kv / (d * (kv + 1))) * (Fv - Fa);
  const double b = -(Fv / d - fmax * Fa / d - slope_k * kv / (kv + 1));
  return (-b + std::sqrt(b * b - 4 * c)) / 2.0;
}

void Schutte1993MuscleDeprecated::calc(const double* z, const MusculotendonInput& in, MuscleOutput& out,
                                       double* zdot) const {
  const double l_opt = m_.optimal_fiber_length, l_s = m_.tendon_slack_length;
  const double F_max = m_.max_isometric_force, phi_opt = m_.pennation_angle_at_optimal;
  const double a = z[0], u = in.excitation;
  const double nfl = z[1] / l_opt;
  const double adot = u >= a ? (u - a) * (activation1_ * u + activation2_) : (u - a) * activation2_;

  const double ca = std::cos(deprecatedPennation(nfl, 1.0, phi_opt));
  const double nmtl = in.length / l_opt;
  const double ntl = nmtl - nfl * ca;
  const double norm_rest = l_s / l_opt;
  const double tendon = tendonForce((ntl - norm_rest) / norm_rest);
  const double passive = passiveForce(nfl);
  const double active = std::max(0.0, active_->value(nfl));

  double nfv;
  if (std::abs(ca) <= kRoundoff) {
    // 90 degrees: the fibre stays until the tendon pulls, then a stiff-tendon velocity; OpenSim
    // subtracts the slack length (m) from the normalized path length (reproduced)
    if (std::abs(tendon) <= kRoundoff) {
      nfv = 0.0;
    } else {
      const double h = nmtl - l_s;
      const double w = l_opt * std::sin(phi_opt);
      const double new_nfl = std::sqrt(h * h + w * w) / l_opt;
      nfv = in.speed * time_scale_ / l_opt * std::cos(deprecatedPennation(new_nfl, 1.0, phi_opt));
    }
  } else {
    nfv = fiberVelocity(a, active, std::max(0.0, tendon / ca - passive));
  }

  const double phi = deprecatedPennation(z[1], l_opt, phi_opt);
  out.activation = a;
  out.fiber_length = z[1];
  out.fiber_velocity = nfv * l_opt / time_scale_;
  out.pennation_angle = phi;
  out.tendon_length = in.length - z[1] * std::cos(phi);
  out.normalized_fiber_length = nfl;
  out.normalized_fiber_velocity = out.fiber_velocity / (l_opt * m_.max_contraction_velocity);
  out.tendon_force = tendon * F_max;
  out.passive_fiber_force = passive * F_max;
  out.active_fiber_force = out.tendon_force / std::cos(phi) - out.passive_fiber_force;

  zdot[0] = adot / time_scale_;
  zdot[1] = out.fiber_velocity;
}

IsometricCurves Schutte1993MuscleDeprecated::isometricCurves() const {
  IsometricCurves c;
  c.active = [this](double l) { return active_->value(l); };
  c.passive = [this](double l) { return passiveForce(l); };
  const double l_s = m_.tendon_slack_length;
  c.tendon_force = [this, l_s](double tendon_length) { return tendonForce(tendon_length / l_s - 1.0); };
  c.tendon_stiffness = [this, l_s](double tendon_length) { return tendon_->value(tendon_length / l_s - 1.0); };
  c.clamp_passive_without_tendon = false;
  return c;
}

void Schutte1993MuscleDeprecated::equilibrate(const MusculotendonInput& in, double* z) const {
  deprecatedIsometricForce(m_, in.length, z[0], isometricCurves(), &z[1]);
}

double Schutte1993MuscleDeprecated::inextensibleTendonActiveFiberForce(const MusculotendonInput& in,
                                                                       double activation) const {
  return deprecatedInextensibleForce(m_, in, activation, isometricCurves());
}

std::vector<std::pair<std::string, double>> Schutte1993MuscleDeprecated::parameterList() const {
  ParameterList out;
  appendMuscleProperties(m_, out);
  out.emplace_back("time_scale", time_scale_);
  out.emplace_back("activation1", activation1_);
  out.emplace_back("activation2", activation2_);
  out.emplace_back("damping", damping_);
  out.emplace_back("passive_force_length_curve_given", passive_ ? 1 : 0);
  return out;
}

}  // namespace redmax::hill
