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
// Type III (wrapping) paths and paths with deformable node points are not handled here (MuscleTerm
// forms their compact J_ar instead).
// The result equals the mass-matrix route sum_a J_ar^T m_a (...) to round-off (same segment rule
// as calcViaPointMassPoints; tests/core/dynamics/recursive_id_test.cpp).
#include <string>
#include <vector>

#include "core/muscles/muscle_workspace.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// Buffers of one muscle's inverse-dynamics pass beyond its MuscleKinematics (sized on first use;
/// no allocation afterwards unless the active point count grows); one scratch per muscle.
struct MuscleIdScratch {
  std::vector<Vec3> dx_b, ddx_b;  // moving points: d x_b / dq_k, d2 x_b / dq_k2         (P)
  std::vector<Vec3> r_w;          // R x_b: path point from its body origin, world axes (P)
  std::vector<Vec3> xddot_w;      // path point accelerations, world                    (P)
  std::vector<Vec3> force_x;      // force on each path point, world                   (P)
  VecX lddot;                     // segment length accelerations                      (P-1)
  VecX sddot, force_s;            // Eulerian accelerations and forces (ends unused)   (P)
  VecX m0, m1, m2;                // per segment sum m, sum m beta, sum m beta^2       (P-1)
  VecX tri_c, tri_d, rhs;         // tridiagonal solve                                 (P-2)
  int alpha_sorted = -1;          // the muscle's mass points come in increasing alpha (1) or not (0);
                                  // found on the first call: a scratch serves one muscle
  // each segment's run of mass points [lo, hi) (alpha increasing) with its mass, mass-weighted
  // mean alpha c and sum m (alpha - c)^2, kept while the run stays the same: the segment's
  // moments are then O(1) per frame, m (c - s_i) and c2 + m (c - s_i)^2 (no cancellation);
  // rebuilt when the mass points' storage changes
  struct Run {
    int lo = -1, hi = -1;
    double m = 0.0, c = 0.0, c2 = 0.0;
  };
  std::vector<Run> runs;          //                                                   (P-1)
  const double* runs_of = nullptr;  // the mass points' storage the runs were found for
};

/// A body's motion in world axes, formed once per pass for all the muscles that attach to it, so
/// a path point on it costs a rotation and three cross products:
///   xdot = omega x r + nu,  xddot = alpha x r + omega x (omega x r) + bias   (r = R x_b)
struct BodyWorldMotion {
  Mat3 R;       // orientation                                      (E_wi)
  Vec3 p;       // origin
  Vec3 omega;   // angular velocity, R omega_i
  Vec3 nu;      // velocity of the point at the origin, R nu_i
  Vec3 alpha;   // angular acceleration, R omegadot_i
  Vec3 bias;    // acceleration of the point at the origin, R nudot_i + omega x nu
};
/// out[b] for every body of `motion`
void calcBodyWorldMotion(const BodyMotion& motion, std::vector<BodyWorldMotion>& out);
/// wrench[b] += the world-axes wrench w_world[b] (torque about the body origin; force) in body
/// coordinates, for every body
void addWorldWrenches(const std::vector<BodyWorldMotion>& bodies, const std::vector<Vec6>& w_world,
                      std::vector<Vec6>& wrench);

/// Why a muscle's mass points do not take the path-wise pass below (null when they do): it wraps
/// (Type III), its points follow its fibre, or its path runs through a deformable node; those
/// muscles form their compact J_ar instead (MuscleTerm), and have no written ID derivatives
/// (core/muscles/muscle_id_tangent.hpp covers the path-wise ones; the wrapping ones' are local
/// differences, core/dynamics/id_derivatives.cpp).
const char* pathwiseInverseDynamicsRefusal(const Muscle& muscle);

/// The compact route of the muscles the path-wise pass refuses (MuscleTerm, and the Type III
/// share's derivatives in core/dynamics/id_derivatives.cpp): after calcMuscleKinematics with
/// velocity, adds to fc (the muscle's k compact columns)
///   sum_a J_ar^T m_a (J_ar qddot_c (+ Jdot_ar qdot_c) (+ a_z) - g)
/// with the quadratic velocity part when `quadratic_velocity` and the fibre's own motion a_z when
/// `fibre_bias` (fibre-following points).
void addCompactMuscleIdShare(const MassPoints& mp, const MuscleKinematics& mk, const VecX& qdot_c, const VecX& qddot_c,
                             const Vec3& gravity, bool quadratic_velocity, bool fibre_bias, VecX& fc);

/// Adds the mass points' share of inverse dynamics of one Type I or II muscle (no wrap objects):
/// to w_world[b] the wrench body b must supply for them (world axes, torque about the body
/// origin; addWorldWrenches turns it into body coordinates [D Eq. 3.14]) and to tau the direct
/// generalized forces of its moving points. `bodies` from calcBodyWorldMotion at the state;
/// gravity g (world). mk is scratch (path-stage fields are overwritten; J_xr, J_ar and the other
/// Jacobians are not touched). Throws MuscleError for a degenerate path, as calcMuscleKinematics does.
void addMuscleInverseDynamics(const Model& model, const State& state, const VecX& qddot,
                              const std::vector<BodyWorldMotion>& bodies, const Vec3& gravity,
                              const Muscle& muscle, MuscleKinematics& mk, MuscleIdScratch& sc,
                              std::vector<Vec6>& w_world, VecX& tau);

}  // namespace redmax
