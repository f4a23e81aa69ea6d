#pragma once
// Type II musculotendons: polylines through via points, by the Eulerian-on-Lagrangian (EOL)
// construction [D Sec. 5.3.2, Eq. 5.12-5.36], for any number n >= 1 of internal points.
//
// Each active path point i = 0..n+1 carries its world position x_i (Lagrangian) and a material
// coordinate s_i (Eulerian). The origin and insertion hold s_0 = 0 and s_{n+1} = 1 fixed (material
// cannot flow past them); the internal s_i follow from "all segments share one strain",
// (s_{i+1} - s_i) / l_i = 1 / length, hence s_i = (arc length up to i) / length. We normalise s to
// [0, 1] so that a mass point's material coordinate equals its arc fraction alpha (the
// dissertation scales by a rest length instead; nothing below depends on the scale).
//
// Differentiating the equal-strain conditions l_{i-1} Delta s_i - l_i Delta s_{i-1} = 0 gives
//   L sdot = -DeltaS ldot,  ldot = DeltaXbar xdot   =>   J_sx = -L^-1 DeltaS DeltaXbar  [D Eq. 5.23]
// and d/dt of L J_sx = -DeltaS DeltaXbar gives Jdot_sx [D Eq. 5.24].
//
// A mass point at s_a in segment (i, i+1) sits at beta = (s_a - s_i) / Delta s [D Eq. 5.29]:
//   x_a = (1 - beta) x_i + beta x_{i+1}                                         [D Eq. 5.30]
//   xdot_a = J_az (xdot_i, xdot_{i+1}, sdot_i, sdot_{i+1}),
//   J_az = ((1 - beta) I, beta I, -(1 - beta) F, -beta F),  F = Delta x / Delta s   [D Eq. 5.33-5.34]
//   betadot = -((1 - beta) sdot_i + beta sdot_{i+1}) / Delta s                       [D Eq. 5.31]
//   Fdot = (Delta xdot - F Delta sdot) / Delta s.
// The dissertation prints Eq. 5.35 as -(Delta xdot + F Delta sdot) / Delta s; differentiating
// F = Delta x / Delta s gives the sign above, which the finite-difference tests confirm.
// The chain is J_ar = J_az J_zr with J_zr = (I; J_sx) J_xr [D Eq. 5.36], so
//   Jdot_ar = Jdot_az J_zr + J_az ((0; Jdot_sx) J_xr + (I; J_sx) Jdot_xr).
#include "core/muscles/muscle_workspace.hpp"

namespace redmax {

/// 3 x 8 J_az of one mass point on (xdot_i, xdot_{i+1}, sdot_i, sdot_{i+1}) [D Eq. 5.34]
Eigen::Matrix<double, 3, 8> calcJ_az(double beta, const Vec3& F);
/// its time derivative from betadot [D Eq. 5.31] and Fdot (header)
Eigen::Matrix<double, 3, 8> calcJdot_az(double beta, double betadot, const Vec3& F, const Vec3& Fdot);

/// Throws MuscleError (naming `muscle_name` and the segment) when a segment of the active path
/// (mk.l after calcPathPoints) has zero length: the Eulerian coordinates need l_i > 0.
void checkEulerianSegments(const MuscleKinematics& mk, const std::string& muscle_name);

/// Eulerian coordinates s, J_sx, J_sr (and with mk.velocity: sdot, Jdot_sx, Jdot_sr) of the active
/// path, after calcPathPoints. Needs P >= 3 and every segment longer than zero (throws MuscleError
/// naming `muscle_name` and the segment otherwise).
void calcEulerianCoordinates(MuscleKinematics& mk, const std::string& muscle_name = "");

/// Mass points of a Type II path [D Eq. 5.29-5.36]: x_a, segment, beta, J_ar (and Jdot_ar with
/// mk.velocity), after calcEulerianCoordinates.
void calcViaPointMassPoints(const MassPoints& mp, MuscleKinematics& mk);

}  // namespace redmax
