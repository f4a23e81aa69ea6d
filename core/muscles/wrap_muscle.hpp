#pragma once
// Type III mass points: a muscle whose path wraps over one surface [D Sec. 5.3.3, Eq. 5.38-5.57].
//
// Supported shape: origin -> (one wrap surface, on any body or the world) -> insertion, i.e. two
// path points (fixed or moving) and one PathWrap whose range covers their segment.
// wrapMassPointsUnsupportedReason() says why another shape is refused (validateMuscle throws it).
//
// Chain rule. The surface frame s moves rigidly with its body b: E_ws = E_wb E_bs (R = R_ws,
// p = p_ws). The end points in s are p1 = R^T (x_1 - p), p2 = R^T (x_2 - p) [D Eq. 5.39-5.41],
// the wrap model gives w(p1, p2, alpha) in s with Jw = (Jw1, Jw2) = dw/d(p1, p2) [D Eq. 5.38,
// 5.44], and the mass point is x_a = R w + p. With omega the body's angular velocity (world),
// J_om = R_wb J_mr(b, omega rows) and J_p = R_wb Gamma(x_bs) J_mr(b) the surface origin's point
// Jacobian (x_bs = E_bs's translation) [D Eq. 5.8-5.9]:
//   A_i   = dp_i/dq = R^T (J_xi - J_p + [x_i - p] J_om)                          (i = 1, 2)
//   J_ar  = R (Jw1 A_1 + Jw2 A_2) - [R w] J_om + J_p           J_ori, J_ins, J_base [D Eq. 5.45-5.50]
//   Jdot_ar = [omega] R Jw A + R (Jwdot A + Jw Adot) - [d(R w)/dt] J_om - [R w] Jdot_om + Jdot_p
//   Adot_i = R^T (-[omega] (J_xi - J_p + [r_i] J_om) + Jdot_xi - Jdot_p + [rdot_i] J_om + [r_i] Jdot_om)
// with r_i = x_i - p, d(R w)/dt = omega x R w + R Jw (p1dot, p2dot), Jwdot = dJw/dt along
// (p1dot, p2dot) = A qdot [D Eq. 5.51-5.57]. A world surface has J_om = J_p = 0.
//
// Wrap models (Muscle::wrap):
//   Smooth (default)  core/muscles/wrap/smooth.hpp: exact wrapped path away from the contact
//                     change, C2 blend across it; J and Jdot exact (dual numbers). The mass matrix
//                     is continuous, so the energy is conserved to integrator error.
//   Exact             the exact library (core/muscles/wrap/wrap_surface.hpp), J by central finite
//                     differences on the end points and Jdot by central differences of that J
//                     along (p1dot, p2dot) (the dissertation's route, [D Eq. 5.58]). Positions are
//                     continuous at a contact change but J jumps there, so the kinetic energy
//                     jumps: the dissertation's motivation for a smooth model.
// Columns: a wrap surface on a body that moves neither end point adds its body's coordinates to
// the muscle's compact columns (initWrapMuscleColumns; calcMuscleKinematics calls it).
#include <string>
#include <vector>

#include "core/muscles/muscle_workspace.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

/// "" when `muscle`'s path has the supported Type III shape for mass points (header) and its
/// surface fits muscle.wrap.model, else a sentence saying why not.
std::string wrapMassPointsUnsupportedReason(const Muscle& muscle);

/// Make mk's compact columns cover every coordinate that moves the path's points or its wrap
/// surfaces' bodies (re-initialising mk when they do not; no-op when they already do).
void initWrapMuscleColumns(const Model& model, const Muscle& muscle, MuscleKinematics& mk);

/// Mass points of a supported Type III muscle after calcPathPoints (mk.x_w, J_xr; with
/// mk.velocity also xdot_w, Jdot_xr): x_a (world), J_ar and (with mk.velocity) Jdot_ar in mk's
/// compact columns; segment = 0 and beta = alpha. Needs the columns of initWrapMuscleColumns and
/// the skeleton workspace of the same state. Throws MuscleError (naming the muscle) when an end
/// point lies inside the surface or the ends coincide, std::logic_error for an unsupported shape.
void calcWrapMassPoints(const Model& model, const SkeletonWorkspace& sk, const Muscle& muscle,
                        MuscleKinematics& mk);

/// The exact library's points at fractions alphas over one surface (frame s), with J = dx/d(p1, p2)
/// by central differences of step h (m; <= 0: 1e-6 times the surface size) and, when
/// `with_jdot`, Jdot by central differences of J along (p1dot, p2dot) (else zero). calcWrap runs
/// once per stencil point for all alphas (1 + 12 + 24 calls with Jdot).
void calcExactWrapPointsFd(const WrapSurface& surface, const Vec3& p1, const Vec3& p2, const Vec3& p1dot,
                           const Vec3& p2dot, const std::vector<double>& alphas, WrapMassPoints& out,
                           double h = 0.0, bool with_jdot = true);

}  // namespace redmax
