#include "core/muscles/hill/thelen2003_curves.hpp"

#include <cmath>
#include <limits>

#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill {
namespace {
const double kSignificantReal = std::pow(std::numeric_limits<double>::epsilon(), 0.875);
}

// ---------------------------------------------------------------------------------------------
// shape parameters

void ThelenShapeParameters::read(const MuscleParameters& p) {
  FmaxTendonStrain = p.get("FmaxTendonStrain", FmaxTendonStrain);
  FmaxMuscleStrain = p.get("FmaxMuscleStrain", FmaxMuscleStrain);
  KshapeActive = p.get("KshapeActive", KshapeActive);
  KshapePassive = p.get("KshapePassive", KshapePassive);
  Af = p.get("Af", Af);
  Flen = p.get("Flen", Flen);
}

void ThelenShapeParameters::check(const std::string& muscle) const {
  const std::pair<const char*, double> positive[] = {{"FmaxTendonStrain", FmaxTendonStrain},
                                                     {"FmaxMuscleStrain", FmaxMuscleStrain},
                                                     {"KshapeActive", KshapeActive},
                                                     {"KshapePassive", KshapePassive},
                                                     {"Af", Af}};
  for (const auto& [key, v] : positive)
    if (!(v > 0) || !std::isfinite(v))
      throw MuscleParameterError(key, "muscle '" + muscle + "': " + key + " must be finite and > 0");
  if (!(Flen > 1.0)) throw MuscleParameterError("Flen", "muscle '" + muscle + "': Flen must be greater than 1");
}

void ThelenShapeParameters::append(ParameterList& out) const {
  out.emplace_back("FmaxTendonStrain", FmaxTendonStrain);
  out.emplace_back("FmaxMuscleStrain", FmaxMuscleStrain);
  out.emplace_back("KshapeActive", KshapeActive);
  out.emplace_back("KshapePassive", KshapePassive);
  out.emplace_back("Af", Af);
  out.emplace_back("Flen", Flen);
}

// ---------------------------------------------------------------------------------------------
// Thelen2003Muscle

double Thelen2003Curves::fal(double lceN) const {
  const double x = lceN - 1.0;
  return std::exp(-x * x / KshapeActive);
}

double Thelen2003Curves::dfalDlceN(double lceN) const {
  // (OpenSim's operation order, so that the two agree to the last bit)
  const double x = lceN - 1.0, inv_k = 1.0 / KshapeActive;
  return -2.0 * x * inv_k * std::exp(-(x * x) * inv_k);
}

double Thelen2003Curves::fpe(double lceN) const {
  if (!(lceN > 1.0)) return 0.0;
  return (std::exp(KshapePassive * (lceN - 1.0) / FmaxMuscleStrain) - 1.0) / (std::exp(KshapePassive) - 1.0);
}

double Thelen2003Curves::dfpeDlceN(double lceN) const {
  if (!(lceN > 1.0)) return 0.0;
  const double inv_e0 = 1.0 / FmaxMuscleStrain;
  return KshapePassive * inv_e0 * std::exp(KshapePassive * (lceN - 1.0) * inv_e0) /
         (std::exp(KshapePassive) - 1.0);
}

// eToe = 99 e0 e^3 / (166 e^3 - 67), klin = 0.67 / (e0 - eToe): F(eToe) = 0.33 and the toe's slope
// at eToe equals klin
double Thelen2003Curves::toeStrain() const {
  const double e3 = std::exp(3.0);
  return 99.0 * FmaxTendonStrain * e3 / (166.0 * e3 - 67.0);
}

double Thelen2003Curves::linearStiffness() const { return 0.67 / (FmaxTendonStrain - toeStrain()); }

double Thelen2003Curves::fse(double tlN) const {
  const double x = tlN - 1.0, e_toe = toeStrain(), k_toe = 3.0, f_toe = 0.33;
  if (x > e_toe) return linearStiffness() * (x - e_toe) + f_toe;
  if (x > 0.0) return f_toe / (std::exp(k_toe) - 1.0) * (std::exp(k_toe * x / e_toe) - 1.0);
  return 0.0;
}

double Thelen2003Curves::dfseDtlN(double tlN) const {
  const double x = tlN - 1.0, e_toe = toeStrain(), k_toe = 3.0, f_toe = 0.33;
  if (x > e_toe) return linearStiffness();
  if (x > 0.0) return f_toe / (std::exp(k_toe) - 1.0) * (k_toe / e_toe) * std::exp(k_toe * x / e_toe);
  return 0.0;
}

// Eq. 5 solved for the velocity: dlceN = (0.25 + 0.75 a)(F - a fal) / b, with b from the
// concentric (F <= a fal) or eccentric branch; outside (0, threshold a fal Flen) the tangent line
// at the nearer end
namespace {
// b of Eq. 5 and db/dF on the concentric or the eccentric branch
void thelenB(double afl, double F, double Af, double Flen, bool concentric, double& b, double& db) {
  if (concentric) {
    b = afl + F / Af;
    db = 1.0 / Af;
  } else {
    b = (2.0 + 2.0 / Af) * (afl * Flen - F) / (Flen - 1.0);
    db = (2.0 + 2.0 / Af) * (-1.0) / (Flen - 1.0);
  }
}
}  // namespace

double Thelen2003Curves::dlceN(double a, double fal, double F) const {
  const double afl = a * fal, asy_e = afl * Flen, k = 0.25 + 0.75 * a;
  // fal underflows to 0 far outside the curve (a trial stage's state): both tangent lines are
  // 0/0 there (OpenSim's NaN); their limit as a fal -> 0 is -k at F = 0 and infinitely fast
  // otherwise (no damping holds the fibre), a non-finite rate the integrators refuse by name
  if (!(afl > 0.0)) return F > 0.0 ? HUGE_VAL : F < 0.0 ? -HUGE_VAL : -k;
  double b, db;
  if (F > 0.0 && F < asy_e * fv_linear_extrap_threshold) {
    thelenB(afl, F, Af, Flen, F <= afl, b, db);
    return k * (F - afl) / b;
  }
  // linear extrapolation from the last point of the curve (F0 = 0 or threshold * a fal Flen)
  const bool concentric = F <= 0.0;
  const double F0 = concentric ? 0.0 : fv_linear_extrap_threshold * asy_e;
  thelenB(afl, F0, Af, Flen, concentric, b, db);
  const double v0 = k * (F0 - afl) / b;
  const double dv = k * (1) / b - (k * (F0 - afl) / (b * b)) * db;
  return v0 + dv * (F - F0);
}

double Thelen2003Curves::dDlceNDaFalFv(double a, double fal, double F) const {
  const double afl = a * fal, asy_e = afl * Flen, k = 0.25 + 0.75 * a;
  double b, db, Fe;
  if (F > 0.0 && F < asy_e * fv_linear_extrap_threshold) {
    Fe = F;
    thelenB(afl, F, Af, Flen, F <= afl, b, db);
  } else {
    const bool concentric = F <= 0.0;
    Fe = concentric ? 0.0 : fv_linear_extrap_threshold * asy_e;
    thelenB(afl, Fe, Af, Flen, concentric, b, db);
  }
  return k * (1) / b - (k * (Fe - afl) / (b * b)) * db;
}

double Thelen2003Curves::fvInverse(double a, double fal, double target, double tolerance,
                                   int max_iter) const {
  // Newton on F = a fal fv from fv = 1 (OpenSim's calcfvInv)
  double ferr = 1.0, F = a * fal;
  for (int iter = 0; std::abs(ferr) >= tolerance && iter < max_iter; ++iter) {
    ferr = dlceN(a, fal, F) - target;
    const double d = dDlceNDaFalFv(a, fal, F);
    if (std::abs(d) > kSignificantReal) F -= ferr / d;
  }
  if (!(std::abs(ferr) < tolerance))
    throw MuscleModelError("Thelen2003Muscle: the force-velocity inverse did not converge");
  return std::max(0.0, F / (a * fal));
}

// ---------------------------------------------------------------------------------------------
// Thelen2003Muscle_Deprecated

double Thelen2003DeprecatedCurves::active(double lceN) const {
  return std::exp(-(lceN - 1.0) * (lceN - 1.0) / KshapeActive);
}

double Thelen2003DeprecatedCurves::dActive(double lceN) const {
  return -2.0 * (lceN - 1.0) / KshapeActive * active(lceN);
}

double Thelen2003DeprecatedCurves::passive(double lceN) const {
  const double k = KshapePassive, e0 = FmaxMuscleStrain;
  if (lceN > 1.0 + e0) {
    const double slope = (k / e0) * std::exp(k * (1.0 + e0 - 1.0) / e0) / std::exp(k);
    return 1.0 + slope * (lceN - (1.0 + e0));
  }
  return std::exp(k * (lceN - 1.0) / e0) / std::exp(k);
}

double Thelen2003DeprecatedCurves::dPassive(double lceN) const {
  const double k = KshapePassive, e0 = FmaxMuscleStrain;
  if (lceN > 1.0 + e0) return (k / e0) * std::exp(k * (1.0 + e0 - 1.0) / e0) / std::exp(k);
  return (k / e0) * std::exp(k * (lceN - 1.0) / e0) / std::exp(k);
}

double Thelen2003DeprecatedCurves::tendon(double e) const {
  const double k_toe = 3.0, e_toe = 0.609 * FmaxTendonStrain, f_toe = 0.333333;
  const double klin = 1.712 / FmaxTendonStrain;
  double f = 0.0;
  if (e > e_toe)
    f = klin * (e - e_toe) + f_toe;
  else if (e > 0.0)
    f = f_toe * (std::exp(k_toe * e / e_toe) - 1.0) / (std::exp(k_toe) - 1.0);
  return f + 0.001 * (1.0 + e);
}

double Thelen2003DeprecatedCurves::dTendon(double e) const {
  const double k_toe = 3.0, e_toe = 0.609 * FmaxTendonStrain, f_toe = 0.333333;
  double d = 0.0;
  if (e > e_toe)
    d = 1.712 / FmaxTendonStrain;
  else if (e > 0.0)
    d = f_toe * (k_toe / e_toe) * std::exp(k_toe * e / e_toe) / (std::exp(k_toe) - 1.0);
  return d + 0.001;
}

double Thelen2003DeprecatedCurves::fiberVelocity(double a, double fal, double Fv) const {
  const double eps = 1e-6;
  if (a < eps) a = eps;
  const double Fa = a * fal;
  if (Fv < Fa) {  // shortening
    if (Fv < 0) {
      // the line through the curve's points at F = 0 and F = eps
      const double F0 = 0, F1 = eps;
      const double fv0 = (F0 - Fa) / (Fa + F0 / Af + damping);
      const double fv1 = (F1 - Fa) / (Fa + F1 / Af + damping);
      return fv0 + (Fv - F0) / ((F1 - F0) / (fv1 - fv0));
    }
    return (Fv - Fa) / (Fa + Fv / Af + damping);
  }
  const auto ecc = [&](double F) {
    const double b = (2 + 2. / Af) * (Fa * Flen - F) / (Flen - 1.);
    return (F - Fa) / (b + damping);
  };
  if (Fv < .95 * Fa * Flen) return ecc(Fv);
  // beyond 0.95 Fa Flen: the secant over [0.95, 0.95 + eps] Fa Flen
  const double F0 = .95 * Fa * Flen, F1 = (.95 + eps) * Fa * Flen;
  // fal underflows to 0 far outside the curve (|lceN - 1| > 18 sqrt(KshapeActive), a trial stage's
  // state): the secant is 0/0 (OpenSim's NaN); its limit as Fa -> 0 is the damper alone
  if (!(F1 > F0)) return Fv / damping;
  const double fv0 = ecc(F0), fv1 = ecc(F1);
  return fv0 + (fv1 - fv0) / (F1 - F0) * (Fv - F0);
}

}  // namespace redmax::hill
