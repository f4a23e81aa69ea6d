// Core vs Simbody speed on serial chains (scenes::limbChain, 5, 10, 20, 40 DoF) and the humanoid
// (scenes::humanoid, 37 DoF), in one
// run: kinematics, mass matrix, inverse dynamics (REDMAX route and recursive), forward dynamics and
// one step of every available integrator, each next to Simbody's equivalent
// (plugin/simbody/speed_comparison.hpp says which). After the Google Benchmark output, a table of
// the ratios redmax / Simbody (CPU time per call). Single-threaded; not run by ctest.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "plugin/simbody/speed_comparison.hpp"
#include "validation/scenes/humanoid.hpp"
#include "validation/scenes/scenes.hpp"

namespace {

using redmax::simbody::SpeedComparison;

// collects real time per benchmark while the console reporter prints as usual
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.run_type != Run::RT_Iteration || r.error_occurred) continue;
      // CPU time in microseconds whatever the display unit: single-threaded ops on a shared
      // machine, where real time also counts the other jobs
      times_us[r.benchmark_name()] = r.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(r.time_unit) * 1e6;
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> times_us;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  std::vector<std::unique_ptr<SpeedComparison>> scenes;
  for (int n : {5, 10, 20, 40})
    scenes.push_back(std::make_unique<SpeedComparison>("chain" + std::to_string(n), redmax::scenes::limbChain(n)));
  scenes.push_back(std::make_unique<SpeedComparison>("humanoid", redmax::scenes::humanoid()));

  // register scene/op/side; remember the pairs for the ratio table
  struct Pair {
    std::string scene, op, redmax, simbody;
    int dof;
    const std::function<std::string()>* remark;
  };
  std::vector<Pair> pairs;
  for (auto& sc : scenes) {
    for (const std::string& why : sc->skipped())
      std::fprintf(stderr, "%s: integrator skipped: %s\n", sc->scene().c_str(), why.c_str());
    for (auto& op : sc->ops()) {
      const std::string base = sc->scene() + "/" + op.name;
      auto* f_r = &op.redmax;
      auto* f_s = &op.simbody;
      // an integrator that fails on a scene is reported, not fatal
      auto run = [](benchmark::State& st, const std::function<void()>* f) {
        for (auto _ : st) {
          try {
            (*f)();
          } catch (const std::exception& e) {
            st.SkipWithError(e.what());
            break;
          }
        }
      };
      benchmark::RegisterBenchmark((base + "/redmax").c_str(), run, f_r)->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark((base + "/simbody").c_str(), run, f_s)->Unit(benchmark::kMicrosecond);
      pairs.push_back({sc->scene(), op.name, base + "/redmax", base + "/simbody", sc->dof(), &op.remark});
    }
  }

  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();

  std::printf("\nredmax / Simbody (CPU time per call, 1 thread)\n");
  std::printf("%-10s %4s  %-18s %12s %12s %8s\n", "scene", "DoF", "operation", "redmax us", "Simbody us", "ratio");
  for (const Pair& p : pairs) {
    const auto r = reporter.times_us.find(p.redmax), s = reporter.times_us.find(p.simbody);
    if (r == reporter.times_us.end() || s == reporter.times_us.end()) continue;  // filtered out
    std::printf("%-10s %4d  %-18s %12.3f %12.3f %8.3f\n", p.scene.c_str(), p.dof, p.op.c_str(), r->second,
                s->second, r->second / s->second);
  }
  for (const Pair& p : pairs)
    if (*p.remark && reporter.times_us.count(p.redmax)) std::printf("  %s %s: %s\n", p.scene.c_str(), p.op.c_str(), (*p.remark)().c_str());
  return 0;
}
