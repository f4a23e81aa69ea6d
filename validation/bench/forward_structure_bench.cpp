// Forward dynamics by the tree's structure (issue 18; core/dynamics/structured_forward.hpp)
// against Simbody, in one run. Scenes: serial chains (scenes::limbChain, 5-80 DoF) and the
// humanoid (37 DoF), bare and with inertial Type II muscles (origin, via point, insertion on a body,
// its parent and its grandparent, 1 kg each on 10 mass points; one muscle per body two levels deep,
// at most 10). Per scene, one call of:
//   redmax/auto         System::forwardDynamics, forward_route Auto (the route it took is printed)
//   redmax/dense        forward_route Dense (J_mr^T M_m J_mr + terms, dense LDLT): the old default
//   redmax/tree_sparse  forward_route TreeSparse (CRBA + terms, LTDL over the tree)
//   simbody             Simbody realize(Acceleration) after invalidating q; with muscles, the mass
//                       points are Simbody particles held on their paths by constraints
//                       (plugin/simbody/particle_muscles.hpp), the equivalent model
//   simbody/bare        with muscles only: Simbody's bare skeleton, for scale
// Before timing, each scene's accelerations are compared with the dense route (and, on the
// chains, with Simbody's: u = qdot there) and the largest difference printed. After Google
// Benchmark's output: a table of CPU microseconds and ratios redmax / Simbody. Single-threaded;
// not run by ctest.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "plugin/simbody/model_to_simbody.hpp"
#include "plugin/simbody/particle_muscles.hpp"
#include "plugin/simbody/simbody_include.hpp"
#include "validation/bench/cpu_reporter.hpp"
#include "validation/scenes/humanoid.hpp"
#include "validation/scenes/scenes.hpp"

namespace {

using namespace redmax;
namespace sb = redmax::simbody;

// one muscle per body two levels below a body (at most 10), over the body, parent, grandparent
std::vector<Muscle> makeMuscles(const Model& m) {
  std::vector<int> deep;
  for (int b = 0; b < m.nb(); ++b) {
    const int p = m.joints()[b].parent;
    if (p >= 0 && m.joints()[p].parent >= 0) deep.push_back(b);
  }
  const int nm = std::min<int>(10, static_cast<int>(deep.size()));
  std::vector<Muscle> muscles;
  for (int k = 0; k < nm; ++k) {
    const int b = deep[k * deep.size() / nm];
    const int p = m.joints()[b].parent, g = m.joints()[p].parent;
    Muscle mu;
    mu.name = "m" + std::to_string(k);
    mu.path.points = {makeFixedPoint(g, Vec3(0.04, -0.15, 0.01)), makeFixedPoint(p, Vec3(0.045, -0.1, -0.01)),
                      makeFixedPoint(b, Vec3(0.04, -0.2, 0.02))};
    MassPointOptions o;
    o.count = 10;
    o.region = MassPointOptions::Region::WholePath;
    mu.mass_points = makeMassPoints(1.0, 0.3, 0.0, o);
    muscles.push_back(mu);
  }
  return muscles;
}

struct Scene {
  std::string name;
  Model model;
  bool muscles = false;
  bool u_is_qdot = false;  // Simbody's u equals the core's qdot (revolute chains)
  std::unique_ptr<System> sys;
  std::unique_ptr<DynamicsWorkspace> ws;
  State s;
  int points = 0;
  ForwardRoute auto_route = ForwardRoute::Auto;
  // Simbody: the equivalent system (particles with muscles) and the bare skeleton
  std::unique_ptr<sb::SimbodyModel> sm, sm_bare;
  std::unique_ptr<sb::ParticleMuscles> particles;
  SimTK::State st, st_bare;

  Scene(std::string n, Model m, bool with_muscles, bool chain)
      : name(std::move(n)), model(std::move(m)), muscles(with_muscles), u_is_qdot(chain) {
    sys = std::make_unique<System>(model);
    std::vector<Muscle> mus;
    if (muscles) {
      mus = makeMuscles(model);
      for (const Muscle& mu : mus) points += mu.mass_points.size();
      sys->addTerm(std::make_shared<MuscleTerm>(model, mus));
    }
    ws = std::make_unique<DynamicsWorkspace>(*sys);
    std::mt19937 rng(model.nr() * 7919 + points);
    std::uniform_real_distribution<double> u(-0.4, 0.4);
    s = sys->defaultState();
    for (int i = 0; i < s.q.size(); ++i) s.q[i] += u(rng), s.qdot[i] = 2 * u(rng);
    sm = sb::makeSimbodyModel(model);
    if (muscles) particles = std::make_unique<sb::ParticleMuscles>(*sm, model, mus);
    st = sm->default_state;
    sb::setSimbodyState(*sm, model, s, st);
    if (particles) particles->placeParticles(st);
    if (muscles) {
      sm_bare = sb::makeSimbodyModel(model);
      st_bare = sm_bare->default_state;
      sb::setSimbodyState(*sm_bare, model, s, st_bare);
    }
  }
  VecX forward(ForwardRoute r) {
    sys->forward_route = r;
    VecX a = sys->forwardDynamics(s, *ws);
    if (r == ForwardRoute::Auto) auto_route = ws->last_route;
    return a;
  }
  static void simbodyForward(sb::SimbodyModel& m, SimTK::State& state) {
    (void)m.matter.updQ(state);  // invalidates Stage::Position and above
    m.system.realize(state, SimTK::Stage::Acceleration);
  }
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  std::vector<std::unique_ptr<Scene>> scenes;
  for (bool mus : {false, true}) {
    for (int n : {5, 10, 20, 40, 80})
      scenes.push_back(std::make_unique<Scene>("chain" + std::to_string(n), scenes::limbChain(n), mus, true));
    scenes.push_back(std::make_unique<Scene>("humanoid", scenes::humanoid(), mus, false));
  }

  // the routes agree before anything is timed
  for (auto& sc : scenes) {
    const VecX dense = sc->forward(ForwardRoute::Dense);
    const double scale = std::max(1.0, dense.lpNorm<Eigen::Infinity>());
    const double d_auto = (sc->forward(ForwardRoute::Auto) - dense).lpNorm<Eigen::Infinity>() / scale;
    const double d_tree = (sc->forward(ForwardRoute::TreeSparse) - dense).lpNorm<Eigen::Infinity>() / scale;
    double d_sb = std::nan("");
    if (sc->u_is_qdot) {
      Scene::simbodyForward(*sc->sm, sc->st);
      const SimTK::Vector& udot = sc->st.getUDot();
      VecX a(sc->model.nr());
      for (int i = 0; i < a.size(); ++i) a[i] = udot[i];
      d_sb = (a - dense).lpNorm<Eigen::Infinity>() / scale;
    }
    std::fprintf(stderr, "%s%s: auto (%s) vs dense %.1e, tree_sparse vs dense %.1e, Simbody vs dense %.1e (of max |qddot|)\n",
                 sc->name.c_str(), sc->muscles ? "/muscles" : "", forwardRouteName(sc->auto_route), d_auto, d_tree, d_sb);
  }

  std::vector<std::string> keys;
  for (auto& sc : scenes) {
    Scene* c = sc.get();
    const std::string base = c->name + (c->muscles ? "/muscles" : "/bare");
    keys.push_back(base);
    for (ForwardRoute r : {ForwardRoute::Auto, ForwardRoute::Dense, ForwardRoute::TreeSparse})
      benchmark::RegisterBenchmark((base + "/redmax/" + forwardRouteName(r)).c_str(), [c, r](benchmark::State& st) {
        c->sys->forward_route = r;
        for (auto _ : st) benchmark::DoNotOptimize(c->sys->forwardDynamics(c->s, *c->ws));
      })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark((base + "/simbody").c_str(), [c](benchmark::State& st) {
      for (auto _ : st) Scene::simbodyForward(*c->sm, c->st);
    })->Unit(benchmark::kMicrosecond);
    if (c->muscles)
      benchmark::RegisterBenchmark((base + "/simbody/bare").c_str(), [c](benchmark::State& st) {
        for (auto _ : st) Scene::simbodyForward(*c->sm_bare, c->st_bare);
      })->Unit(benchmark::kMicrosecond);
  }

  bench::CpuReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  benchmark::Shutdown();

  auto at = [&](const std::string& k) { return rep.us.count(k) ? rep.us[k] : std::nan(""); };
  std::printf("\nforward dynamics, CPU microseconds per call, 1 thread; ratio = redmax / Simbody\n\n");
  std::printf("| scene | DoF | mass points | auto route | auto | dense | tree_sparse | Simbody | auto / Simbody | "
              "dense / Simbody | Simbody bare skeleton | auto / Simbody bare |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  size_t i = 0;
  for (auto& sc : scenes) {
    const std::string& b = keys[i++];
    const double a = at(b + "/redmax/auto"), d = at(b + "/redmax/dense"), t = at(b + "/redmax/tree_sparse"),
                 s = at(b + "/simbody"), sbare = sc->muscles ? at(b + "/simbody/bare") : std::nan("");
    std::printf("| %s | %d | %d | %s | %.2f | %.2f | %.2f | %.2f | %.3f | %.3f | %.2f | %.2f |\n", sc->name.c_str(),
                sc->model.nr(), sc->points, forwardRouteName(sc->auto_route), a, d, t, s, a / s, d / s, sbare,
                a / sbare);
  }
  return 0;
}
