#pragma once
// Thelen 2003's musculotendon curves [Thelen 2003, Eqs. 1-5], as OpenSim computes them in
// Thelen2003Muscle (4.x) and Thelen2003Muscle_Deprecated (the 2.x pipeline's muscle_deriv_func9).
// Lengths are normalized: lceN = l_f / l_opt, tlN = l_T / l_s; velocities by v_max l_opt.
namespace redmax::hill {

/// Thelen2003Muscle's curves and its force-velocity inverse with linear extrapolation.
struct Thelen2003Curves {
  double FmaxTendonStrain = 0.04;  ///< e0 of the tendon: strain at F_max
  double FmaxMuscleStrain = 0.6;   ///< e0^M: passive strain at F_max
  double KshapeActive = 0.45;      ///< gamma: width of the Gaussian active force-length curve
  double KshapePassive = 5.0;      ///< k^PE
  double Af = 0.25;                ///< force-velocity shape factor
  double Flen = 1.4;               ///< maximum normalized lengthening force
  double fv_linear_extrap_threshold = 0.95;

  /// active force-length exp(-(lceN-1)^2 / gamma) [Thelen 2003, Eq. 3] and d/dlceN
  double fal(double lceN) const;
  double dfalDlceN(double lceN) const;
  /// passive force-length (exp(k (lceN-1)/e0) - 1) / (exp(k) - 1) for lceN > 1, else 0 (Eq. 2)
  double fpe(double lceN) const;
  double dfpeDlceN(double lceN) const;
  /// tendon force-strain (Eq. 1): exponential toe up to eToe, then linear with slope klin; eToe
  /// and klin are the exact values that make the curve C1 with F(eToe) = 0.33 (OpenSim's
  /// thelenINIT_20120127; the paper rounds eToe to 0.609 e0)
  double fse(double tlN) const;
  double dfseDtlN(double tlN) const;
  double toeStrain() const;
  double linearStiffness() const;
  /// normalized fibre velocity dlceN from the active fibre force a fal fv (Eq. 5 solved for the
  /// velocity, (0.25 + 0.75 a)(F - a fal)/b), linear beyond 0 and beyond threshold * a fal Flen
  double dlceN(double a, double fal, double a_fal_fv) const;
  /// d(dlceN)/d(a fal fv)
  double dDlceNDaFalFv(double a, double fal, double a_fal_fv) const;
  /// the force-velocity multiplier fv whose dlceN() equals `dlceN` (Newton from fv = 1, OpenSim's
  /// calcfvInv); throws MuscleModelError without convergence
  double fvInverse(double a, double fal, double dlceN, double tolerance = 1e-6, int max_iter = 100) const;
};

/// Thelen2003Muscle_Deprecated's curves (the same paper, as OpenSim 1.x-3.x coded it).
struct Thelen2003DeprecatedCurves {
  double FmaxTendonStrain = 0.033, FmaxMuscleStrain = 0.6, KshapeActive = 0.5, KshapePassive = 4.0;
  double damping = 0.05, Af = 0.3, Flen = 1.8;

  /// exp(-(lceN-1)^2 / gamma)
  double active(double lceN) const;
  double dActive(double lceN) const;
  /// exp(k (lceN-1)/e0) / exp(k), linear above lceN = 1 + e0 (nonzero at every length)
  double passive(double lceN) const;
  double dPassive(double lceN) const;
  /// tendon force from strain: toe 0.333333 (exp(3 e/eToe) - 1)/(exp(3) - 1) up to
  /// eToe = 0.609 e0, then 1.712/e0 (e - eToe) + 0.333333; plus 0.001 (1 + e) everywhere
  double tendon(double strain) const;
  double dTendon(double strain) const;
  /// normalized fibre velocity (by the activation-scaled Vmax) from the velocity-dependent force
  /// Fv = F_T/cos(phi) - F_PE at active force a fal, with the damping, linear below 0 and above
  /// 0.95 a fal Flen; a is raised to 1e-6
  double fiberVelocity(double a, double fal, double Fv) const;
};

}  // namespace redmax::hill
