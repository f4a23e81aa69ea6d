#pragma once
// The speed map of joints whose generalized speeds are not their coordinate rates: Simbody's
// Ball and Ellipsoid mobilizers (u = w_FM, the angular velocity of M in F expressed in F) and Free
// (u = [w_FM; v_FM], both in F), which OpenSim's inverse dynamics fills with the data's
// Euler-angle rates (core/dynamics/id_engine.hpp). The core keeps qdot = dq/dt; per joint
//   u = T(q) qdot,  T = blockdiag(R, R) S  (free: 6 rows)   or  T = R S_w  (ball, ellipsoid: 3 rows)
//   udot = T qddot + Tdot qdot,  Tdot = blockdiag(R[w], R[w]) S + blockdiag(R, R) Sdot
// with R = R_FM(q), S and Sdot the joint's twist map in M [D Eq. 4.29] and w = S_w qdot. The one
// implementation of it: the core's ID engine (converter/id/core_id_engine.hpp) and the Simbody
// plugin's velocity map (plugin/simbody/model_to_simbody.hpp) both call it.
#include "core/joints/joint.hpp"

namespace redmax {

/// u = T(q) qdot of one joint (nu x nq; nu = 6 for a free joint, 3 for ball and ellipsoid, nq for
/// a Composite whose first part is such a joint, the rest identity) and, if Tdot is given, its
/// time derivative along qdot. A Reversed joint uses its inner joint's map (u keeps its meaning
/// under Simbody's Direction::Reverse). Throws IdEngineError (core/dynamics/id_engine.hpp) for any
/// other joint type (hasOpenSimSpeedMap false).
void calcOpenSimSpeedMap(const Joint& joint, const VecJ& q, const VecJ& qdot, MatJ& T, MatJ* Tdot);

/// true if calcOpenSimSpeedMap accepts the joint
bool hasOpenSimSpeedMap(const Joint& joint);

}  // namespace redmax
