#pragma once
// `redmax simulate --engine simbody`: the same model, initial state and output rows as the core
// driver (validation/simulate/simulate.hpp), integrated by Simbody with one particle per muscle
// mass point (plugin/simbody/particle_simulation.hpp). The rows have the core's columns (time, q,
// qdot, kinetic, potential and total energy); the energies are Simbody's (skeleton + particles,
// gravity relative to the world origin, joint springs), which equal the core's on the same state.
//
// Integrators: rk45 -> SimTK::RungeKuttaMersonIntegrator, cvode -> SimTK::CPodesIntegrator (BDF,
// Newton); --simbody-method picks another (feldberg, rk3, verlet) and --simbody-norm Simbody's
// error norm. --rtol is Simbody's accuracy and --atol its constraint tolerance (the particles' path
// constraints, m and m/s). What Simbody cannot take (core constraints, impulses, --no-qvv, other
// integrators) is refused by simbodyEngineUnsupportedReason before anything runs.
//
// The finger (osim_models/finger.osim, FDP and FDS 0.2 kg each) is sensitive: a 1e-10 rad change of
// q0 grows to 1.6e-6 rad in 1 s, so agreeing with the core to 1e-6 there needs local errors near
// 1e-12. RungeKuttaFeldberg with the infinity norm reaches it with the fewest realizations (each
// assembles G M^-1 G^T over the 30 constraint rows): docs/simbody.md has the comparison.
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "validation/simulate/simulate.hpp"

namespace redmax::cli {

/// `redmax simulate --engine simbody` settings beyond SimulateOptions.
struct SimbodyEngineFlags {
  /// "" = from --integrator (rk45 -> merson, cvode -> cpodes); else merson, feldberg, rk3, verlet or
  /// cpodes (plugin/simbody/particle_simulation.hpp)
  std::string method;
  bool infinity_norm = false;  ///< --simbody-norm inf (default rms)
};

/// The flag names for Args.
std::vector<std::string> simbodyEngineFlagNames();

/// Reads --simbody-method and --simbody-norm; UsageError for a bad value, or when either is given
/// without --engine simbody (`engine`).
SimbodyEngineFlags parseSimbodyEngineFlags(const Args& a, const std::string& engine);

/// The --help lines for the flags.
const char* simbodyEngineFlagsUsage();

/// "" when `m` with `so` and `quadratic_velocity` can run on Simbody, else why not (a sentence).
std::string simbodyEngineUnsupportedReason(const validation::SimulationModel& m, const validation::SimulateOptions& so,
                                           bool quadratic_velocity);

/// The run on Simbody. Rows at the core driver's output times. A Simbody failure or a non-finite
/// state stops the run (failed, failure names the time); throws simbody::SimbodyBuildError,
/// ModelError or std::invalid_argument when the model cannot be built (the user's input). The
/// stats are Simbody's: steps, realizations (as rhs_evals), error-test + convergence failures.
validation::SimulationResult simulateSimbody(const validation::SimulationModel& m, const State& initial,
                                             const validation::SimulateOptions& so,
                                             const SimbodyEngineFlags& flags = {});

}  // namespace redmax::cli
