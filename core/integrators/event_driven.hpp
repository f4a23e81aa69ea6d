#pragma once
// Hard joint limits for the adaptive integrators (rk45, cvode) by event location (issue 21,
// docs/contact.md §6.1): between events the system runs with each limit that holds a coordinate
// at its bound as a locked coordinate (PrescribedCoordinate::makeLocked, its multiplier the torque
// the limit applies); the run stops at the two kinds of event and changes phase:
//   - a free coordinate reaches a bound (the signed gap q - lower or upper - q crosses zero): an
//     impact, resolved at velocity level by the contact QP of the bdf1 step (solveUnilateralStep
//     with A = M, the bilateral rows kept): the coordinate leaves at -e times its approach speed
//     (e the limit's restitution), or stops when it approached slower than the options'
//     restitution_threshold; a stopped coordinate joins the locked ones;
//   - a locked coordinate's limit would pull (its torque changes sign): it is released.
// Event times are located by bisection on re-runs from the last checked state, to 1e-12 s
// relative; events are looked for every `check_interval` s of simulated time (an event that
// starts and ends between two checks, e.g. a bounce shorter than the interval, is missed).
// Contact pairs are not handled here (they need the contact points' bias accelerations at the
// acceleration level): a system with pairs is refused with the advice to use bdf1.
#include <string>

#include "core/integrators/integrator.hpp"

namespace redmax {

/// Counts of an event-driven run (added to the integrator's stats by the caller).
struct LimitEventCounts {
  long impacts = 0;      ///< limit impacts resolved
  long releases = 0;     ///< locked limits released
  long bisections = 0;   ///< re-runs spent locating events
};

/// Advance s to t_out with `method` ("rk45" or "cvode") on sys, whose unilateral constraints are
/// joint limits only, as the file header describes. Throws std::invalid_argument for contact
/// pairs, SimulationError from the runs (s left at the last state reached).
void advanceWithLimitEvents(const std::string& method, const IntegratorOptions& opt, const System& sys, State& s,
                            double t_out, double check_interval, IntegratorStats& stats, LimitEventCounts* counts = nullptr);

}  // namespace redmax
