#pragma once
// The derivative of a Type I or II muscle's share of inverse dynamics along one direction of
// (q, qdot) at fixed qddot (docs/gradients.md §2.1), for the adjoint's analytic step Jacobians
// (core/dynamics/id_derivatives.hpp). The share is the one addMuscleInverseDynamics computes
// (muscle_inverse_dynamics.hpp: path point accelerations from the bodies' world motion, Eulerian
// accelerations by the equal-strain tridiagonal system, the mass points' forces through J_az^T and
// J_sx^T onto the path points, and onto the bodies) [D Eq. 5.8-5.36]; here every quantity is a
// forward-mode dual number (value, derivative along the direction), seeded by the bodies' world
// motion and its derivative. The path-wise pass is written again over duals, plainly (each mass
// point on its own, a Thomas solve), not the optimized double pass: one definition of the
// mathematics, two evaluations; the test checks that both give the same values.
//
// Moving points enter through their functions' value, first and second derivative; the third,
// needed for the derivative of the second along q, is a fourth-order central difference of the
// second (function-local, as the joints' second derivative of S). Conditional points keep the
// activity of the state (the derivative of the piecewise path away from its switches).
#include <vector>

#include "core/geometry/dual.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/muscles/muscle_inverse_dynamics.hpp"
#include "core/skeleton/state.hpp"

namespace redmax {

/// The derivative of a body's world motion (BodyWorldMotion) along one direction: dR = [dtheta] R.
struct BodyWorldTangent {
  Vec3 dtheta = Vec3::Zero(), dp = Vec3::Zero(), domega = Vec3::Zero(), dnu = Vec3::Zero();
  Vec3 dalpha = Vec3::Zero(), dbias = Vec3::Zero();
};

/// Buffers of addMuscleIdShareTangent, kept between calls (sized on use; one per caller).
struct MuscleIdTangentScratch {
  using D = detail::Dual<double>;
  using V = detail::V3<D>;
  std::vector<int> active;
  std::vector<V> x, xd, xdd, r, dxw, u, fx;
  std::vector<D> l, ld, ldd, sv, sd, sdd, sub, diag, super, rhs, m0, m1, m2, fs, c, d;
};

/// Adds one Type I or II muscle's share of inverse dynamics to wrench[b] (body coordinates, the
/// wrench body b must supply) and tau (its moving points' coordinates), and, with `tangents`, the
/// derivative of both along the direction (dq, dqdot) to dwrench and dtau. `bodies` is the bodies'
/// world motion at (s, qddot) (calcBodyWorldMotion), `tangents` its derivative (null: the value
/// only). Throws MuscleError for a degenerate path, std::logic_error for a Type III muscle or a
/// deformable node point.
void addMuscleIdShareTangent(const Muscle& muscle, const State& s, const VecX& qddot, const VecX& dq,
                             const VecX& dqdot, const std::vector<BodyWorldMotion>& bodies,
                             const std::vector<BodyWorldTangent>* tangents, const Vec3& gravity,
                             std::vector<Vec6>& wrench, VecX& tau, std::vector<Vec6>* dwrench, VecX* dtau,
                             MuscleIdTangentScratch& scratch);

}  // namespace redmax
