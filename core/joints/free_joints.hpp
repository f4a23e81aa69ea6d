#pragma once
// Free joints [D Sec. 4.5.10, 4.5.11].
#include "core/joints/euler_joints.hpp"
#include "core/joints/joint_kinematics.hpp"
#include "core/joints/spherical_exp.hpp"

namespace redmax {

/// Planar free joint: translation (x, y) in the F x-y plane, then rotation theta about z
/// [D Sec. 4.5.10]. q = (x, y, theta); Q = T(x, y, 0) R_z(theta). S = [R^T e_x, R^T e_y, e_z] in
/// the translational / rotational rows as [D Eq. 4.55].
struct Free2D {
  static constexpr int kNq = 3;
  int nq() const { return 3; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
};

/// Which rotation coordinates a Free3D uses.
enum class FreeRotation {
  Exponential,  ///< exponential coordinates (SphericalExp), reparameterised near |r| = 2 pi
  Euler         ///< Euler angles of Free3D::sequence (SphericalEuler)
};
/// Order of the factors in Q.
enum class FreeOrder {
  TranslationThenRotation,  ///< Q = T(p) R: p is the origin of M in F [D Eq. 4.56-4.59]
  RotationThenTranslation   ///< Q = R T(p): p is expressed in the rotated frame [D Eq. 4.60-4.62]
};
/// Order of the coordinates in q.
enum class FreeLayout {
  TranslationFirst,  ///< q = (tx, ty, tz, r1, r2, r3)
  RotationFirst      ///< q = (r1, r2, r3, tx, ty, tz) (OpenSim/Simbody FreeJoint)
};

/// 3D free joint: a translational and a spherical joint composed [D Sec. 4.5.11], 6 coordinates.
/// With p = translation coordinates, r = rotation coordinates, R = R(r), Shat/Shatdot the
/// rotational 3 x 3 Jacobian of the rotation part:
///  T then R: S = [[0, Shat], [R^T, 0]],  Sdot = [[0, Shatdot], [-[Shat rdot] R^T, 0]]   (p, r)
///  R then T: S = [[Shat, 0], [-[p] Shat, I]],
///            Sdot = [[Shatdot, 0], [-[pdot] Shat - [p] Shatdot, 0]]                     (r, p)
/// then the columns are ordered as `layout` says.
struct Free3D {
  static constexpr int kNq = 6;
  FreeRotation rotation = FreeRotation::Exponential;
  EulerSequence sequence = EulerSequence::XYZ;  // used when rotation == Euler
  FreeOrder order = FreeOrder::TranslationThenRotation;
  FreeLayout layout = FreeLayout::TranslationFirst;

  /// OpenSim/Simbody FreeJoint with Euler angles: q = (rx, ry, rz, tx, ty, tz),
  /// X_FM = (R_XYZ body-fixed, p expressed in F).
  static Free3D opensim() {
    return Free3D{FreeRotation::Euler, EulerSequence::XYZ, FreeOrder::TranslationThenRotation,
                  FreeLayout::RotationFirst};
  }

  int nq() const { return 6; }
  void calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const;
  /// exponential rotation: the SphericalExp chart switch on r (p and its rate are unchanged:
  /// the rotation and the body twist stay the same); Euler: never
  bool reparameterize(VecJ& q, VecJ& qdot) const;
  /// the rotation part's singularityDistance (SphericalEuler or SphericalExp); translation
  /// never makes a free joint singular
  double singularityDistance(const VecJ& q) const;
  /// offsets of the rotation and translation coordinates in q
  int rotationOffset() const { return layout == FreeLayout::RotationFirst ? 0 : 3; }
  int translationOffset() const { return layout == FreeLayout::RotationFirst ? 3 : 0; }
};

}  // namespace redmax
