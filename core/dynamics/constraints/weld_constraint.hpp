#pragma once
// Weld constraint on maximal coordinates: a frame F fixed in body A and a frame G fixed in body B
// coincide (OpenSim WeldConstraint, and loops closed by a WeldJoint). Six rows, all in world
// coordinates: three for the relative angular velocity, then three for the relative velocity of
// the frame origins (the point constraint of [D Eq. 4.96] at the origins), multiplied by J_mr as
// in [D Eq. 4.101, 4.105].
//
//   G = [ Jw_a - Jw_b ; Jp_a - Jp_b ],   Jw = R_i (top three rows of J_i), Jp = R_i Gamma(x) J_i
//   C = [ log(R_wF R_wG^T) ; p_F - p_G ]
// The translational rows satisfy G = dC/dq everywhere. The rotational error is a rotation vector,
// whose derivative equals the relative angular velocity only on the constraint manifold
// (R_wF = R_wG); off it the two differ at first order in |C|, which is harmless for
// stabilisation and for the (quasi-)Newton projection.
#include "core/dynamics/constraint.hpp"

namespace redmax {

class WeldConstraint final : public Constraint {
 public:
  /// body_a, body_b in [-1, nb) and different (-1 = world); E_af: frame F in body A's frame,
  /// E_bg: frame G in body B's frame (rigid transforms). Throws ModelError on bad input.
  WeldConstraint(const Model& model, int body_a, const Mat4& E_af, int body_b, const Mat4& E_bg,
                 std::string name = "weld");
  std::string name() const override { return name_; }
  int rows() const override { return 6; }
  void calcAcceleration(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<MatX> G,
                        Eigen::Ref<VecX> rhs) const override;
  /// pos_err = (log(R_wF R_wG^T); p_F - p_G), vel_err = (omega_a - omega_b; v_F - v_G), world
  void calcErrors(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> pos_err,
                  Eigen::Ref<VecX> vel_err) const override;

 private:
  std::string name_;
  int body_a_, body_b_;
  Mat4 E_af_, E_bg_;
  int nb_, nr_;
};

}  // namespace redmax
