#pragma once
// Spherical joint in exponential coordinates [D Sec. 4.5.8]: R = exp([q]), q in R^3 (radians).
//
// S: [D Eq. 4.43-4.44] (Gallego and Yezzi's derivative) reduces to the right Jacobian of SO(3),
//   S_rot = J_r(q) = I - b(th) [q] + c(th) [q]^2,  b = (1 - cos th)/th^2,  c = (th - sin th)/th^3,
// th = |q|, which is what we evaluate: it has no 1/|q|^2 division, so the limit |q| -> 0
// (S_rot = I) is reached smoothly with Taylor series for b, c and their derivatives.
// Sdot differentiates it directly (equivalent to [D Eq. 4.47]):
//   Sdot_rot = -beta (q.qdot) [q] - b [qdot] + gamma (q.qdot) [q]^2 + c ([qdot][q] + [q][qdot]),
// with beta = b'(th)/th and gamma = c'(th)/th.
//
// Conditioning: the singular values of J_r are 1 (along q) and |sin(th/2)/(th/2)| (twice): it is
// singular only on the shells th = 2 pi n, and at th = pi its condition number is only pi/2.
#include "core/joints/joint_kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

struct SphericalExp {
  static constexpr int kNq = 3;
  /// Chart switch threshold: reparameterize when |q| > 1.5 pi. Grassia's rule is "near 2 pi",
  /// where S becomes singular. At 1.5 pi the condition number of S is still only 3.3, and
  /// mapping q -> (1 - 2 pi/|q|) q gives |q_new| = 2 pi - |q| < 0.5 pi. The band [0.5 pi, 1.5 pi]
  /// is a hysteresis: a joint swinging about |q| = pi never switches back and forth, and |q|
  /// never exceeds 1.5 pi (plus one step of motion) between checks.
  static constexpr double kReparameterizeAbove = 1.5 * 3.14159265358979323846;

  int nq() const { return 3; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
  /// If |q| > kReparameterizeAbove: q -> (1 - 2 pi/|q|) q (the same rotation) and
  /// qdot -> S_new^-1 S_prev qdot (the same body angular velocity) [D Sec. 4.5.8]. Returns
  /// whether it changed q and qdot.
  bool reparameterize(VecJ& q, VecJ& qdot) const;
  /// Distance from the singular shells |q| = 2 pi n: sigma_min(S)/sigma_max(S) =
  /// |sin(th/2)/(th/2)| in [0, 1] (1 at q = 0, 0.64 at pi, 0.30 at the 1.5 pi switch, 0 at 2 pi).
  double singularityDistance(const VecJ& q) const;

  /// rotation part only, 3 x 3 blocks (used by the free joints)
  static void calcRotation(const Vec3& q, const Vec3& qdot, Mat3& R, Mat3& S, Mat3& Sdot);
  /// the 3-vector version of reparameterize
  static bool reparameterizeRotation(Vec3& q, Vec3& qdot);
  /// the 3-vector version of singularityDistance
  static double rotationSingularityDistance(const Vec3& q);
};

}  // namespace redmax
