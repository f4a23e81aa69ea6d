#include "core/muscles/hill/millard2012_equilibrium_muscle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace redmax::hill {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
const double kSignificantReal = std::pow(kEps, 0.875);
const double kSqrtEps = std::sqrt(kEps);
constexpr double kMinNonzeroDamping = 0.001;  // OpenSim's MIN_NONZERO_DAMPING_COEFFICIENT

[[noreturn]] void bad(const std::string& muscle, const std::string& key, const std::string& what) {
  throw MuscleParameterError(key, "muscle '" + muscle + "': " + key + " " + what);
}

// build a curve; a refused curve property is reported under its curve ("FiberForceLengthCurve/...")
template <class F>
SmoothSegmentedFunction curve(const std::string& muscle, const std::string& name, F make) {
  try {
    return make();
  } catch (const MuscleParameterError& e) {
    throw MuscleParameterError(name + "/" + e.property(), "muscle '" + muscle + "': " + name + " " + e.what());
  } catch (const MuscleModelError& e) {
    throw MuscleParameterError(name, "muscle '" + muscle + "': " + name + ": " + e.what());
  }
}

// the optional properties of a curve: all given or none (OpenSim refuses a mix)
bool optionalGroup(const MuscleParameters& p, const std::string& curve_name,
                   const std::vector<std::string>& keys) {
  int given = 0;
  for (const auto& k : keys) given += p.has(curve_name + "/" + k);
  if (given != 0 && given != static_cast<int>(keys.size()))
    bad(p.name, curve_name + "/" + keys[0],
        "and the other optional properties of " + curve_name + " must all be given, or none");
  return given > 0;
}

}  // namespace

Millard2012EquilibriumMuscle::Millard2012EquilibriumMuscle(const MuscleParameters& p) {
  name_ = p.name;
  // min_control's default is the default minimum activation, 0.01 (set at construction)
  m_ = readMuscleProperties(p, 0.01);
  m_.default_activation = p.get("default_activation", 0.05);
  beta_ = p.get("fiber_damping", 0.1);
  act_.activation_time_constant = p.get("activation_time_constant", 0.010);
  act_.deactivation_time_constant = p.get("deactivation_time_constant", 0.040);
  act_.minimum_activation = p.get("minimum_activation", 0.01);
  maximum_pennation_angle_ = p.get("maximum_pennation_angle", std::acos(0.1));

  // the curves' properties
  Millard2012CurveParameters& c = cp_;
  const auto g = [&](const std::string& key, double& v) { v = p.get(key, v); };
  g("ActiveForceLengthCurve/min_norm_active_fiber_length", c.min_norm_active_fiber_length);
  g("ActiveForceLengthCurve/transition_norm_fiber_length", c.transition_norm_fiber_length);
  g("ActiveForceLengthCurve/max_norm_active_fiber_length", c.max_norm_active_fiber_length);
  g("ActiveForceLengthCurve/shallow_ascending_slope", c.shallow_ascending_slope);
  g("ActiveForceLengthCurve/minimum_value", c.minimum_value);
  g("ForceVelocityCurve/concentric_slope_at_vmax", c.concentric_slope_at_vmax);
  g("ForceVelocityCurve/concentric_slope_near_vmax", c.concentric_slope_near_vmax);
  g("ForceVelocityCurve/isometric_slope", c.isometric_slope);
  g("ForceVelocityCurve/eccentric_slope_at_vmax", c.eccentric_slope_at_vmax);
  g("ForceVelocityCurve/eccentric_slope_near_vmax", c.eccentric_slope_near_vmax);
  g("ForceVelocityCurve/max_eccentric_velocity_force_multiplier", c.max_eccentric_velocity_force_multiplier);
  g("ForceVelocityCurve/concentric_curviness", c.concentric_curviness);
  g("ForceVelocityCurve/eccentric_curviness", c.eccentric_curviness);
  g("FiberForceLengthCurve/strain_at_zero_force", c.fpe_strain_at_zero_force);
  g("FiberForceLengthCurve/strain_at_one_norm_force", c.fpe_strain_at_one_norm_force);
  if (optionalGroup(p, "FiberForceLengthCurve", {"stiffness_at_low_force", "stiffness_at_one_norm_force", "curviness"})) {
    g("FiberForceLengthCurve/stiffness_at_low_force", c.fpe_stiffness_at_low_force);
    g("FiberForceLengthCurve/stiffness_at_one_norm_force", c.fpe_stiffness_at_one_norm_force);
    g("FiberForceLengthCurve/curviness", c.fpe_curviness);
  } else {
    // OpenSim's values when none is given
    c.fpe_stiffness_at_one_norm_force = 2.0 / (c.fpe_strain_at_one_norm_force - c.fpe_strain_at_zero_force);
    c.fpe_stiffness_at_low_force = 0.2;
    c.fpe_curviness = 0.75;
  }
  g("TendonForceLengthCurve/strain_at_one_norm_force", c.tendon_strain_at_one_norm_force);
  if (optionalGroup(p, "TendonForceLengthCurve", {"stiffness_at_one_norm_force", "norm_force_at_toe_end", "curviness"})) {
    g("TendonForceLengthCurve/stiffness_at_one_norm_force", c.tendon_stiffness_at_one_norm_force);
    g("TendonForceLengthCurve/norm_force_at_toe_end", c.tendon_norm_force_at_toe_end);
    g("TendonForceLengthCurve/curviness", c.tendon_curviness);
  } else {
    c.tendon_stiffness_at_one_norm_force = 1.375 / c.tendon_strain_at_one_norm_force;
    c.tendon_norm_force_at_toe_end = 2.0 / 3.0;
    c.tendon_curviness = 0.5;
  }

  // extendFinalizeFromProperties: which model, and the curve adjustments it implies
  if (beta_ < kMinNonzeroDamping) beta_ = 0.0;
  damped_ = beta_ >= kMinNonzeroDamping;
  if (!(beta_ >= 0) || !std::isfinite(beta_)) bad(p.name, "fiber_damping", "must be finite and >= 0");
  if (c.concentric_slope_near_vmax < kSqrtEps)
    bad(p.name, "ForceVelocityCurve/concentric_slope_near_vmax", "cannot be less than 1.49e-8");
  if (c.eccentric_slope_near_vmax < kSqrtEps)
    bad(p.name, "ForceVelocityCurve/eccentric_slope_near_vmax", "cannot be less than 1.49e-8");
  double con_at_vmax = c.concentric_slope_at_vmax, ecc_at_vmax = c.eccentric_slope_at_vmax;
  if (!m_.ignore_tendon_compliance && !damped_) {
    // the classic Hill model divides by a fal and needs an invertible force-velocity curve
    if (act_.minimum_activation < 0.01)
      bad(p.name, "minimum_activation", "cannot be less than 0.01 with an elastic tendon and no damping");
    if (m_.min_control < act_.minimum_activation)
      bad(p.name, "min_control", "cannot be less than minimum_activation");
    if (c.minimum_value < 0.1) c.minimum_value = 0.1;
    if (con_at_vmax < c.concentric_slope_near_vmax * 0.5) con_at_vmax = c.concentric_slope_near_vmax * 0.5;
    if (ecc_at_vmax < c.eccentric_slope_near_vmax * 0.5) ecc_at_vmax = c.eccentric_slope_near_vmax * 0.5;
  } else {
    // the damped (or rigid-tendon) model: no active force at the curve ends, flat velocity ends
    if (act_.minimum_activation > 0.0) act_.minimum_activation = std::clamp(act_.minimum_activation, 0.0, 1.0);
    if (c.minimum_value > 0.0) c.minimum_value = 0.0;
    if (con_at_vmax > 0.0) con_at_vmax = 0.0;
    if (ecc_at_vmax > 0.0) ecc_at_vmax = 0.0;
    if (act_.minimum_activation < 0.0) bad(p.name, "minimum_activation", "cannot be less than zero");
    if (m_.min_control < act_.minimum_activation)
      bad(p.name, "min_control", "cannot be less than minimum_activation");
  }
  c.concentric_slope_at_vmax = con_at_vmax;
  c.eccentric_slope_at_vmax = ecc_at_vmax;
  if (!m_.ignore_activation_dynamics) {
    if (!(act_.activation_time_constant >= kSignificantReal))
      bad(p.name, "activation_time_constant", "must be greater than zero");
    if (!(act_.deactivation_time_constant >= kSignificantReal))
      bad(p.name, "deactivation_time_constant", "must be greater than zero");
    if (!(act_.minimum_activation <= 1.0 - kSignificantReal))
      bad(p.name, "minimum_activation", "must be in [0, 1)");
  }

  fal_ = curve(p.name, "ActiveForceLengthCurve", [&] {
    return makeFiberActiveForceLengthCurve(c.min_norm_active_fiber_length, c.transition_norm_fiber_length, 1.0,
                                           c.max_norm_active_fiber_length, c.minimum_value,
                                           c.shallow_ascending_slope, 1.0);
  });
  fv_ = curve(p.name, "ForceVelocityCurve", [&] {
    return makeFiberForceVelocityCurve(c.max_eccentric_velocity_force_multiplier, con_at_vmax,
                                       c.concentric_slope_near_vmax, c.isometric_slope, ecc_at_vmax,
                                       c.eccentric_slope_near_vmax, c.concentric_curviness, c.eccentric_curviness);
  });
  // the inverse (classic model's velocity, and the damped solve's first guess) has slopes at
  // v_max of half those near it, so that it is invertible
  fv_inv_ = curve(p.name, "ForceVelocityCurve", [&] {
    return makeFiberForceVelocityInverseCurve(
        c.max_eccentric_velocity_force_multiplier, c.concentric_slope_near_vmax * 0.5, c.concentric_slope_near_vmax,
        c.isometric_slope, c.eccentric_slope_near_vmax * 0.5, c.eccentric_slope_near_vmax, c.concentric_curviness,
        c.eccentric_curviness);
  });
  fpe_ = curve(p.name, "FiberForceLengthCurve", [&] {
    return makeFiberForceLengthCurve(c.fpe_strain_at_zero_force, c.fpe_strain_at_one_norm_force,
                                     c.fpe_stiffness_at_low_force, c.fpe_stiffness_at_one_norm_force, c.fpe_curviness);
  });
  fse_ = curve(p.name, "TendonForceLengthCurve", [&] {
    return makeTendonForceLengthCurve(c.tendon_strain_at_one_norm_force, c.tendon_stiffness_at_one_norm_force,
                                      c.tendon_norm_force_at_toe_end, c.tendon_curviness);
  });

  try {
    pen_ = FixedWidthPennation(m_.optimal_fiber_length, m_.pennation_angle_at_optimal, maximum_pennation_angle_);
  } catch (const MuscleParameterError& e) {
    bad(p.name, e.property(), "must be in [0, pi/2]");
  }
  l_min_ = std::max(kSignificantReal,
                    std::max(c.min_norm_active_fiber_length * m_.optimal_fiber_length, pen_.minFiberLength()));

  if (!m_.ignore_activation_dynamics) {
    i_act_ = static_cast<int>(state_names_.size());
    state_names_.push_back("activation");
  }
  if (!m_.ignore_tendon_compliance) {
    i_len_ = static_cast<int>(state_names_.size());
    state_names_.push_back("fiber_length");
  }
}

void Millard2012EquilibriumMuscle::defaultState(double* z) const {
  // setActivation clamps to [minimum_activation, 1]; setFiberLength to the minimum length
  if (i_act_ >= 0) z[i_act_] = act_.clamp(m_.default_activation);
  if (i_len_ >= 0) z[i_len_] = std::max(m_.default_fiber_length, l_min_);
}

double Millard2012EquilibriumMuscle::inextensibleTendonActiveFiberForce(const MusculotendonInput& in,
                                                                       double activation) const {
  const double l_opt = m_.optimal_fiber_length;
  const double lce = pen_.fiberLength(in.length, m_.tendon_slack_length);
  const double phi = pen_.pennationAngle(lce);
  const double dlce = in.speed * std::cos(phi);  // rigid tendon
  if (std::isnan(dlce)) return 0.0;
  // calcActiveFiberForceAlongTendon
  if (lce <= l_min_) return 0.0;
  const double a = act_.clamp(activation);
  const double lceN = lce / l_opt;
  const double dlceN = dlce / (l_opt * m_.max_contraction_velocity);
  const double fal = fal_.value(lceN), fv = fv_.value(dlceN);
  // OpenSim passes the normalized fibre length to the pennation model here
  const double phi_n = pen_.pennationAngle(lceN);
  return m_.max_isometric_force * (a * fal * fv) * std::cos(phi_n);
}

double Millard2012EquilibriumMuscle::activationOf(const double* z, double u) const {
  return act_.clamp(i_act_ >= 0 ? z[i_act_] : u);
}

void Millard2012EquilibriumMuscle::calc(const double* z, const MusculotendonInput& in, MuscleOutput& out,
                                        double* zdot) const {
  const double l_opt = m_.optimal_fiber_length, l_s = m_.tendon_slack_length;
  const double fiso = m_.max_isometric_force, vmax = m_.max_contraction_velocity;
  const bool rigid = m_.ignore_tendon_compliance;
  const double a = activationOf(z, in.excitation);

  // length stage: a rigid tendon keeps its slack length, the fibre takes the rest
  const double lce = std::max(rigid ? pen_.fiberLength(in.length, l_s) : z[i_len_], l_min_);
  const double lceN = lce / l_opt;
  const double phi = pen_.pennationAngle(lce);
  const double cosphi = std::cos(phi);
  const double tl = in.length - lce * cosphi;
  const double tlN = tl / l_s;
  double fpe, dfpe, fal, dfal;
  fpe_.valueAndDerivative(lceN, fpe, dfpe);
  fal_.valueAndDerivative(lceN, fal, dfal);

  // velocity stage
  double fse = std::numeric_limits<double>::quiet_NaN();
  if (!rigid) fse = fse_.value(tlN);
  double dlce, dlceN, fv;
  if (rigid) {
    if (tl < l_s - kSignificantReal) {  // a slack tendon: the fibre does not move
      dlce = 0.0;
      dlceN = 0.0;
      fv = 1.0;
    } else {
      dlce = in.speed * cosphi;
      dlceN = dlce / (l_opt * vmax);
      fv = fv_.value(dlceN);
    }
  } else if (!damped_) {
    // classic Hill model: fv from the force balance, the velocity from the inverse curve
    if (!(cosphi > kSignificantReal && a > kSignificantReal && fal > kSignificantReal))
      throw MuscleModelError("Millard2012EquilibriumMuscle '" + name_ +
                             "': the undamped model is singular (pennation at 90 degrees, zero activation or "
                             "zero active force-length multiplier)");
    fv = (fse / cosphi - fpe) / (a * fal);
    dlceN = fv_inv_.value(fv);
    dlce = dlceN * vmax * l_opt;
  } else {
    // damped model: Newton on the normalized velocity for
    // (a fal fv(v) + fpe + beta v) cos(phi) = fse, from the inverse curve's guess within [-1, 1]
    int iter = 0;
    double tol = std::max(1.0e-10 * fiso, kSignificantReal * 100);
    double err = 1.0e10;
    fv = (fse / std::max(cosphi, 0.01) - fpe) / (std::max(a, 0.01) * std::max(fal, 0.01));
    double v = std::clamp(fv_inv_.value(fv), -1.0, 1.0);
    int nudges = 0;
    while (std::abs(err) > tol && iter < 20) {
      double dfv;
      fv_.valueAndDerivative(v, fv, dfv);
      const double Fm = fiso * (a * fal * fv) + (fiso * fpe + fiso * beta_ * v);
      err = Fm * cosphi - fse * fiso;
      const double derr = fiso * (a * fal * dfv + beta_) * cosphi;
      if (std::abs(err) > tol && std::abs(derr) > kSignificantReal) {
        v -= err / derr;
      } else if (std::abs(derr) < kSignificantReal) {
        // OpenSim nudges by a random amount in [-0.05, 0.05]; a fixed sequence here
        v += 0.05 * ((nudges++ % 2) ? -0.5 : 0.5);
      }
      ++iter;
    }
    if (!(std::abs(err) <= tol))
      throw MuscleModelError("Millard2012EquilibriumMuscle '" + name_ +
                             "': the damped fibre velocity did not converge (error " + std::to_string(err) + " N)");
    dlceN = v;
    dlce = dlceN * l_opt * vmax;
  }
  // a fibre at its minimum length that would shorten further is held there
  const bool clamped = lce <= l_min_ && dlce <= 0;
  if (clamped) {
    dlce = 0.0;
    dlceN = 0.0;
    fv = 1.0;
  }

  // dynamics stage
  double aFm = 0, pFm = 0, fmAT = 0, p1 = 0;
  if (!clamped) {
    aFm = fiso * (a * fal * fv);
    p1 = fiso * fpe;
    double p2 = fiso * beta_ * dlceN;
    double fm = aFm + (p1 + p2);
    // a rigid tendon cannot push: the damping takes what would make the fibre force negative
    if (rigid && fm < 0) {
      fm = 0.0;
      p2 = -aFm - p1;
    }
    pFm = p1 + p2;
    fmAT = fm * cosphi;
  }
  const double tendon_force = rigid ? fmAT : fse * fiso;

  out.activation = a;
  out.fiber_length = lce;
  out.fiber_velocity = dlce;
  out.pennation_angle = phi;
  out.tendon_length = tl;
  out.normalized_fiber_length = lceN;
  out.normalized_fiber_velocity = dlceN;
  out.tendon_force = tendon_force;
  out.active_fiber_force = aFm;
  out.passive_fiber_force = pFm;
  out.passive_fiber_elastic_force = p1;  // p2 (damping) is in pFm only
  if (i_act_ >= 0) zdot[i_act_] = act_.derivative(z[i_act_], in.excitation);
  if (i_len_ >= 0) zdot[i_len_] = dlce;
}

void Millard2012EquilibriumMuscle::equilibrate(const MusculotendonInput& in, double* z) const {
  if (m_.ignore_tendon_compliance) return;
  const double ma = activationOf(z, in.excitation);  // Muscle::getActivation: clamped
  const double ml = in.length, tsl = m_.tendon_slack_length, ofl = m_.optimal_fiber_length;
  const double fiso = m_.max_isometric_force;
  const double tol = std::max(1e-8 * fiso, kSignificantReal * 10);
  const int max_iter = 200;
  // static: the fibre at rest, fv = 1, no damping force
  const double fv = 1.0, dlceN = 0.0;

  double tl = tsl * 1.01;
  double lce = std::max(pen_.fiberLength(ml, tl), l_min_);
  double phi = 0, cosphi = 1, sinphi = 0, tlN = tl / tsl, lceN = lce / ofl;
  double fse = 0, fal = 0, fpe = 0, Fm = 0, ferr = std::numeric_limits<double>::max();
  double dFmAT_dlce = 0, dFt_d_lce = 0;
  const auto position = [&] {
    phi = pen_.pennationAngle(lce);
    cosphi = std::cos(phi);
    sinphi = std::sin(phi);
    tl = ml - lce * cosphi;
    lceN = lce / ofl;
    tlN = tl / tsl;
  };
  const auto multipliers = [&] {
    fal = fal_.value(lceN);
    fpe = fpe_.value(lceN);
    fse = fse_.value(tlN);
  };
  const auto error = [&] {
    Fm = fiso * (ma * fal * fv) + (fiso * fpe + fiso * beta_ * dlceN);
    ferr = Fm * cosphi - fse * fiso;
  };
  const auto partials = [&] {
    const double dFm_dlce = fiso * (ma * (fal_.derivative(lceN) / ofl) * fv + fpe_.derivative(lceN) / ofl);
    const double dphi = pen_.dPennationAngleDFiberLength(lce);
    dFmAT_dlce = dFm_dlce * cosphi + Fm * (-sinphi * dphi);
    const double dFt_d_tl = fse_.derivative(tlN) * fiso / tsl;
    dFt_d_lce = dFt_d_tl * (lce * sinphi * dphi - cosphi);
  };

  position();
  multipliers();
  Fm = fiso * (ma * fal * fv) + (fiso * fpe + fiso * beta_ * dlceN);
  partials();
  error();
  partials();
  const FiberLengthSolve r = solveFiberLength(
      lce, ferr, dFmAT_dlce - dFt_d_lce, l_min_, tol, max_iter,
      [&](double l) {
        lce = l;
        position();
        multipliers();
        error();
        return ferr;
      },
      [&] {
        partials();
        return dFmAT_dlce - dFt_d_lce;
      });
  lce = r.lce;
  const int iter = r.iterations;
  if (std::abs(ferr) < tol) {
    z[i_len_] = std::max(lce, l_min_);
    return;
  }
  if (lce <= l_min_) {  // OpenSim warns and keeps the minimum length
    z[i_len_] = l_min_;
    return;
  }
  throw MuscleModelError("Millard2012EquilibriumMuscle '" + name_ +
                         "': no fibre length balances the tendon (error " + std::to_string(std::abs(ferr)) +
                         " N after " + std::to_string(iter) + " iterations, activation " + std::to_string(ma) + ")");
}

std::vector<std::pair<std::string, double>> Millard2012EquilibriumMuscle::parameterList() const {
  ParameterList out;
  appendMuscleProperties(m_, out);
  const Millard2012CurveParameters& c = cp_;
  const std::pair<const char*, double> rows[] = {
      {"default_activation", m_.default_activation},
      {"default_fiber_length", m_.default_fiber_length},
      {"fiber_damping", beta_},
      {"activation_time_constant", act_.activation_time_constant},
      {"deactivation_time_constant", act_.deactivation_time_constant},
      {"minimum_activation", act_.minimum_activation},
      {"maximum_pennation_angle", maximum_pennation_angle_},
      {"minimum_fiber_length", l_min_},
      {"ActiveForceLengthCurve/min_norm_active_fiber_length", c.min_norm_active_fiber_length},
      {"ActiveForceLengthCurve/transition_norm_fiber_length", c.transition_norm_fiber_length},
      {"ActiveForceLengthCurve/max_norm_active_fiber_length", c.max_norm_active_fiber_length},
      {"ActiveForceLengthCurve/shallow_ascending_slope", c.shallow_ascending_slope},
      {"ActiveForceLengthCurve/minimum_value", c.minimum_value},
      {"ForceVelocityCurve/concentric_slope_at_vmax", c.concentric_slope_at_vmax},
      {"ForceVelocityCurve/concentric_slope_near_vmax", c.concentric_slope_near_vmax},
      {"ForceVelocityCurve/isometric_slope", c.isometric_slope},
      {"ForceVelocityCurve/eccentric_slope_at_vmax", c.eccentric_slope_at_vmax},
      {"ForceVelocityCurve/eccentric_slope_near_vmax", c.eccentric_slope_near_vmax},
      {"ForceVelocityCurve/max_eccentric_velocity_force_multiplier", c.max_eccentric_velocity_force_multiplier},
      {"ForceVelocityCurve/concentric_curviness", c.concentric_curviness},
      {"ForceVelocityCurve/eccentric_curviness", c.eccentric_curviness},
      {"FiberForceLengthCurve/strain_at_zero_force", c.fpe_strain_at_zero_force},
      {"FiberForceLengthCurve/strain_at_one_norm_force", c.fpe_strain_at_one_norm_force},
      {"FiberForceLengthCurve/stiffness_at_low_force", c.fpe_stiffness_at_low_force},
      {"FiberForceLengthCurve/stiffness_at_one_norm_force", c.fpe_stiffness_at_one_norm_force},
      {"FiberForceLengthCurve/curviness", c.fpe_curviness},
      {"TendonForceLengthCurve/strain_at_one_norm_force", c.tendon_strain_at_one_norm_force},
      {"TendonForceLengthCurve/stiffness_at_one_norm_force", c.tendon_stiffness_at_one_norm_force},
      {"TendonForceLengthCurve/norm_force_at_toe_end", c.tendon_norm_force_at_toe_end},
      {"TendonForceLengthCurve/curviness", c.tendon_curviness}};
  for (const auto& [k, v] : rows) out.emplace_back(k, v);
  return out;
}

}  // namespace redmax::hill
