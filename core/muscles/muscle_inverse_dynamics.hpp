#pragma once
// The mass points' share of inverse dynamics without forming J_ar, Jdot_ar or M (docs/performance.md
// §6). Inverse dynamics needs tau = M qddot - f, and the mass points' part of it [D Eq. 5.7] is
//   tau_muscle = sum_a J_ar^T m_a (J_ar qddot + Jdot_ar qdot - g) = sum_a J_ar^T m_a (xddot_a - g),
// a force m_a (xddot_a - g) on every mass point mapped back through the chain
// J_ar = J_az J_zr, J_zr = (I; J_sx) J_xr, J_xr = J_xm J_mr [D Eq. 5.4, 5.15, 5.36]:
//   1. forward, path-wise: path point accelerations from the body motion (pose, twist phi and its
//      rate phidot, what recursive inverse dynamics has at hand) [D Eq. 5.8, 5.11]
//        xddot_w = R (Gamma(x_b) phidot + omega x (Gamma(x_b) phi) + 2 omega x x_b' qdot_k
//                     + x_b'' qdot_k^2 + x_b' qddot_k)                  (moving points: x_b(q_k));
//      segment length accelerations and the internal Eulerian accelerations
//        sddot = J_sx xddot + Jdot_sx xdot
//              = -L^-1 (DeltaS lddot + Ldot sdot + DeltaSdot ldot)       [D Eq. 5.23-5.24]
//      by one tridiagonal solve (L is tridiagonal; J_sx itself is never formed);
//   2. per segment (i, i+1): with beta = (s_a - s_i) / Delta s, betadot and betaddot are affine in
//      beta, so the mass points' accelerations are xddot_a = c0 + c1 beta (c0, c1 shared by the
//      segment's points), and the segment's points add up through three moments
//      sum m_a, sum m_a beta_a, sum m_a beta_a^2:
//        Fs0 = sum m_a (xddot_a - g),  Fs1 = sum m_a beta_a (xddot_a - g),
//      giving the path points the forces J_az^T: (Fs0 - Fs1, Fs1) on x_i, x_{i+1} and
//      -F . (Fs0 - Fs1), -F . Fs1 on s_i, s_{i+1}  (F = Delta x / Delta s) [D Eq. 5.34];
//   3. backward: the Eulerian forces onto the path points, J_sx^T g_s = -DeltaXbar^T DeltaS^T
//      L^-T g_s (a second tridiagonal solve), then each path point's force G onto its body as the
//      wrench Gamma(x_b)^T R^T G (body coordinates) and, for a moving point, (R x_b') . G onto its
//      coordinate. The bodies' wrenches go through the skeleton's backward pass (J_mr^T).
// Work per muscle: O(P) path points plus a few flops per mass point, independent of the number of
// coordinates the muscle spans; Types I (P = 2: s = (0, 1) fixed, beta = alpha) and II alike.
// Type III (wrapping) paths are not handled here (MuscleTerm forms their compact J_ar instead).
// The result equals the mass-matrix route sum_a J_ar^T m_a (...) to round-off (same segment rule
// as calcViaPointMassPoints; tests/core/dynamics/recursive_id_test.cpp).
#include <string>
#include <vector>

#include "core/muscles/muscle_workspace.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// Buffers of one muscle's inverse-dynamics pass beyond its MuscleKinematics (sized on first use;
/// no allocation afterwards unless the active point count grows).
struct MuscleIdScratch {
  std::vector<Vec3> dx_b, ddx_b;  // moving points: d x_b / dq_k, d2 x_b / dq_k2         (P)
  std::vector<Vec3> xddot_w;      // path point accelerations, world                    (P)
  std::vector<Vec3> force_x;      // force on each path point, world                   (P)
  VecX lddot;                     // segment length accelerations                      (P-1)
  VecX sddot, force_s;            // Eulerian accelerations and forces (ends unused)   (P)
  VecX m0, m1, m2;                // per segment sum m, sum m beta, sum m beta^2       (P-1)
  VecX tri_c, tri_d, rhs;         // tridiagonal solve                                 (P-2)
};

/// Adds the mass points' share of inverse dynamics of one Type I or II muscle (no wrap objects):
/// to wrench[b] the wrench body b must supply for them (body coordinates, [D Eq. 3.14]) and to
/// tau the direct generalized forces of its moving points. `motion` at the state (poses, twists
/// and their rates for every body); gravity g (world). mk is scratch (path-stage fields are
/// overwritten; J_xr, J_ar and the other Jacobians are not touched). Throws MuscleError for a
/// degenerate path, as calcMuscleKinematics does.
void addMuscleInverseDynamics(const Model& model, const State& state, const VecX& qddot,
                              const BodyMotion& motion, const Vec3& gravity, const Muscle& muscle,
                              MuscleKinematics& mk, MuscleIdScratch& sc, std::vector<Vec6>& wrench, VecX& tau);

}  // namespace redmax
