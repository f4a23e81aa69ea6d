#pragma once
// Console reporter that also keeps each benchmark's CPU time per iteration in microseconds, for
// the ratio tables the benchmarks print after Google Benchmark's output (CPU time: the machine is
// shared, and real time would also count the other jobs).
#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

namespace redmax::bench {

class CpuReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.run_type == Run::RT_Iteration && !r.error_occurred)
        us[r.benchmark_name()] = r.GetAdjustedCPUTime() / benchmark::GetTimeUnitMultiplier(r.time_unit) * 1e6;
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> us;
};

}  // namespace redmax::bench
