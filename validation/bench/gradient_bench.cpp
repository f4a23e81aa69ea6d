// Cost of the adjoint gradient (core/adjoint, docs/gradients.md §5) against central differences of
// whole simulations, for 4, 40 and 400 parameters: osim_models/double_pendulum_via.osim with
// 0.5 kg in via_muscle (20 mass points), 0.2 s at dt = 1 ms, euler, generalized forces on q1 and
// q2 in 2, 20 or 200 time pieces each. Counters: the time of one forward run (forward_s), of the
// forward run and the adjoint sweep (adjoint_s), of the 2P runs of central differences
// (differences_s), and their ratios (adjoint_per_forward, differences_per_adjoint); then the step
// Jacobians' two routes without muscle mass (stepJacobianRoutes). Not run by ctest.
#include <benchmark/benchmark.h>

#include <chrono>
#include <string>

#include "validation/gradient/gradient.hpp"

namespace {

using redmax::validation::GradientSetup;

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void adjointAgainstDifferences(benchmark::State& st) {
  const int pieces = static_cast<int>(st.range(0));
  redmax::validation::SimulationModelOptions mo;
  mo.explicit_masses = {{"via_muscle", 0.5}};
  const std::string spec = "torques:q1@" + std::to_string(pieces) + ",q2@" + std::to_string(pieces);
  const GradientSetup g = redmax::validation::makeGradientSetup(
      std::string(REDMAX_SOURCE_DIR) + "/osim_models/double_pendulum_via.osim", mo, "euler", 0.2, 1e-3, spec,
      "point:link2@0,-1,0=0.5,-1.5,0;0.1*speed");
  redmax::VecX p = redmax::VecX::Constant(g.p0.size(), 0.3);
  double forward = 0, adjoint = 0, differences = 0;
  for (auto _ : st) {
    auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(redmax::adjoint::evaluate(g.problem, g.objective, p, false).objective);
    forward = seconds(t0);
    t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(redmax::adjoint::evaluate(g.problem, g.objective, p, true).gradient);
    adjoint = seconds(t0);
    t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(redmax::adjoint::finiteDifferenceGradient(g.problem, g.objective, p));
    differences = seconds(t0);
  }
  st.counters["parameters"] = static_cast<double>(g.p0.size());
  st.counters["forward_s"] = forward;
  st.counters["adjoint_s"] = adjoint;
  st.counters["differences_s"] = differences;
  st.counters["adjoint_per_forward"] = adjoint / forward;
  st.counters["differences_per_adjoint"] = differences / adjoint;
}

BENCHMARK(adjointAgainstDifferences)->Arg(2)->Arg(20)->Arg(200)->Iterations(1)->Unit(benchmark::kSecond);

// The step Jacobians' two routes (docs/gradients.md §2.1) on a model where both apply: the same
// pendulum without muscle mass, 1 s at 1 ms (1000 steps), torques in 2, 20 or 200 pieces on each
// coordinate; the fastest of the repetitions of each. Counters: forward_s, analytic_s and
// differenced_s (forward run + adjoint sweep by each route), their ratios to the forward run, and
// plain_differences_per_analytic: 2P forward runs (central differences of whole runs at one step)
// over the analytic adjoint.
void stepJacobianRoutes(benchmark::State& st) {
  const int pieces = static_cast<int>(st.range(0));
  const std::string spec = "torques:q1@" + std::to_string(pieces) + ",q2@" + std::to_string(pieces);
  GradientSetup g = redmax::validation::makeGradientSetup(
      std::string(REDMAX_SOURCE_DIR) + "/osim_models/double_pendulum_via.osim", {}, "euler", 1.0, 1e-3, spec,
      "point:link2@0,-1,0=0.5,-1.5,0;0.1*speed");
  redmax::VecX p = redmax::VecX::Constant(g.p0.size(), 0.3);
  double forward = 1e300, analytic = 1e300, differenced = 1e300;
  for (auto _ : st) {
    for (int rep = 0; rep < 3; ++rep) {
      auto t0 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(redmax::adjoint::evaluate(g.problem, g.objective, p, false).objective);
      forward = std::min(forward, seconds(t0));
      g.problem.step_jacobians = "analytic";
      t0 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(redmax::adjoint::evaluate(g.problem, g.objective, p, true).gradient);
      analytic = std::min(analytic, seconds(t0));
      g.problem.step_jacobians = "differences";
      t0 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(redmax::adjoint::evaluate(g.problem, g.objective, p, true).gradient);
      differenced = std::min(differenced, seconds(t0));
    }
  }
  const double P = static_cast<double>(g.p0.size());
  st.counters["parameters"] = P;
  st.counters["forward_s"] = forward;
  st.counters["analytic_s"] = analytic;
  st.counters["differenced_s"] = differenced;
  st.counters["analytic_per_forward"] = analytic / forward;
  st.counters["differenced_per_forward"] = differenced / forward;
  st.counters["plain_differences_per_analytic"] = 2.0 * P * forward / analytic;
}

BENCHMARK(stepJacobianRoutes)->Arg(2)->Arg(20)->Arg(200)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
