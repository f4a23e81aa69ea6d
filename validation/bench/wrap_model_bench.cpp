// Cost of the Type III smooth wrap model per mass point with J and Jdot (issue 18), in one run:
//   model/   one muscle's whole kinematics (calcMuscleKinematics with velocity, 20 mass points) on
//            the wrapping pendulum (validation/scenes/wrap_pendulums.hpp): straight (Type I), a via
//            point where the cylinder is (Type II, EOL), the cylinder with the smooth model (Type III)
//   surface/ the smooth model alone in the surface frame, 20 points on one wrapped segment of
//            each surface type: the per-point nested-dual route it replaced (smooth_reference)
//            against the shared construction over Jet numbers (calcSmoothWrapPoints)
// After the Google Benchmark output, per-point CPU times and the ratios. Not run by ctest.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/muscles/muscle_kinematics.hpp"
#include "core/muscles/muscle_workspace.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/scenes/scenes.hpp"
#include "validation/scenes/wrap_pendulums.hpp"
#include "validation/bench/cpu_reporter.hpp"

namespace {

using namespace redmax;
constexpr int kPoints = 20;

using bench::CpuReporter;

// the pendulum's muscle in three shapes: 0 straight, 1 via point at the cylinder, 2 wrapping
Muscle pendulumMuscle(int shape) {
  const scenes::WrapPendulumSpec spec;
  Muscle mu = scenes::makeWrapPendulumMuscle(spec, WrapMassOptions{});
  if (shape < 2) {
    mu.path.wraps.clear();
    mu.path.num_wraps = 0;
  }
  // a via point on link 1 just outside the cylinder at the middle joint (0, -1, 0), where the wrap bends the path
  if (shape == 1) mu.path.points.insert(mu.path.points.begin() + 1, makeFixedPoint(0, Vec3(-0.09, -1.0, 0.0), "via"));
  return mu;
}

struct ModelCase {
  Model model = scenes::doublePendulum();
  State state;
  Muscle muscle;
  std::unique_ptr<SkeletonWorkspace> sk;
  MuscleWorkspace ws;
  explicit ModelCase(int shape) : muscle(pendulumMuscle(shape)) {
    state.q = Vec2(0.3, 0.35);
    state.qdot = Vec2(1.0, -0.7);
    sk = std::make_unique<SkeletonWorkspace>(model);
    calcKinematics(model, state, *sk);
    ws = MuscleWorkspace(model, {muscle});
  }
  void run() { calcMuscleKinematics(model, state, *sk, muscle, ws.muscles[0], true); }
};

struct SurfaceCase {
  WrapSurface s;
  Vec3 p1, p2, v1 = Vec3(0.3, -0.2, 0.1), v2 = Vec3(-0.1, 0.4, 0.2);
  std::vector<double> alphas;
  SurfaceCase(WrapSurface s_, Vec3 a, Vec3 b) : s(s_), p1(a), p2(b) {
    for (int k = 0; k < kPoints; ++k) alphas.push_back((k + 0.5) / kPoints);
  }
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  const char* shapes[] = {"type1_straight", "type2_via_eol", "type3_smooth"};
  std::vector<std::unique_ptr<ModelCase>> models;
  for (int shape = 0; shape < 3; ++shape) models.push_back(std::make_unique<ModelCase>(shape));
  const double d = scenes::wrapPenetration(models[2]->model, models[2]->muscle, models[2]->state);
  std::printf("pendulum: wrap penetration %.4f m at q = (0.3, 0.35) (> 0: wrapped)\n", d);
  for (int shape = 0; shape < 3; ++shape) {
    ModelCase* mc = models[shape].get();
    benchmark::RegisterBenchmark((std::string("model/") + shapes[shape]).c_str(), [mc](benchmark::State& st) {
      for (auto _ : st) mc->run();
    })->Unit(benchmark::kMicrosecond);
  }

  // one wrapped segment per surface type (weight 1: the whole construction runs)
  std::vector<std::pair<std::string, SurfaceCase>> surfaces = {
      {"cylinder", SurfaceCase(WrapSurface::makeCylinder(0.5, 10.0), Vec3(1.5, 0.3, -0.4), Vec3(-1.4, 0.2, 0.5))},
      {"sphere", SurfaceCase(WrapSurface::makeSphere(0.5), Vec3(1.5, 0.3, -0.4), Vec3(-1.4, 0.2, 0.5))},
      {"ellipsoid", SurfaceCase(WrapSurface::makeEllipsoid(Vec3(0.7, 0.5, 0.4)), Vec3(1.5, 0.3, -0.4), Vec3(-1.4, 0.2, 0.5))},
      {"torus", SurfaceCase(WrapSurface::makeTorus(0.3, 1.2), Vec3(0.8, 0.05, 1.0), Vec3(1.1, -0.05, -1.0))}};
  for (auto& [name, sc] : surfaces) {
    const double w = calcSmoothWrapPointDerivatives(sc.s, sc.p1, sc.p2, 0.5, sc.v1, sc.v2).weight;
    std::printf("%s: blend weight %.3f\n", name.c_str(), w);
    SurfaceCase* c = &sc;
    benchmark::RegisterBenchmark(("surface/" + name + "/nested_per_point").c_str(), [c](benchmark::State& st) {
      for (auto _ : st)
        for (double a : c->alphas)
          benchmark::DoNotOptimize(smooth_reference::calcSmoothWrapPointDerivatives(c->s, c->p1, c->p2, a, c->v1, c->v2));
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("surface/" + name + "/shared_jet").c_str(), [c](benchmark::State& st) {
      WrapMassPoints out;
      for (auto _ : st) {
        calcSmoothWrapPoints(c->s, c->p1, c->p2, c->v1, c->v2, c->alphas, {}, SmoothWrapOptions{}, out);
        benchmark::DoNotOptimize(out.J.data());
      }
    })->Unit(benchmark::kMicrosecond);
  }

  CpuReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  auto at = [&](const std::string& k) { return rep.us.count(k) ? rep.us[k] : 0.0; };
  std::printf("\nCPU microseconds per mass point (%d points), 1 thread\n", kPoints);
  const double eol = at("model/type2_via_eol") / kPoints;
  for (const char* s : shapes) {
    const double t = at(std::string("model/") + s) / kPoints;
    if (t == 0.0) continue;  // filtered out
    std::printf("  model/%-16s %8.3f us/point  (%.2fx Type II EOL)\n", s, t, eol > 0 ? t / eol : 0.0);
  }
  for (auto& [name, sc] : surfaces) {
    const double a = at("surface/" + name + "/nested_per_point") / kPoints, b = at("surface/" + name + "/shared_jet") / kPoints;
    if (a == 0.0 && b == 0.0) continue;  // filtered out
    std::printf("  surface/%-10s nested per point %8.3f us, shared jet %7.3f us (%.1fx faster); shared = %.2fx Type II EOL\n",
                name.c_str(), a, b, b > 0 ? a / b : 0.0, eol > 0 ? b / eol : 0.0);
  }
  return 0;
}
