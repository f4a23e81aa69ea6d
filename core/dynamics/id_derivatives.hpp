#pragma once
// Derivatives of inverse dynamics with respect to q and qdot (docs/gradients.md §2.1):
//   tau(q, qdot, qddot) = M(q) qddot - f(q, qdot),
//   dtau/dq = dM/dq qddot - df/dq,   dtau/dqdot = -df/dqdot.
// They hold the derivatives of M and f: at qddot = 0 they are -df/dq and -df/dqdot, and
// dtau/dq(qddot) - dtau/dq(0) = (dM/dq_k qddot)_k. The adjoint uses them for the step Jacobians of
// `euler` (core/adjoint): qddot = M^-1 f, d qddot / dy = -M^-1 dtau/dy.
//
// The skeleton's derivatives are the tangent of recursive Newton-Euler inverse dynamics
// (recursiveIdForward / Backward in skeleton_dynamics.cpp) along each coordinate and speed: poses,
// twists, their rates and the wrenches carried forward, the wrenches' transmission carried back,
// analytic in the tree [D Eq. 4.5, 4.8, 3.21-3.22]. A joint enters through Q, S and Sdot:
//   dQ/dq_c = Q [S e_c],   dS/dq_c = Sdot(q, e_c)   (exact: Sdot(q, v) = sum_c dS/dq_c v_c),
//   d(Sdot qdot)/dqdot_c = Sdot(q, e_c) qdot + Sdot(q, qdot) e_c   (exact, bilinear),
//   d(Sdot qdot)/dq_c: a second derivative of S, the one entry no joint computes, taken as a
//     fourth-order central difference of the joint's own Sdot qdot (joint-local, 4 calls per
//     coordinate; relative error ~1e-12). Joints whose S is constant in M (revolute, prismatic,
//     ...) have Sdot = 0 and so an exact zero here.
// The derivative of J_mr follows from the same identity: dJ_mr/dq_c = Jdot_mr(q, e_c)
// (jacobianDerivative). Terms: the joint springs and dampers, the massless terms whose
// derivatives are written (CoordinateLimitForceTerm, SpringGeneralizedForceTerm,
// CoordinateActuatorTerm at fixed controls), and a MuscleTerm's mass points: on Type I and II paths
// analytic (core/muscles/muscle_id_tangent.hpp: the path-wise pass over dual numbers, seeded by the
// tangent of the bodies' world motion, its wrenches added to the tangent's backward pass), on
// Type III (wrapping) paths by a muscle-local fourth-order difference of the muscle's own share
// along the coordinates that move it (the wrap construction's J and Jdot have no written
// derivatives along q; the dissertation differences its network Jacobians likewise [D Eq. 5.58]).
// Hill-type muscles (MuscleForceTerm) and the force terms without written derivatives that add
// no mass and have no states (contact, bushings, point-to-point springs, point and torque
// actuators) join by central differences of the term alone at `term_step`, not of the step
// (systemIdDerivativesLocalDifferences names them). Fibre-following mass points, any other term,
// external loads, extra coordinates, a coordinate map or Simbody-compatible joint velocity terms
// make systemIdDerivatives refuse (false, with the reason), and the adjoint then differences its
// step (docs/gradients.md §2).
#include <string>

#include "core/dynamics/system.hpp"

namespace redmax {

/// dtau/dq and dtau/dqdot (nr x nr) of the bare skeleton's inverse dynamics at (s, qddot): gravity,
/// the bodies' inertia and Coriolis wrenches, joint springs and dampers.
void skeletonIdDerivatives(const Model& model, const State& s, const VecX& qddot, MatX& dtau_dq, MatX& dtau_dqdot);

/// Whether every joint's Sdot is the time derivative of its S (false for Simbody-compatible
/// function-based joints, whose Sdot is Simbody's approximation); the name of the first that is not.
bool jointsHaveExactVelocityTerms(const Model& model, std::string* offending = nullptr);

/// The system's dtau/dq and dtau/dqdot (ndof x ndof) at (s, qddot) with the workspace's controls
/// (ws.controls): the skeleton's plus each term's. False (and *why) when the system has a part
/// whose derivatives are not written (see the file comment); the matrices are then unspecified.
struct StateTermDerivatives;
bool systemIdDerivatives(const System& sys, const State& s, const VecX& qddot, const DynamicsWorkspace& ws,
                         MatX& dtau_dq, MatX& dtau_dqdot, std::string* why = nullptr, double term_step = 2e-7,
                         StateTermDerivatives* state_terms = nullptr);
/// Whether systemIdDerivatives can apply to this system (everything but the workspace's loads);
/// false with the first part that has no written derivatives.
bool systemIdDerivativesAvailable(const System& sys, std::string* why = nullptr);
/// The parts whose derivatives systemIdDerivatives takes by local differences rather than in
/// closed form, in words ("" when none): the mass points of wrapping (Type III) muscles, the
/// Hill-type muscles' forces and states, the force terms differenced alone.
std::string systemIdDerivativesLocalDifferences(const System& sys);

/// Hill-type muscles (MuscleForceTerm: f -= F_t (dl/dq)^T, zdot from each model's calc) are the
/// terms with auxiliary states z and controls u (excitations). Their Hill curves (Thelen's
/// force-velocity inverse, the activation's switch, a tendon's toe region) and Type III path
/// lengths (dl/dq is itself a difference at 1e-7) have no written derivatives, so theirs are
/// central differences of the term alone, not of the step: at each column the skeleton's
/// kinematics and the term (every muscle's path, model and rates) are evaluated twice, at the
/// relative step `step` (the adjoint passes its Problem::jacobian_step: 2e-7 for muscles that do
/// not wrap, 6e-6 with wrapping ones, docs/gradients.md §2). systemIdDerivatives adds their
/// -df/dq and -df/dqdot at `term_step`, and with `state_terms` fills it from the same
/// evaluations (the adjoint's sdirk2 stages take their df/dz, df/du so); StateTermDerivatives
/// holds the rest, at the controls ws.controls (n = ndof, nz = numStates, nu = numControls; zero
/// outside the terms' own):
struct StateTermDerivatives {
  MatX df_dz, df_du;                    ///< their generalized force        (n x nz, n x nu)
  MatX dzdot_dq, dzdot_dv;              ///< their states' rates            (nz x n)
  MatX dzdot_dz, dzdot_du;              ///<                                (nz x nz, nz x nu)
};
void stateTermDerivatives(const System& sys, const State& s, const DynamicsWorkspace& ws, double step,
                          StateTermDerivatives& out);

/// The derivatives of the constraint rows as System::calcConstraints forms them (G, the stabilized
/// rhs, vel_err). Other constraints (points, welds, prescribed points) are differenced alone: a
/// fourth-order local difference of their own G w, G^T lambda, rhs and errors along each
/// coordinate and speed (localDerivative; the skeleton's kinematics at each stencil point).
/// Written for coordinate couplers (OpenSim's CoordinateCouplerConstraint,
/// C = scale f(q_I) - q_dep): G = (scale grad f, -1) and rhs = -scale qdot_I^T Hess f qdot_I, so the
/// derivatives need f's Hessian (exact, the function's own) and, for rhs along q, its third
/// derivative (a fourth-order difference of the Hessian, function-local as the joints' second
/// derivative of S). For the KKT steps (docs/gradients.md §2.1), at a state, a vector w and the
/// multipliers lambda:
struct ConstraintRowDerivatives {
  MatX dGw_dq;              ///< d(G w)/dq                       (nc x n)
  MatX dGTl_dq;             ///< d(G^T lambda)/dq                (n x n)
  MatX drhs_dq, drhs_dv;    ///< the stabilized rhs              (nc x n)
  MatX dverr_dq, dverr_dv;  ///< the velocity error              (nc x n)
};
/// Locked and prescribed coordinates (PrescribedCoordinate: G = -e_k^T, rhs = -qddot_p(t)) have
/// constant rows; only their errors move with the state.
/// Whether the rows of every constraint of the system have derivatives here (all but those on
/// extra coordinates); false with the first that has not.
bool constraintRowDerivativesAvailable(const System& sys, std::string* why = nullptr);
void constraintRowDerivatives(const System& sys, const State& s, const VecX& w, const VecX& lambda,
                              ConstraintRowDerivatives& out);

/// dJ_mr/dq_c (nm x nr) at s.q: Jdot_mr at the speeds e_c (Jdot_mr is linear in qdot).
MatX jacobianDerivative(const Model& model, const State& s, int c);

/// dJ_mr/dq_c and dJdot_mr/dq_c (nm x nr each) at s: the tangent of calcKinematics' recursion
/// [D Alg. 2] along q_c, analytic in the tree (dAd_ip = -ad(S_i e_c) Ad_ip on the coordinate's
/// own joint, carried down its subtree); the joint's own dSdot/dq_c is a fourth-order difference of
/// its Sdot (joint-local, as in skeletonIdDerivatives). dJdot_mr/dqdot_c = dJ_mr/dq_c.
void jacobianDerivatives(const Model& model, const State& s, int c, MatX& dJ, MatX& dJdot);

}  // namespace redmax
