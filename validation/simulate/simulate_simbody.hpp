#pragma once
// The Simbody simulation driver (`redmax simulate --engine simbody`): the same model, initial state
// and output rows as the core driver (validation/simulate/simulate.hpp), integrated by Simbody with one particle per muscle
// mass point (plugin/simbody/particle_simulation.hpp). The rows have the core's columns (time, q,
// qdot, kinetic, potential and total energy); the energies are Simbody's (skeleton + particles,
// gravity relative to the world origin, joint springs), which equal the core's on the same state.
//
// Integrators: rk45 -> SimTK::RungeKuttaMersonIntegrator, cvode -> SimTK::CPodesIntegrator (BDF,
// Newton); --simbody-method picks another (feldberg, rk3, verlet) and --simbody-norm Simbody's
// error norm. rtol is Simbody's accuracy and atol its constraint tolerance (the particles' path
// constraints, m and m/s). What Simbody cannot take (core constraints, impulses, hard unilateral
// constraints, --no-qvv, other integrators) is refused by simbodyEngineUnsupportedReason before
// anything runs. Of the ForceSet it applies the compliant contact forces (HuntCrossleyForce,
// SmoothSphereHalfSpaceForce) as Simbody's own force elements (plugin/simbody/contact_forces.hpp);
// the other passive forces are named as not applied by the caller (validation::PassiveForces).
//
// The finger (osim_models/finger.osim, FDP and FDS 0.2 kg each) is sensitive: a 1e-10 rad change of
// q0 grows to 1.6e-6 rad in 1 s, so agreeing with the core to 1e-6 there needs local errors near
// 1e-12. RungeKuttaFeldberg with the infinity norm reaches it with the fewest realizations (each
// assembles G M^-1 G^T over the 30 constraint rows): docs/simbody.md has the comparison.
#include <string>

#include "validation/simulate/simulate.hpp"

namespace redmax::validation {

/// Simbody's integrator settings beyond SimulateOptions (`redmax simulate --simbody-method,
/// --simbody-norm`).
struct SimbodyEngineOptions {
  /// "" = from the integrator (rk45 -> merson, cvode -> cpodes); else merson, feldberg, rk3, verlet or
  /// cpodes (plugin/simbody/particle_simulation.hpp)
  std::string method;
  bool infinity_norm = false;  ///< error norm: the largest component instead of rms
};

/// The methods SimbodyEngineOptions::method takes.
const std::vector<std::string>& simbodyMethodNames();

/// "" when `m` with `so` and `quadratic_velocity` can run on Simbody, else why not (a sentence).
std::string simbodyEngineUnsupportedReason(const SimulationModel& m, const SimulateOptions& so,
                                           bool quadratic_velocity);

/// The run on Simbody. Rows at the core driver's output times. A Simbody failure or a non-finite
/// state stops the run (failed, failure names the time); throws simbody::SimbodyBuildError,
/// ModelError or std::invalid_argument when the model cannot be built (the user's input). The
/// stats are Simbody's: steps, realizations (as rhs_evals), error-test + convergence failures.
SimulationResult simulateSimbody(const SimulationModel& m, const State& initial, const SimulateOptions& so,
                                 const SimbodyEngineOptions& engine = {});

}  // namespace redmax::validation
