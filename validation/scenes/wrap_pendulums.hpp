#pragma once
// Wrapping double pendulums [D Fig. 1.6, 6.5; Sec. 6.2.5] for the Type III wrap models, and a group of
// them with varied origin, insertion, radius and surface rotation that all run on one trained
// network (issue 7, Results).
//
// Scene: scenes::doublePendulum (two 1 m, 1 kg rods about z, gravity -y); a cylinder of radius R
// (quadrant -x, length 0.2 m) centred on the middle joint, its axis along z turned by `tilt` about
// the link's y axis; the muscle's origin on link 1, its insertion on link 2 (frames at each link's
// joint; link 1's joint at the top, so the middle joint is at (0, -1, 0) in link 1's frame); a 1 kg
// muscle of 20 mass points (fibre share 0.5 / 0.8), gravity only, released from rest.
// osim_models/double_pendulum_wrap.osim is the spec {(-0.1, -0.6, 0), (-0.1, -0.4, 0), 0.08, 0}: its
// end points lie 5 radii from the axis, outside the committed networks' training box (3 radii),
// so it runs on the smooth fallback throughout; the group keeps its end points within the box.
#include <memory>
#include <string>
#include <vector>

#include "core/muscles/mass_points.hpp"
#include "core/skeleton/model.hpp"
#include "core/skeleton/state.hpp"

namespace redmax::scenes {

struct WrapPendulumSpec {
  Vec3 origin = Vec3(-0.1, -0.8, 0.0);     ///< on link 1, link 1's frame (m)
  Vec3 insertion = Vec3(-0.1, -0.2, 0.0);  ///< on link 2, link 2's frame (m)
  double radius = 0.08;                    ///< cylinder radius (m)
  double tilt = 0.0;                       ///< rotation of the cylinder axis about link 1's y axis (rad)
  double q1 = 0.3, q2 = 0.35;              ///< release angles (rad), at rest
};

/// The muscle of a spec (name "wrap_muscle", wrap object "joint_cylinder") with wrap model `wrap`.
Muscle makeWrapPendulumMuscle(const WrapPendulumSpec& spec, const WrapMassOptions& wrap);

/// n specs drawn with a fixed seed: origin and insertion 0.08-0.13 m on the -x side and 0.12-0.2 m
/// from the middle joint, radius 0.065-0.085 m, tilt within +-0.3 rad, q2 at release 0.3-0.5 rad.
std::vector<WrapPendulumSpec> makeWrapPendulumGroup(int n, unsigned seed);

/// One simulated pendulum: energy (links + mass points) sampled every 10 ms.
struct WrapPendulumRun {
  WrapPendulumSpec spec;
  double E0 = 0.0;               ///< J
  double max_drift = 0.0;        ///< max |E(t) - E(0)| (J)
  double max_step_change = 0.0;  ///< largest |E_k - E_{k-1}| between 10 ms samples (J)
  int contact_changes = 0;       ///< sign changes of the penetration between samples
  long steps = 0;                ///< integrator steps
  long evaluations = 0, fallbacks = 0;  ///< Neural: wrap-model evaluations and smooth fallbacks
  std::string first_fallback;    ///< Neural: why the first one fell back ("" if none)
  double wall_s = 0.0;
};

/// Simulate a spec for `duration` s with rk45 (rtol = atol = tol) under wrap model `wrap`; for
/// Neural the run's fallback counts (summed from its workspaces) land in the result.
WrapPendulumRun runWrapPendulum(const WrapPendulumSpec& spec, WrapMassOptions wrap, double duration, double tol = 1e-12);

/// The group's table, one line per pendulum (spec, drift, steps, fallbacks).
std::string formatWrapPendulumTable(const std::vector<WrapPendulumRun>& runs);

/// Penetration d (m) of the muscle's straight segment (first to last active point) into its single
/// wrap surface at state s (core/muscles/wrap/smooth.hpp): d > 0 where the exact library wraps; its
/// sign change is a contact change. std::invalid_argument unless the muscle has one wrap object.
double wrapPenetration(const Model& model, const Muscle& muscle, const State& s);

}  // namespace redmax::scenes
