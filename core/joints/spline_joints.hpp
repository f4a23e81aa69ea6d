#pragma once
// Spline joints of Lee and Terzopoulos [D Sec. 4.5.12, 4.5.13], uniform cubic B-splines.
#include <array>
#include <vector>

#include "core/joints/joint_kinematics.hpp"

namespace redmax {

/// Uniform cubic B-spline basis weights in cumulative form [D Eq. 4.64-4.69] on one segment,
/// u in [0, 1]: Bt[i] = sum_{j >= i} B_j(u) for i = 1..3 (Bt[0] = 1 is implied), and their first
/// and second derivatives in u.
struct CumulativeBasis {
  Vec3 Bt, dBt, ddBt;  // entries for B~_2, B~_3, B~_4
  explicit CumulativeBasis(double u);
};

/// Spline curve joint [D Sec. 4.5.12, Alg. 3], 1 coordinate.
/// Control frames C_0..C_{n-1} (n >= 4) are SE(3) poses of M in F; segment s (0 <= s <= n-4)
/// uses C_s..C_{s+3}:
///   Q(q) = C_s exp([dC_{s+1}] B~_2(u)) exp([dC_{s+2}] B~_3(u)) exp([dC_{s+3}] B~_4(u)),
///   dC_i = log(C_{i-1}^-1 C_i),  u = q - s                                   [D Eq. 4.70]
/// Parameter range: q in [0, n-3], one unit per segment (segment s covers [s, s+1]); the curve
/// is C2 across segments. Beyond the range the end segment's polynomial is EXTRAPOLATED
/// (s = 0 for q < 0, s = n-4 for q > n-3): Q, S and Sdot stay smooth and S stays nonzero, so
/// the mass matrix stays regular, but the motion leaves the control polygon; keep q in range
/// (e.g. with a coordinate limit) when that matters.
class SplineCurve {
 public:
  static constexpr int kNq = 1;
  /// throws JointError if fewer than 4 frames, a frame is not a rigid transform, or two
  /// consecutive frames differ by a rotation of pi or more (the log would be ambiguous)
  explicit SplineCurve(std::vector<Mat4> control_frames);

  int nq() const { return 1; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;

  const std::vector<Mat4>& controlFrames() const { return frames_; }
  int numSegments() const { return static_cast<int>(frames_.size()) - 3; }

 private:
  std::vector<Mat4> frames_;
  std::vector<Vec6> deltas_;  // deltas_[i] = dC_i = log(C_{i-1}^-1 C_i), deltas_[0] unused
};

/// Spline surface joint [D Sec. 4.5.13, Alg. 4], 2 coordinates, one bicubic patch.
/// Each of the six spatial coordinates (x, y, z translation, then x, y, z rotation) is the tensor
/// product f(C_k, q) = qv1^T B^T C_k B qv2 with qv = (1, q, q^2, q^3) [D Eq. 4.71-4.72], and
///   Q(q) = prod_{k=1..6} exp(e_k f(C_k, q))  (translations before rotations)  [D Eq. 4.73-4.74]
/// so the rotation part acts as body-fixed XYZ Euler angles (gimbal lock at y rotation = pi/2).
/// Parameter range q in [0, 1]^2; outside it the bicubic polynomial is extrapolated.
class SplineSurface {
 public:
  static constexpr int kNq = 2;
  /// control values: C[0..2] x, y, z translation, C[3..5] x, y, z rotation (radians); rows
  /// index the q1 control points, columns the q2 control points. Throws JointError if not finite.
  explicit SplineSurface(const std::array<Mat4, 6>& control);

  int nq() const { return 2; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
  /// f(C_k, q), its gradient (2) and Hessian (2 x 2)
  void evalCoordinate(int k, const VecJ& q, double& f, Vec2& grad, Eigen::Matrix2d& hess) const;

  const std::array<Mat4, 6>& control() const { return control_; }

 private:
  std::array<Mat4, 6> control_;
};

}  // namespace redmax
