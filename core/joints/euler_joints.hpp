#pragma once
// Rotation joints parameterised by Euler angles [D Sec. 4.5.5, 4.5.6].
//
// Convention: intrinsic (body-fixed) sequences. For the sequence "abc",
//   R(q) = R_a(q1) R_b(q2) R_c(q3),
// the second rotation is about axis b of the frame already turned by the first, and so on.
// OpenSim/Simbody's "body-fixed XYZ" (Gimbal, Ball and Free with Euler angles) is sequence XYZ.
// Differentiating R gives the columns of the body Jacobian in M for every sequence at once:
//   S_1 = R_c^T R_b^T e_a,   S_2 = R_c^T e_b,   S_3 = e_c                    [D Eq. 4.30]
// and, with d/dt R_x(q)^T = -qdot [e_x] R_x(q)^T,
//   Sdot_1 = -q3dot e_c x S_1 - q2dot R_c^T (e_b x R_b^T e_a),  Sdot_2 = -q3dot e_c x S_2,
//   Sdot_3 = 0.
// The joint is singular where S_1, S_2, S_3 are dependent: |det S_rot| = |sin q2| for proper
// sequences (a == c) and |cos q2| for Tait-Bryan sequences (a, b, c distinct).
#include <cmath>
#include <string>

#include "core/joints/joint_kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

/// The 12 Euler sequences: 6 Tait-Bryan (all axes distinct) then 6 proper (first == last).
enum class EulerSequence { XYZ, XZY, YXZ, YZX, ZXY, ZYX, XYX, XZX, YXY, YZY, ZXZ, ZYZ };

/// the axis indices (0 = x, 1 = y, 2 = z) of a sequence, in rotation order
void eulerAxes(EulerSequence seq, int& a, int& b, int& c);
/// true for the proper sequences (XZX, ZYZ, ...), false for Tait-Bryan (XYZ, ...)
bool isProperEuler(EulerSequence seq);
/// "XYZ", "ZXZ", ...
std::string eulerSequenceName(EulerSequence seq);
/// inverse of eulerSequenceName (case-insensitive); throws JointError naming the bad input
EulerSequence parseEulerSequence(const std::string& name);

/// rotation by `angle` about coordinate axis `axis` (0 = x, 1 = y, 2 = z)
Mat3 rotationAboutAxis(int axis, double angle);

/// Spherical joint with Euler angles of any sequence [D Sec. 4.5.5]; q = (q1, q2, q3) in
/// radians, qdot = dq/dt. S and Sdot are 6 x 3 with zero translational rows.
struct SphericalEuler {
  static constexpr int kNq = 3;
  EulerSequence sequence = EulerSequence::XYZ;

  int nq() const { return 3; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
  /// Distance from gimbal lock, |det S_rot| in [0, 1]: |sin q2| (proper) or |cos q2|
  /// (Tait-Bryan). 0 means S has lost rank; integrators and solvers can report it.
  double gimbalDistance(const VecJ& q) const;
  /// same as gimbalDistance (the name every joint with coordinate singularities provides)
  double singularityDistance(const VecJ& q) const { return gimbalDistance(q); }
  /// rotation part only, 3 x 3 blocks (used by the free joints)
  void calcRotation(const Vec3& q, const Vec3& qdot, Mat3& R, Mat3& S, Mat3& Sdot) const;
};

/// Universal joint: rotation about x, then about the rotated y [D Sec. 4.5.6]; the XYZ
/// sequence with q3 = 0. R = R_x(q1) R_y(q2), S = ((c2, 0, s2), e_y) [D Eq. 4.37-4.40].
struct Universal {
  static constexpr int kNq = 2;
  int nq() const { return 2; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
    const double c2 = std::cos(q[1]), s2 = std::sin(q[1]);
    out.resize(2);
    out.Q = makeE(rotationAboutAxis(0, q[0]) * rotationAboutAxis(1, q[1]), Vec3::Zero());
    out.S.col(0).head<3>() = Vec3(c2, 0.0, s2);
    out.S(1, 1) = 1.0;
    out.Sdot.col(0).head<3>() = Vec3(-s2, 0.0, c2) * qdot[1];  // [D Eq. 4.40]
  }
};

}  // namespace redmax
