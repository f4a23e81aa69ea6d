#pragma once
// Hard unilateral constraints (joint limits and contact pairs) for the adaptive integators (rk45,
// cvode) by event location (issue 21, docs/contact.md §6.1). Between events the system runs with
// the contacts that hold as bilateral rows (core/dynamics/unilateral/held_contacts.hpp: a normal
// row each, and per direction of the four-sided friction pyramid a sticking row or a sliding
// friction force tied to the normal force); the run stops at four kinds of event and changes mode:
//   - impact: a free contact point's gap falls below zero while it approaches: resolved at velocity
//     level by the contact QP of the bdf1 step (solveUnilateralStep with A = M and the system's own
//     bilateral rows; the held contacts join as unilateral rows, so an impact may lift them): a
//     point leaves at -e times its approach speed, or stops when it approached slower than the
//     options' restitution_threshold; stopped points are held from then on, sticking in each
//     tangent direction whose speed is zero after the impulse and sliding in the others;
//   - release: a held contact's normal force would pull (p_n < 0): it is free again;
//   - slip: a sticking direction needs more than mu p_n: it slides, against that force;
//   - stick: a sliding direction's speed reaches zero: it sticks (and slips again at once if the
//     force it then needs is outside the pyramid, possibly the other way).
// Event times are located by bisection on re-runs from the last checked state, to 1e-12 s
// relative; events are looked for every `check_interval` s of simulated time (an event that
// starts and ends between two checks, e.g. a bounce shorter than the interval, is missed).
// After a change the positions and velocities are projected onto the new held set. An impact
// slower than the restitution threshold holds every point it involves (no lift-off at velocity
// level: a body rocking between two points would otherwise impact again and again within
// microseconds); a point that should leave does so at the next check, by its normal force.
// The held set carries over to the next call when that call starts from the state this one ended
// at (EventMemory); a call from any other state starts with the points that sit on their surfaces.
#include <string>
#include <vector>

#include "core/dynamics/unilateral/held_contacts.hpp"
#include "core/integrators/integrator.hpp"

namespace redmax {

/// Counts of an event-driven run (added to the integrator's stats by the caller).
struct UnilateralEventCounts {
  long impacts = 0;      ///< contact points and limit sides in resolved impacts
  long releases = 0;     ///< held contacts released
  long slips = 0;        ///< sticking directions that began to slide
  long sticks = 0;       ///< sliding directions that stuck
  long bisections = 0;   ///< re-runs spent locating events
  double max_penetration = 0.0;  ///< largest penetration of the states reached at the checks and events (m or rad)
};

/// The held set at the end of a run and the state it belongs to (sys null: none yet).
struct EventMemory {
  const System* sys = nullptr;
  State end;
  std::vector<HeldContact> held;
};

/// Advance s to t_out with `method` ("rk45" or "cvode") on sys (which has unilateral constraints),
/// as the file header describes. Throws std::invalid_argument for contact pairs on a system with
/// extra coordinates, SimulationError from the runs or when the contact modes do not settle at
/// one instant (s left at the last state reached).
void advanceWithUnilateralEvents(const std::string& method, const IntegratorOptions& opt, const System& sys,
                                 State& s, double t_out, double check_interval, IntegratorStats& stats,
                                 UnilateralEventCounts* counts = nullptr, EventMemory* memory = nullptr);

}  // namespace redmax
