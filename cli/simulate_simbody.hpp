#pragma once
// `redmax simulate --engine simbody`: the same model, initial state and output rows as the core
// driver (validation/simulate/simulate.hpp), integrated by Simbody with one particle per muscle
// mass point (plugin/simbody/particle_simulation.hpp). The rows have the core's columns (time, q,
// qdot, kinetic, potential and total energy); the energies are Simbody's (skeleton + particles,
// gravity relative to the world origin, joint springs), which equal the core's on the same state.
//
// Integrators: rk45 -> SimTK::RungeKuttaMersonIntegrator, cvode -> SimTK::CPodesIntegrator (BDF,
// Newton); --rtol is Simbody's accuracy and --atol its constraint tolerance (the particles' path
// constraints, m and m/s). What Simbody cannot take (core constraints, impulses, --no-qvv, other
// integrators) is refused by simbodyEngineUnsupportedReason before anything runs.
#include <string>

#include "validation/simulate/simulate.hpp"

namespace redmax::cli {

/// "" when `m` with `so` and `quadratic_velocity` can run on Simbody, else why not (a sentence).
std::string simbodyEngineUnsupportedReason(const validation::SimulationModel& m, const validation::SimulateOptions& so,
                                           bool quadratic_velocity);

/// The run on Simbody. Rows at the core driver's output times. A Simbody failure or a non-finite
/// state stops the run (failed, failure names the time); throws simbody::SimbodyBuildError,
/// ModelError or std::invalid_argument when the model cannot be built (the user's input). The
/// stats are Simbody's: steps, realizations (as rhs_evals), error-test + convergence failures.
validation::SimulationResult simulateSimbody(const validation::SimulationModel& m, const State& initial,
                                             const validation::SimulateOptions& so);

}  // namespace redmax::cli
