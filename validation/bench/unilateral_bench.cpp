// Time per bdf1 step with hard unilateral constraints against the contact count (issue 21,
// docs/contact.md §6): box stacks of 1 to 16 free boxes (6 to 96 coordinates), each box's four
// bottom corners on the ground or on the box below (4 to 64 simultaneous contacts, friction 0.5,
// four coplanar contacts per box: rank deficient).
//   settled  N  one step of a stack that has settled (0.5 s simulated first)
//   falling  N  the first 200 steps after dropping the boxes 2 cm apart (impacts, contacts
//               appearing), per step
//   nocontact N the same system's bdf1 step without its unilateral constraints (the baseline:
//               what the contact QP adds)
// Counters: contacts and QP iterations (active-set changes) and QPs per step. After Google
// Benchmark's output: a table of CPU microseconds per step and the ratio to the baseline. Not
// run by ctest; timing only.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "validation/bench/cpu_reporter.hpp"
#include "validation/scenes/contact_scenes.hpp"

namespace {

using namespace redmax;

constexpr double kStep = 1e-3;
const std::vector<int> kBoxes = {1, 2, 4, 8, 16};

std::string key(int n, const char* what) { return std::string(what) + "/" + std::to_string(n); }

void settled(benchmark::State& st, int n, bool contacts) {
  scenes::BoxStackOptions o;
  o.boxes = n;
  State s;
  auto sys = scenes::makeBoxStack(o, s);
  IntegratorOptions io;
  io.dt = kStep;
  auto integ = makeIntegrator("bdf1", io);
  integ->advance(*sys, s, 0.5);  // settle
  std::shared_ptr<System> plain;
  if (!contacts) {
    plain = std::make_shared<System>(*sys);
    plain->setUnilateral(nullptr);
    integ = makeIntegrator("bdf1", io);  // fresh statistics; the boxes now fall freely
  }
  const System& run = contacts ? *sys : *plain;
  const IntegratorStats before = integ->stats();
  const State start = s;
  long steps = 0;
  for (auto _ : st) {
    integ->advance(run, s, s.t + kStep);
    ++steps;
    if (!contacts && steps % 200 == 0) s = start;  // keep the free fall short
  }
  const IntegratorStats& after = integ->stats();
  st.counters["contacts"] = double(after.contact_rows - before.contact_rows) / double(steps);
  st.counters["qp_iter"] = double(after.qp_iterations - before.qp_iterations) / double(steps);
  st.counters["qps"] = double(after.qp_solves - before.qp_solves) / double(steps);
}

void falling(benchmark::State& st, int n) {
  scenes::BoxStackOptions o;
  o.boxes = n;
  o.initial_gap = 0.02;
  State s0;
  auto sys = scenes::makeBoxStack(o, s0);
  IntegratorOptions io;
  io.dt = kStep;
  long steps = 0, qp = 0, contacts = 0, qps = 0;
  for (auto _ : st) {
    auto integ = makeIntegrator("bdf1", io);
    State s = s0;
    integ->advance(*sys, s, 200 * kStep);
    steps += integ->stats().steps;
    qp += integ->stats().qp_iterations;
    qps += integ->stats().qp_solves;
    contacts += integ->stats().contact_rows;
  }
  st.counters["contacts"] = double(contacts) / double(steps);
  st.counters["qp_iter"] = double(qp) / double(steps);
  st.counters["qps"] = double(qps) / double(steps);
  st.counters["steps_per_iter"] = 200;
}

}  // namespace

int main(int argc, char** argv) {
  for (int n : kBoxes) {
    benchmark::RegisterBenchmark(key(n, "settled").c_str(), [n](benchmark::State& st) { settled(st, n, true); })
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(key(n, "nocontact").c_str(), [n](benchmark::State& st) { settled(st, n, false); })
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(key(n, "falling").c_str(), [n](benchmark::State& st) { falling(st, n); })
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::Initialize(&argc, argv);
  redmax::bench::CpuReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  std::printf("\nCPU microseconds per bdf1 step (falling: per step of a 200-step run)\n");
  std::printf("%6s %6s %10s %10s %10s %10s %10s\n", "boxes", "dofs", "nocontact", "settled", "ratio", "falling", "ratio");
  for (int n : kBoxes) {
    auto get = [&](const char* w) {
      auto it = rep.us.find(key(n, w));
      return it == rep.us.end() ? 0.0 : it->second;
    };
    const double base = get("nocontact"), set = get("settled"), fall = get("falling") / 200.0;
    if (base <= 0.0) continue;
    std::printf("%6d %6d %10.1f %10.1f %10.2f %10.1f %10.2f\n", n, 6 * n, base, set, set / base, fall, fall / base);
  }
  benchmark::Shutdown();
  return 0;
}
