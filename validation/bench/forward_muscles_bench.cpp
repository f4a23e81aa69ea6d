// Muscle-driven forward simulation speed, as simulated seconds per wall second (the ForwardTool,
// validation/forward/forward_tool.hpp, end to end: every step's dynamics, muscles, controls):
//   arm26_standard    OpenSim's arm26 ForwardTool setup (Applications/Forward/tests), 1 s, rk45 at
//                     1e-5, read as Thelen2003Muscle_Deprecated (the standard's class)
//   arm26_thelen      the same setup with the model's own Thelen2003Muscle, rk45 and cvode
//   gait2354_<mass>   gait2354 (23 DoF, 54 Thelen2003Muscle), every muscle at excitation 0.2 (a
//                     ControlSet, validation/forward/constant_excitation.hpp) from
//                     equilibrium, 0.1 s, at 1e-4: cvode lumped and with physiological muscle mass, rk45 lumped
// Reported as the counter sim_per_wall (simulated s / wall s, higher is faster) beside steps and
// right-hand sides. OpenSim's ForwardTool beside these: opensim_side_by_side_bench (built where
// OpenSim is installed). Needs ../shared (REDMAX_SHARED_DIR); not run by ctest.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "validation/forward/constant_excitation.hpp"
#include "validation/forward/forward_tool.hpp"

namespace {

namespace fs = std::filesystem;
using redmax::validation::ForwardResult;
using redmax::validation::ForwardTool;
using redmax::validation::ForwardToolSettings;

std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }

std::string constantExcitationSetup(const std::string& model, double t1, double excitation, double tolerance) {
  const fs::path dir = fs::temp_directory_path() / ("redmax_forward_bench_" + std::to_string(::getpid()));
  return redmax::validation::writeConstantExcitationSetup(model, dir.string(), fs::path(model).stem().string(), t1,
                                                          excitation, tolerance);
}

void runTool(benchmark::State& st, const ForwardToolSettings& s) {
  std::unique_ptr<ForwardTool> tool;
  try {
    tool = std::make_unique<ForwardTool>(s);
  } catch (const std::exception& e) {
    st.SkipWithError(e.what());
    return;
  }
  const double span = tool->setup().final_time - tool->setup().initial_time;
  double wall = 0, steps = 0, rhs = 0;
  long runs = 0;
  for (auto _ : st) {
    const ForwardResult r = tool->run();
    if (r.failed) {
      st.SkipWithError(r.failure.c_str());
      return;
    }
    wall += r.wall_s;
    steps = static_cast<double>(r.stats.steps);
    rhs = static_cast<double>(r.stats.rhs_evals);
    ++runs;
  }
  st.counters["sim_per_wall"] = span * runs / wall;
  st.counters["steps"] = steps;
  st.counters["rhs"] = rhs;
}

void Arm26(benchmark::State& st, std::string muscle_class, std::string integrator) {
  const std::string dir = shared("opensim-core/Applications/Forward/tests/resources");
  ForwardToolSettings s;
  s.setup_file = dir + "/arm26_Setup_Forward.xml";
  s.muscle_class = muscle_class;
  s.integrator = integrator;
  runTool(st, s);
}

void Gait2354(benchmark::State& st, bool with_mass, std::string integrator) {
  static const std::string setup =
      constantExcitationSetup(shared("opensim-models/Models/Gait2354_Simbody/gait2354_simbody.osim"), 0.1, 0.2, 1e-4);
  ForwardToolSettings s;
  s.setup_file = setup;
  s.integrator = integrator;
  if (with_mass) s.muscle_mass.source = redmax::osim::MuscleMassOptions::Source::Physiological;
  runTool(st, s);
}

BENCHMARK_CAPTURE(Arm26, standard_deprecated_rk45, std::string("Thelen2003Muscle_Deprecated"), std::string("rk45"))
    ->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(Arm26, thelen_rk45, std::string(""), std::string("rk45"))->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(Arm26, thelen_cvode, std::string(""), std::string("cvode"))->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(Gait2354, lumped_cvode, false, std::string("cvode"))->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(Gait2354, physiological_mass_cvode, true, std::string("cvode"))
    ->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(Gait2354, lumped_rk45, false, std::string("rk45"))->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
