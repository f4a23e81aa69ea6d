#include "core/muscles/hill/thelen2003_muscle.hpp"

#include "core/muscles/hill/deprecated_muscle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace redmax::hill {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
const double kSignificantReal = std::pow(kEps, 0.875);  // SimTK::SignificantReal
constexpr double kRoundoff = 2e-13;                     // SimmMacros.h ROUNDOFF_ERROR

[[noreturn]] void bad(const std::string& muscle, const std::string& key, const std::string& what) {
  throw MuscleParameterError(key, "muscle '" + muscle + "': " + key + " " + what);
}

void positive(const MuscleParameters& p, const std::string& key, double v) {
  if (!(v > 0) || !std::isfinite(v)) bad(p.name, key, "must be finite and > 0");
}

// OpenSim's (Deprecated) ActivationFiberLengthMuscle refuses both flags
void noIgnoreFlags(const MuscleParameters& p, const MuscleProperties& m, const std::string& cls) {
  if (m.ignore_activation_dynamics)
    bad(p.name, "ignore_activation_dynamics", "is not implemented by OpenSim's " + cls);
  if (m.ignore_tendon_compliance)
    bad(p.name, "ignore_tendon_compliance", "is not implemented by OpenSim's " + cls);
}

const std::vector<std::string>& activationFiberLengthStates() {
  static const std::vector<std::string> names = {"activation", "fiber_length"};
  return names;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// activation

double FirstOrderActivation::clamp(double a) const { return std::clamp(a, minimum_activation, 1.0); }

double FirstOrderActivation::derivative(double a, double u) const {
  a = clamp(a);
  const double tau = u > a ? activation_time_constant * (0.5 + 1.5 * a)
                           : deactivation_time_constant / (0.5 + 1.5 * a);
  return (u - a) / tau;
}

// ---------------------------------------------------------------------------------------------
// Thelen2003Muscle

Thelen2003Muscle::Thelen2003Muscle(const MuscleParameters& p) {
  name_ = p.name;
  act_.minimum_activation = p.get("minimum_activation", 0.01);
  // min_control's default is the default minimum activation (set at construction, before the
  // XML is read), 0.01, whatever minimum_activation the file gives
  m_ = readMuscleProperties(p, 0.01);
  noIgnoreFlags(p, m_, "Thelen2003Muscle");
  c_.read(p);
  c_.fv_linear_extrap_threshold = p.get("fv_linear_extrap_threshold", 0.95);
  maximum_pennation_angle_ = p.get("maximum_pennation_angle", std::acos(0.1));
  act_.activation_time_constant = p.get("activation_time_constant", 0.015);
  act_.deactivation_time_constant = p.get("deactivation_time_constant", 0.050);

  // Thelen2003Muscle::extendFinalizeFromProperties
  c_.check(p.name);
  if (!(c_.fv_linear_extrap_threshold > 1.0 / c_.Flen))
    bad(p.name, "fv_linear_extrap_threshold", "must be greater than 1/Flen");
  if (!(act_.minimum_activation >= 0.01)) bad(p.name, "minimum_activation", "cannot be less than 0.01");
  if (!(act_.minimum_activation <= 1.0 - kSignificantReal))
    bad(p.name, "minimum_activation", "must be in [0.01, 1)");
  if (!(m_.min_control >= act_.minimum_activation))
    bad(p.name, "min_control", "cannot be less than minimum_activation");
  if (!(act_.activation_time_constant >= kSignificantReal))
    bad(p.name, "activation_time_constant", "must be greater than zero");
  if (!(act_.deactivation_time_constant >= kSignificantReal))
    bad(p.name, "deactivation_time_constant", "must be greater than zero");
  try {
    pen_ = FixedWidthPennation(m_.optimal_fiber_length, m_.pennation_angle_at_optimal,
                               maximum_pennation_angle_);
  } catch (const MuscleParameterError& e) {
    bad(p.name, e.property(), "must be in [0, pi/2]");
  }
}

double Thelen2003Muscle::inextensibleTendonActiveFiberForce(const MusculotendonInput& in, double activation) const {
  const double l_opt = m_.optimal_fiber_length;
  const double lf = pen_.fiberLength(in.length, m_.tendon_slack_length);
  if (!(lf > pen_.minFiberLength())) return 0.0;
  const double phi = pen_.pennationAngle(lf);
  const double vf = in.speed * std::cos(phi);  // rigid tendon: the whole speed goes to the fibre
  // calcActiveFiberForceAlongTendon
  const double a = act_.clamp(activation);
  const double lceN = pen_.clampFiberLength(lf) / l_opt;
  const double dlceN = vf / (l_opt * m_.max_contraction_velocity);
  const double fal = c_.fal(lceN);
  const double fv = c_.fvInverse(a, fal, dlceN, 1e-6, 100);
  return m_.max_isometric_force * a * fal * fv * std::cos(phi);
}

const std::vector<std::string>& Thelen2003Muscle::stateNames() const { return activationFiberLengthStates(); }

void Thelen2003Muscle::defaultState(double* z) const {
  z[0] = m_.default_activation;
  z[1] = m_.default_fiber_length;
}

void Thelen2003Muscle::calc(const double* z, const MusculotendonInput& in, MuscleOutput& out,
                            double* zdot) const {
  const double l_opt = m_.optimal_fiber_length, l_s = m_.tendon_slack_length;
  const double F_max = m_.max_isometric_force;
  // length stage (calcMuscleLengthInfo): the fibre is clamped at its minimum length
  const double lce = pen_.clampFiberLength(z[1]);
  const double lceN = lce / l_opt;
  const double phi = pen_.pennationAngle(lce);
  const double cos_phi = std::cos(phi);
  const double tl = in.length - lce * cos_phi;
  const double fpe = c_.fpe(lceN), fal = c_.fal(lceN);

  // velocity stage (calcFiberVelocityInfo): the fibre velocity that balances the tendon force
  const double a = act_.clamp(z[0]);
  const double fse = c_.fse(tl / l_s);
  const double a_fal_fv = fse / cos_phi - fpe;
  double fv = a_fal_fv / (a * fal);
  double dlceN = c_.dlceN(a, fal, a_fal_fv);
  double dlce = dlceN * m_.max_contraction_velocity * l_opt;
  // a fibre at its minimum length that would shorten further is held there
  bool clamped = false;
  if (z[1] <= pen_.minFiberLength() && dlceN <= 0) {
    clamped = true;
    dlce = 0;
    dlceN = 0;
    fv = 1.0;
  }

  out.activation = a;
  out.fiber_length = lce;
  out.fiber_velocity = dlce;
  out.pennation_angle = phi;
  out.tendon_length = tl;
  out.normalized_fiber_length = lceN;
  out.normalized_fiber_velocity = dlceN;
  out.tendon_force = fse * F_max;
  // calcMuscleDynamicsInfo: no active force while the fibre state is clamped
  out.active_fiber_force = clamped ? 0.0 : a * fal * fv * F_max;
  out.passive_fiber_force = fpe * F_max;
  out.passive_fiber_elastic_force = out.passive_fiber_force;  // no damping

  zdot[0] = act_.derivative(z[0], in.excitation);
  zdot[1] = dlce;
}

void Thelen2003Muscle::equilibrate(const MusculotendonInput& in, double* z) const {
  const double ma = z[0], ml = in.length, dml = in.speed;
  const double tsl = m_.tendon_slack_length, ofl = m_.optimal_fiber_length;
  const double vol = ofl * std::sin(m_.pennation_angle_at_optimal);
  const double fiso = m_.max_isometric_force, vmax = m_.max_contraction_velocity;
  const double tol = std::max(1e-8 * fiso, kSignificantReal * 10);
  const int max_iter = 20;
  const double l_min = pen_.minFiberLength();

  double tl = tsl * 1.01;
  double lce = pen_.fiberLength(ml, tl);
  double phi = 0.0, cosphi = 1.0, tlN = tl / tsl, lceN = lce / ofl;
  double fse = 0, fal = 0, fpe = 0, fv = 0, dtl = 0, dlce = 0, dlceN = 0;
  double Fm = 0, FmAT = 0, Ft = 0, ferr = std::numeric_limits<double>::max();
  double dFm_dlce = 0, dFmAT_dlce = 0, dFmAT_dlceAT = 0, dFt_d_lce = 0, dFt_d_tl = 0;

  const auto position = [&] {
    phi = pen_.pennationAngle(lce);
    cosphi = std::cos(phi);
    tl = ml - lce * cosphi;
    lceN = lce / ofl;
    tlN = tl / tsl;
  };
  const auto multipliers = [&] {
    fse = c_.fse(tlN);
    fal = c_.fal(lceN);
    fpe = c_.fpe(lceN);
  };
  const auto error = [&] {
    Fm = (ma * fal * fv + fpe) * fiso;
    FmAT = Fm * cosphi;
    Ft = fse * fiso;
    ferr = FmAT - Ft;
  };
  // the partial derivatives of the fibre force along the tendon and of the tendon force
  const auto partials = [&] {
    dFm_dlce = ((ma * fv) * c_.dfalDlceN(lceN) + c_.dfpeDlceN(lceN)) * fiso * (1 / ofl);
    const double h2 = vol * vol, l2 = lce * lce, l3 = l2 * lce;
    const double dcosphi_d_lce = h2 / (l3 * std::pow(1 - h2 / l2, 0.5));
    dFmAT_dlce = dFm_dlce * cosphi + Fm * dcosphi_d_lce;
    dFmAT_dlceAT = dFmAT_dlce * cosphi;
    const double dfse = c_.dfseDtlN(tl / tsl);
    dFt_d_tl = dfse * (fiso / tsl);
    const double r = vol / lce;
    const double dphi_d_lce = -vol / (lce * lce * std::pow(1 - r * r, 0.5));
    const double dtl_d_lce = -std::cos(phi) + lce * std::sin(phi) * dphi_d_lce;
    dFt_d_lce = c_.dfseDtlN(tlN) * dtl_d_lce * (fiso / tsl);
  };
  // the path's lengthening speed shared between fibre and tendon by their stiffnesses
  const auto velocity = [&] {
    if (std::abs(dFmAT_dlceAT + dFt_d_tl) > kSignificantReal && tl > tsl)
      dtl = (dFmAT_dlceAT / (dFmAT_dlceAT + dFt_d_tl)) * dml;
    else
      dtl = dml;
    dlce = (dml - dtl) * cosphi;
    dlceN = dlce / (vmax * ofl);
    fv = c_.fvInverse(ma, fal, dlceN, tol, 100);
  };

  position();
  multipliers();
  fv = 1.0;
  partials();
  velocity();
  error();
  partials();
  const FiberLengthSolve r = solveFiberLength(
      lce, ferr, dFmAT_dlce - dFt_d_lce, l_min, tol, max_iter,
      [&](double l) {
        lce = l;
        position();
        multipliers();
        error();
        return ferr;
      },
      [&] {
        partials();
        velocity();
        return dFmAT_dlce - dFt_d_lce;
      });
  lce = r.lce;
  const int iter = r.iterations;
  if (std::abs(ferr) < tol) {
    z[1] = lce;
    return;
  }
  if (lce <= l_min) {  // OpenSim warns and keeps the minimum length
    z[1] = l_min;
    return;
  }
  throw MuscleModelError("Thelen2003Muscle '" + name_ + "': no fibre length balances the tendon (error " +
                         std::to_string(std::abs(ferr)) + " N after " + std::to_string(iter) +
                         " Newton iterations, activation " + std::to_string(ma) + ")");
}

std::vector<std::pair<std::string, double>> Thelen2003Muscle::parameterList() const {
  ParameterList out;
  appendMuscleProperties(m_, out);
  out.emplace_back("default_activation", m_.default_activation);
  out.emplace_back("default_fiber_length", m_.default_fiber_length);
  c_.append(out);
  out.emplace_back("fv_linear_extrap_threshold", c_.fv_linear_extrap_threshold);
  out.emplace_back("maximum_pennation_angle", maximum_pennation_angle_);
  out.emplace_back("activation_time_constant", act_.activation_time_constant);
  out.emplace_back("deactivation_time_constant", act_.deactivation_time_constant);
  out.emplace_back("minimum_activation", act_.minimum_activation);
  out.emplace_back("minimum_fiber_length", pen_.minFiberLength());
  return out;
}

// ---------------------------------------------------------------------------------------------
// Thelen2003Muscle_Deprecated

Thelen2003MuscleDeprecated::Thelen2003MuscleDeprecated(const MuscleParameters& p) {
  name_ = p.name;
  m_ = readMuscleProperties(p, 0.0);
  noIgnoreFlags(p, m_, "Thelen2003Muscle_Deprecated");
  tau_act_ = p.get("activation_time_constant", 0.01);
  tau_deact_ = p.get("deactivation_time_constant", 0.04);
  Vmax_ = p.get("Vmax", 10.0);
  Vmax0_ = p.get("Vmax0", 5.0);
  c_.read(p);
  c_.damping = p.get("damping", 0.05);
  // OpenSim checks none of these; these are the values whose equations divide by zero
  positive(p, "activation_time_constant", tau_act_);
  positive(p, "deactivation_time_constant", tau_deact_);
  c_.check(p.name);
  if (!(c_.damping >= 0)) bad(p.name, "damping", "must be >= 0");
  if (!std::isfinite(Vmax_) || !std::isfinite(Vmax0_)) bad(p.name, "Vmax", "must be finite");
}

const std::vector<std::string>& Thelen2003MuscleDeprecated::stateNames() const {
  return activationFiberLengthStates();
}

void Thelen2003MuscleDeprecated::defaultState(double* z) const {
  z[0] = 0.0;
  z[1] = 0.0;
}

double Thelen2003MuscleDeprecated::pennation(double l_f, double l_opt) const {
  return deprecatedPennation(l_f, l_opt, m_.pennation_angle_at_optimal);
}

IsometricCurves Thelen2003MuscleDeprecated::isometricCurves() const {
  IsometricCurves c;
  c.active = [this](double l) { return c_.active(l); };
  c.passive = [this](double l) { return c_.passive(l); };
  c.tendon_force = [this](double tendon_length) {
    const double l_opt = m_.optimal_fiber_length, norm_rest = m_.tendon_slack_length / l_opt;
    return c_.tendon((tendon_length / l_opt - norm_rest) / norm_rest);
  };
  c.tendon_stiffness = c.tendon_force;
  return c;
}

void Thelen2003MuscleDeprecated::calc(const double* z, const MusculotendonInput& in, MuscleOutput& out,
                                      double* zdot) const {
  const double l_opt = m_.optimal_fiber_length, l_s = m_.tendon_slack_length;
  const double F_max = m_.max_isometric_force;
  const double a = z[0], u = in.excitation;
  const double nfl = z[1] / l_opt;
  // the maximum shortening velocity grows with activation from Vmax0 to Vmax
  double Vmax = Vmax_;
  if (a < 1.0) Vmax = Vmax0_ + a * (Vmax - Vmax0_);
  Vmax = Vmax * l_opt;

  const double adot = u >= a ? (u - a) / tau_act_ : (u - a) / tau_deact_;

  const double ca = std::cos(pennation(nfl, 1.0));
  const double nmtl = in.length / l_opt;
  const double ntl = nmtl - nfl * ca;
  const double norm_rest = l_s / l_opt;
  const double tendon = c_.tendon((ntl - norm_rest) / norm_rest);
  const double passive = c_.passive(nfl);
  const double active = c_.active(nfl);

  double nfv;
  if (std::abs(ca - 0.0) <= kRoundoff) {
    // pennation at 90 degrees: the fibre stays until the tendon pulls, then a stiff-tendon
    // velocity. OpenSim subtracts the tendon slack length (m) from the normalized path length.
    if (std::abs(tendon - 0.0) <= kRoundoff) {
      nfv = 0.0;
    } else {
      const double h = nmtl - l_s;
      const double w = l_opt * std::sin(m_.pennation_angle_at_optimal);
      const double new_nfl = std::sqrt(h * h + w * w) / l_opt;
      nfv = in.speed / (Vmax * std::cos(pennation(new_nfl, 1.0)));
    }
  } else {
    nfv = c_.fiberVelocity(a, active, tendon / ca - passive);
  }

  // outputs as ActivationFiberLengthMuscle_Deprecated reports them
  const double phi = pennation(z[1], l_opt);
  out.activation = a;
  out.fiber_length = z[1];
  out.fiber_velocity = nfv * Vmax;
  out.pennation_angle = phi;
  out.tendon_length = in.length - z[1] * std::cos(phi);
  out.normalized_fiber_length = nfl;
  out.normalized_fiber_velocity = out.fiber_velocity / (l_opt * m_.max_contraction_velocity);
  out.tendon_force = tendon * F_max;
  out.passive_fiber_force = passive * F_max;
  out.active_fiber_force = out.tendon_force / std::cos(phi) - out.passive_fiber_force;

  zdot[0] = adot;
  zdot[1] = nfv * Vmax;
}

void Thelen2003MuscleDeprecated::equilibrate(const MusculotendonInput& in, double* z) const {
  deprecatedIsometricForce(m_, in.length, z[0], isometricCurves(), &z[1]);
}

double Thelen2003MuscleDeprecated::inextensibleTendonActiveFiberForce(const MusculotendonInput& in,
                                                                      double activation) const {
  return deprecatedInextensibleForce(m_, in, activation, isometricCurves());
}

std::vector<std::pair<std::string, double>> Thelen2003MuscleDeprecated::parameterList() const {
  ParameterList out;
  appendMuscleProperties(m_, out);
  out.emplace_back("activation_time_constant", tau_act_);
  out.emplace_back("deactivation_time_constant", tau_deact_);
  out.emplace_back("Vmax", Vmax_);
  out.emplace_back("Vmax0", Vmax0_);
  c_.append(out);
  out.emplace_back("damping", c_.damping);
  return out;
}

}  // namespace redmax::hill
