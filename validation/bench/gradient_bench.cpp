// Cost of the adjoint gradient (core/adjoint, docs/gradients.md §5) against central differences of
// whole simulations, for 4, 40 and 400 parameters: osim_models/double_pendulum_via.osim with
// 0.5 kg in via_muscle (20 mass points), 0.2 s at dt = 1 ms, euler, generalized forces on q1 and
// q2 in 2, 20 or 200 time pieces each. Counters: the time of one forward run (forward_s), of the
// forward run and the adjoint sweep (adjoint_s), of the 2P runs of central differences
// (differences_s), and their ratios (adjoint_per_forward, differences_per_adjoint); then the step
// Jacobians' two routes without muscle mass (stepJacobianRoutes) and with muscles whose parts the
// analytic route differences locally (stepJacobianRoutesWithMuscles). Not run by ctest.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <string>

#include "validation/gradient/gradient.hpp"

namespace {

using redmax::validation::GradientSetup;

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// the fastest of three: a forward run, forward + adjoint by the analytic route, and by the
// differenced route (docs/gradients.md §2.1), each kept at its minimum over calls
void timeRoutes(GradientSetup& g, const redmax::VecX& p, double& forward, double& analytic, double& differenced) {
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
  for (auto _ : st) timeRoutes(g, p, forward, analytic, differenced);
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

// The two routes where the analytic one differences parts locally (docs/gradients.md §2.1), the
// same counters: 0, tug_of_war_step.osim with its two Millard muscles excited (8 nodes) and 0.5 kg
// in one, 0.1 s at 1 ms; 1, reach_arm.osim with its six wrapping heads' physiological mass, four
// torques, 0.3 s at 10 ms; 2, the same arm with DELT1 and TRIlong excited (3 nodes each), 0.05 s
// at 0.25 ms.
void stepJacobianRoutesWithMuscles(benchmark::State& st) {
  const int c = static_cast<int>(st.range(0));
  redmax::validation::SimulationModelOptions mo;
  const std::string dir = std::string(REDMAX_SOURCE_DIR) + "/osim_models/";
  GradientSetup g = [&] {
    if (c == 0) {
      mo.explicit_masses = {{"left_muscle", 0.5}};
      mo.muscle_mass.mass_points = 8;
      st.SetLabel("tug of war, Hill-type");
      return redmax::validation::makeGradientSetup(dir + "tug_of_war_step.osim", mo, "euler", 0.1, 1e-3,
                                                   "excitations:left_muscle@5=0.8,right_muscle@3=0.7",
                                                   "point:block@0,0,0=0.05,0,0;0.1*speed");
    }
    mo.muscle_mass.source = redmax::osim::MuscleMassOptions::Source::Physiological;
    mo.muscle_mass.wrap_mass = true;
    if (c == 1) {
      st.SetLabel("reach arm, wrapping mass points");
      return redmax::validation::makeGradientSetup(
          dir + "reach_arm.osim", mo, "euler", 0.3, 1e-2,
          "torques:shoulder_flexion,shoulder_adduction,shoulder_rotation,elbow_flexion",
          "point:hand@0,-0.08,0=0.25,-0.55,0.05;0.1*speed");
    }
    st.SetLabel("reach arm, wrapping mass points and Hill-type");
    return redmax::validation::makeGradientSetup(dir + "reach_arm.osim", mo, "euler", 0.05, 2.5e-4,
                                                 "excitations:DELT1@3=0.3,TRIlong@3=0.3",
                                                 "point:hand@0,-0.08,0=0.25,-0.55,0.05");
  }();
  const redmax::VecX p = g.p0;
  double forward = 1e300, analytic = 1e300, differenced = 1e300;
  for (auto _ : st) timeRoutes(g, p, forward, analytic, differenced);
  st.counters["parameters"] = static_cast<double>(g.p0.size());
  st.counters["forward_s"] = forward;
  st.counters["analytic_per_forward"] = analytic / forward;
  st.counters["differenced_per_forward"] = differenced / forward;
}

BENCHMARK(stepJacobianRoutesWithMuscles)->Arg(0)->Arg(1)->Arg(2)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace

BENCHMARK_MAIN();
