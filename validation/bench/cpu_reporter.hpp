#pragma once
// Console reporter that also keeps each benchmark's CPU time per iteration in microseconds (the
// fastest of its repetitions), for the ratio tables the benchmarks print after Google Benchmark's
// output (CPU time: the machine is shared, and real time would also count the other jobs).
#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

namespace redmax::bench {

class CpuReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.run_type == Run::RT_Iteration && !r.error_occurred) {
        // with --benchmark_repetitions the fastest repetition: the one least disturbed by the
        // machine's other jobs
        const double t = r.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(r.time_unit) * 1e6;
        auto [it, fresh] = us.emplace(r.benchmark_name(), t);
        if (!fresh && t < it->second) it->second = t;
      }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> us;
};

}  // namespace redmax::bench
