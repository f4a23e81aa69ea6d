#pragma once
// Fibre-following placement of mass points (beyond [D]; its Sec. 7.3 names the gap): the
// dissertation's points sit at fixed arc fractions alpha of the whole path (equal strain over
// fibre and tendons), so a long-tendon muscle's fibre mass slides as if its tendon stretched
// with it. Here, with a Hill-type model (core/muscles/hill/muscle_model.hpp), the tendon has its
// own length l_T and the points spread over the fibre only:
//   sigma_k = l_T / 2 + c_k (L - l_T)        arc length of point k from the origin,
// with L the path length and c_k = (k + 1/2) / N the point's fraction of the fibre's projection
// on the path, L - l_T = l_M cos(pennation). The tendon is split half to each end, as the
// uniform placement splits it (core/muscles/mass_points.hpp: OpenSim's one lumped tendon does not
// say where it sits, most limb muscles have tendon or aponeurosis at both ends, and the split
// keeps the fibre centred, so both placements agree when l_T / L = l_ts / (l_opt + l_ts)).
//
// The tendon length is l_T = dT_dL L + b(z) (TendonKinematics):
//   rigid tendon (no fibre-length state)      l_T = l_ts: dT_dL = 0, b' = 0
//   fibre-length state l_M (elastic tendon)   l_T = L - l_M cos(alpha(l_M)): dT_dL = 1
// so the points depend on q and on the fibre length. With the fixed-width pennation of every
// OpenSim Hill model (l_M sin(alpha) = w), P(l_M) = l_M cos(alpha) = sqrt(l_M^2 - w^2),
// P' = 1 / cos(alpha), P'' = -w^2 / P^3. Along a motion
//   d l_T/dt = dT_dL Ldot + rate,  rate = -P' v_M,  d rate/dt = -P'' v_M^2 - P' dv_M/dt,
// with v_M the fibre-length rate (the model's zdot). dv_M/dt is a central difference of the
// model's own rate along the motion (z + h zdot, L + h Ldot): the elastic-tendon models' fibre
// rate depends on l_M, L and the activation but not on Ldot, so it holds no qddot and enters as
// a velocity-product (bias) term, never the mass matrix.
//
// Kinematics (Type I and II paths; Type III keeps the uniform placement): the point is in segment
// i (S_i <= sigma < S_i + l_i, S_i the arc length to path point i), u = sigma - S_i, t_i the unit
// direction, x_a = x_i + u t_i. With T_i = (I - t t^T) (J_i+1 - J_i) / l_i (dt_i/dq) and
// sigma_q = (c + (1/2 - c) dT_dL) dL/dq:
//   J_ar  = dx_a/dq |_z   = J_i + t_i (sigma_q - dS_i/dq) + u T_i
//   Jdot_ar = d/dt J_ar   = Jdot_i + tdot_i u_q + t_i udot_q + udot T_i + u Tdot_i
//   J_aT  = dx_a/dl_T |_q = (1/2 - c) t_i                         (so dx_a/dl_M = -P' J_aT)
//   xdot_a  = J_ar qdot + v_z,         v_z = J_aT rate
//   xddot_a = J_ar qddot + Jdot_ar qdot + a_z,   a_z = (1/2 - c)(tdot_i rate + t_i rate_dot)
// The generalized force of the points becomes J_ar^T (m g - m Jdot_ar qdot - m a_z): the
// skeleton feels the fibre carrying mass along the path; the reaction along the path on the
// fibre is not fed back into the muscle's own first-order dynamics (as in [D], muscle models
// stay massless, the points move kinematically).
//
// Without states (inverse dynamics, or a System whose muscles exert no force) the fibre length
// comes from the model's equilibrium at the frame's path length and speed with its default
// activation, and the tendon is held at that length over the frame's derivatives (a rigid tendon
// of the equilibrium length: dT_dL = 0, rate = 0). Rigid-tendon models need no equilibrium.
#include <memory>
#include <string>

#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/muscle_workspace.hpp"

namespace redmax {

/// The tendon's length and its rates at one instant: l_T = dT_dL L + b(z), d l_T/dt = dT_dL Ldot
/// + rate, d(rate)/dt = rate_dot (no qddot in it).
struct TendonKinematics {
  double length = 0.0;    ///< l_T, m
  double dT_dL = 0.0;     ///< d l_T / dL at fixed states: 1 with a fibre-length state, else 0
  double rate = 0.0;      ///< the states' share of d l_T / dt (m/s): -v_M / cos(pennation)
  double rate_dot = 0.0;  ///< its time derivative along the motion (m/s^2)
};

/// The muscle's own states at one instant, for TendonKinematics: z (the model's numStates, in
/// its order) and the muscle's excitation; z null: no states (equilibrium, see the header).
struct FibreStates {
  const double* z = nullptr;
  double excitation = 0.0;
};

/// Why `mu` cannot follow its fibre with `model` ("" = it can): no model, a wrapping (Type III)
/// path, a model whose state is not a fibre length (DeGrooteFregly2016's tendon force), no mass
/// points.
std::string fibrePlacementUnsupportedReason(const Muscle& mu, const hill::MuscleModel* model);

/// Index of "fiber_length" among `model`'s states, -1 when it has none (rigid tendon).
int fiberStateIndex(const hill::MuscleModel& model);

/// Give `mu` (with N mass points) fibre-following placement with `model`: Muscle::fibre with
/// c_k = (k + 1/2) / N, and mass_points.alpha set to the points' arc fractions at pose `q`
/// (`E_wi` its body poses) with the fibre at equilibrium (so that mass taken from the bones at
/// that pose, converter/build/muscle_mass.hpp, is taken where the points are). Throws ModelError
/// with fibrePlacementUnsupportedReason when it cannot.
void setFibrePlacement(const Model& model, const VecX& q, const std::vector<Mat4>& E_wi,
                       std::shared_ptr<const hill::MuscleModel> muscle_model, Muscle& mu);

/// The tendon of fibre-following muscle `mu` (Muscle::fibre set) at path length L and speed Ldot
/// (rates only with `velocity`), from its states or, with fs.z null, its equilibrium.
TendonKinematics calcTendonKinematics(const Muscle& mu, double L, double Ldot, const FibreStates& fs,
                                      bool velocity = true);

/// The mass-point stage of a fibre-following Type I/II muscle after the path stage (mk.x_w, J_xr,
/// l, dxbar, length; velocity fields with mk.velocity): x_a, segment, beta, J_ar, J_aT and, with
/// mk.velocity, Jdot_ar, v_z, a_z (header). `c` are the points' fibre fractions. Throws MuscleError
/// (naming `muscle_name`) for a zero-length path or segment under a point.
void calcFibreMassPoints(const std::vector<double>& c, const TendonKinematics& tk, MuscleKinematics& mk,
                         const std::string& muscle_name = "");

}  // namespace redmax
