// Cost per frame against DoF and mass points (issue 18), in one run: serial chains
// (scenes::limbChain, 5-80 DoF) carrying Type II muscles (origin, via point, insertion on three
// consecutive links, so each spans two hinges) with 0-5000 mass points in all. Operations:
//   id_recursive   System::inverseDynamicsRecursive (Newton-Euler, path-wise muscle pass)
//   id_mass        System::inverseDynamics (tau = M qddot - f: J_mr, M, muscle J_ar)
//   forward        System::forwardDynamics (Auto route, docs/performance.md §10: ABA without
//                  muscles, LTDL with them from 16 DoF; the dense LDLT before §9)
// After the Google Benchmark output: the tables (CPU microseconds per call) and exponents fitted
// by least squares on log-log data (DoF at 0 points; points at 20 DoF over 500-5000 points).
// Not run by ctest; timing only.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "validation/scenes/humanoid.hpp"
#include "validation/bench/cpu_reporter.hpp"
#include "validation/bench/fit.hpp"

namespace {

using namespace redmax;

using bench::CpuReporter;

// n links; `points` mass points spread over min(10, n - 2) Type II muscles of 1 kg (0: no muscle)
struct Scene {
  std::unique_ptr<System> sys;
  std::unique_ptr<DynamicsWorkspace> ws;
  State s;
  VecX qddot, tau;
  Scene(int n, int points) {
    const Model m = scenes::limbChain(n);
    sys = std::make_unique<System>(m);
    if (points > 0) {
      const int nm = std::min(10, n - 2);
      std::vector<Muscle> muscles;
      for (int k = 0; k < nm; ++k) {
        const int b = k * (n - 2) / nm;  // links b, b+1, b+2 (each 0.3 m along -y)
        Muscle mu;
        mu.name = "m" + std::to_string(k);
        mu.path.points = {makeFixedPoint(b, Vec3(0.04, -0.15, 0.01)), makeFixedPoint(b + 1, Vec3(0.045, -0.1, -0.01)),
                          makeFixedPoint(b + 2, Vec3(0.04, -0.2, 0.02))};
        MassPointOptions o;
        o.count = points / nm + (k < points % nm ? 1 : 0);
        o.region = MassPointOptions::Region::WholePath;
        mu.mass_points = makeMassPoints(1.0, 0.3, 0.0, o);
        muscles.push_back(mu);
      }
      sys->addTerm(std::make_shared<MuscleTerm>(m, muscles));
    }
    ws = std::make_unique<DynamicsWorkspace>(*sys);
    std::mt19937 rng(n * 7919 + points);
    std::uniform_real_distribution<double> u(-0.4, 0.4);
    s = sys->defaultState();
    qddot.resize(s.q.size());
    for (int i = 0; i < s.q.size(); ++i) s.q[i] = u(rng), s.qdot[i] = 2 * u(rng), qddot[i] = 10 * u(rng);
  }
};

// least-squares slope of log(y) against log(x)
using bench::fittedExponent;

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  const std::vector<int> dofs{5, 10, 20, 40, 80}, points{0, 50, 500, 5000};
  const char* ops[] = {"id_recursive", "id_mass", "forward"};
  std::vector<std::pair<std::string, std::unique_ptr<Scene>>> scenes_;
  auto add = [&](int n, int p) {
    const std::string key = "chain" + std::to_string(n) + "/points" + std::to_string(p);
    for (auto& [k, sc] : scenes_)
      if (k == key) return;
    scenes_.emplace_back(key, std::make_unique<Scene>(n, p));
  };
  for (int n : dofs) add(n, 0);
  for (int p : points) add(20, p);
  add(80, 5000);
  for (auto& [key, sc] : scenes_) {
    Scene* c = sc.get();
    benchmark::RegisterBenchmark((key + "/id_recursive").c_str(), [c](benchmark::State& st) {
      for (auto _ : st) c->sys->inverseDynamicsRecursive(c->s, c->qddot, *c->ws, c->tau);
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark((key + "/id_mass").c_str(), [c](benchmark::State& st) {
      for (auto _ : st) benchmark::DoNotOptimize(c->sys->inverseDynamics(c->s, c->qddot, *c->ws));
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark((key + "/forward").c_str(), [c](benchmark::State& st) {
      for (auto _ : st) benchmark::DoNotOptimize(c->sys->forwardDynamics(c->s, *c->ws));
    })->Unit(benchmark::kMicrosecond);
  }

  CpuReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  auto at = [&](int n, int p, const char* op) {
    const std::string k = "chain" + std::to_string(n) + "/points" + std::to_string(p) + "/" + op;
    return rep.us.count(k) ? rep.us[k] : std::nan("");
  };
  std::printf("\nCPU microseconds per call, 1 thread (limbChain, Type II muscles)\n\n| DoF (0 points) |");
  for (const char* op : ops) std::printf(" %s |", op);
  std::printf("\n|---|---|---|---|\n");
  for (int n : dofs) {
    std::printf("| %d |", n);
    for (const char* op : ops) std::printf(" %.2f |", at(n, 0, op));
    std::printf("\n");
  }
  std::printf("| fitted exponent (5-80 DoF) |");
  for (const char* op : ops) {
    std::vector<double> x, y;
    for (int n : dofs) x.push_back(n), y.push_back(at(n, 0, op));
    std::printf(" %.2f |", fittedExponent(x, y));
  }
  std::printf("\n\n| mass points (20 DoF) |");
  for (const char* op : ops) std::printf(" %s |", op);
  std::printf("\n|---|---|---|---|\n");
  for (int p : points) {
    std::printf("| %d |", p);
    for (const char* op : ops) std::printf(" %.2f |", at(20, p, op));
    std::printf("\n");
  }
  std::printf("| fitted exponent (500-5000 points) |");
  for (const char* op : ops) std::printf(" %.2f |", fittedExponent({500, 5000}, {at(20, 500, op), at(20, 5000, op)}));
  std::printf("\n| ns per mass point (500 -> 5000) |");
  for (const char* op : ops) std::printf(" %.1f |", 1e3 * (at(20, 5000, op) - at(20, 500, op)) / 4500.0);
  std::printf("\n| 80 DoF, 5000 points |");
  for (const char* op : ops) std::printf(" %.2f |", at(80, 5000, op));
  std::printf("\n");
  return 0;
}
