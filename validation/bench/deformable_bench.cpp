// Time per linearly implicit step of a deformable body against its vertex count (issue 24,
// docs/deformable.md §5): a co-rotated FEM beam (4k x k x k cubes, 6 tets each, one end clamped),
// 81 to 10,388 vertices, in node space (core/deformable/node_solver.hpp: the System assembles dense
// matrices, the speed study uses this deformable-only path). Operations per step:
//   assemble   forces, exact stiffness, A = M + h D + h^2 K and the right-hand side (sparse)
//   sparse     assemble + Eigen SimplicialLDLT (AMD ordering) of A
//   cholmod    assemble + CHOLMOD's Cholesky of A (when built with SuiteSparse)
//   dense      assemble + Eigen's dense LDLT of A (up to 1,225 vertices: O(n^3))
// Second study, the coupled System (bdf1 over skeleton and nodes in one system [D Eq. 4.95]): a
// 3-link chain holding a soft block (4k x k x k cubes) by one face, one bdf1 step with the dense
// route (M, K, D over all coordinates, dense KKT) against the sparse route (System::
// calcSparseMatrices + detail::solveImplicitSparse); this sets kSparseStepFrom.
// After Google Benchmark's output: tables (CPU milliseconds per step) and the exponents fitted
// by least squares on log-log data. Not run by ctest; timing only.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/SparseCholesky>
#ifdef REDMAX_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include "core/deformable/deformable_term.hpp"
#include "core/deformable/node_solver.hpp"
#include "core/integrators/linearly_implicit_euler.hpp"
#include "validation/scenes/scenes.hpp"
#include "validation/bench/cpu_reporter.hpp"
#include "validation/bench/fit.hpp"

namespace {

using namespace redmax;

constexpr double kStep = 1e-3;

struct Scene {
  DeformableBody body;
  NodeSpaceProblem p;
  VecX x, v;
  explicit Scene(int k) {
    const TetMesh mesh = makeBoxTetMesh(Vec3(0.4, 0.1, 0.1), 4 * k, k, k);
    body = makeFemBody(mesh, 1e6, 0.3, 1000);
    body.rayleigh_mass = 0.1;
    body.rayleigh_stiffness = 1e-3;
    p.body = &body;
    p.gravity = Vec3(0, -9.81, 0);
    p.fixed.assign(mesh.numNodes(), 0);
    for (int n = 0; n < mesh.numNodes(); ++n) p.fixed[n] = mesh.nodes[n].x() < 1e-12;
    std::mt19937 rng(k);
    std::uniform_real_distribution<double> u(-1, 1);
    x = restPositions(body);
    v = VecX::Zero(x.size());
    for (int i = 0; i < x.size(); ++i)
      if (!p.fixed[i / 3]) x[i] += 1e-3 * u(rng), v[i] = 0.05 * u(rng);
  }
  int vertices() const { return body.numNodes(); }
};

using bench::fittedExponent;

// the coupled study's system: chain + block, at a deformed moving state
struct Coupled {
  System sys{scenes::revoluteChain(3)};
  State s;
  explicit Coupled(int k) {
    const TetMesh mesh = makeBoxTetMesh(Vec3(0.4, 0.1, 0.1), 4 * k, k, k, Vec3(0.0, -1.25, -0.05));
    DeformableBody fem = makeFemBody(mesh, 1e6, 0.3, 1000.0);
    fem.rayleigh_mass = 0.1;
    fem.rayleigh_stiffness = 1e-3;
    std::vector<NodeAttachment> att;
    for (int n = 0; n < mesh.numNodes(); ++n)
      if (mesh.nodes[n].x() < 1e-12) att.push_back({n, 2});
    auto term = addDeformableBody(sys, fem, att);
    s = sys.defaultState();
    term->setRestState(s);
    std::mt19937 rng(k);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < s.q.size(); ++i) {
      s.q[i] += i < 3 ? 0.5 * u(rng) : 1e-3 * u(rng);
      s.qdot[i] = i < 3 ? u(rng) : 0.05 * u(rng);
    }
    vertices = mesh.numNodes();
  }
  int vertices = 0;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  const std::vector<int> ks{2, 3, 4, 6, 8, 10, 13};
  const int dense_max_k = 6;
  std::vector<std::string> ops{"assemble", "sparse", "dense"};
#ifdef REDMAX_HAVE_CHOLMOD
  ops.insert(ops.begin() + 2, "cholmod");
#endif
  std::map<int, std::unique_ptr<Scene>> scenes;
  for (int k : ks) scenes[k] = std::make_unique<Scene>(k);
  auto key = [](int V, const std::string& op) { return "vertices" + std::to_string(V) + "/" + op; };
  for (int k : ks) {
    Scene* c = scenes[k].get();
    const int V = c->vertices();
    benchmark::RegisterBenchmark(key(V, "assemble").c_str(), [c](benchmark::State& st) {
      SparseMat A;
      VecX rhs;
      for (auto _ : st) implicitStepSystem(c->p, c->x, c->v, kStep, A, rhs);
    })->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(key(V, "sparse").c_str(), [c](benchmark::State& st) {
      SparseMat A;
      VecX rhs;
      for (auto _ : st) {
        implicitStepSystem(c->p, c->x, c->v, kStep, A, rhs);
        Eigen::SimplicialLDLT<SparseMat> ldlt(A);
        benchmark::DoNotOptimize(VecX(ldlt.solve(rhs)));
      }
    })->Unit(benchmark::kMillisecond);
#ifdef REDMAX_HAVE_CHOLMOD
    benchmark::RegisterBenchmark(key(V, "cholmod").c_str(), [c](benchmark::State& st) {
      SparseMat A;
      VecX rhs;
      for (auto _ : st) {
        implicitStepSystem(c->p, c->x, c->v, kStep, A, rhs);
        Eigen::CholmodDecomposition<SparseMat, Eigen::Lower> chol(A);
        benchmark::DoNotOptimize(VecX(chol.solve(rhs)));
      }
    })->Unit(benchmark::kMillisecond);
#endif
    if (k <= dense_max_k)
      benchmark::RegisterBenchmark(key(V, "dense").c_str(), [c](benchmark::State& st) {
        SparseMat A;
        VecX rhs;
        for (auto _ : st) {
          implicitStepSystem(c->p, c->x, c->v, kStep, A, rhs);
          benchmark::DoNotOptimize(VecX(MatX(A).ldlt().solve(rhs)));
        }
      })->Unit(benchmark::kMillisecond);
  }

  // the coupled System: dense against sparse bdf1 steps
  const std::vector<int> kc{1, 2, 3, 4, 6, 8};
  const int coupled_dense_max_k = 4;
  std::map<int, std::unique_ptr<Coupled>> coupled;
  auto ckey = [](int V, const std::string& op) { return "coupled" + std::to_string(V) + "/" + op; };
  for (int k : kc) {
    coupled[k] = std::make_unique<Coupled>(k);
    Coupled* c = coupled[k].get();
    for (const std::string op : {"dense", "sparse"}) {
      if (op == "dense" && k > coupled_dense_max_k) continue;
      benchmark::RegisterBenchmark(ckey(c->vertices, op).c_str(), [c, op](benchmark::State& st) {
        IntegratorOptions io;
        io.linear_solver = op;
        LinearlyImplicitEuler euler(io);
        DynamicsWorkspace ws(c->sys);
        for (auto _ : st) {
          State x = c->s;
          euler.step(c->sys, x, kStep, ws);
          benchmark::DoNotOptimize(x.qdot.data());
        }
      })->Unit(benchmark::kMillisecond);
    }
  }

  redmax::bench::CpuReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  std::printf("\nCPU milliseconds per implicit step, 1 thread (co-rotated FEM beam, h = %g s)\n\n| vertices |", kStep);
  for (const auto& op : ops) std::printf(" %s |", op.c_str());
  std::printf("\n|---|");
  for (size_t i = 0; i < ops.size(); ++i) std::printf("---|");
  std::printf("\n");
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> fit;
  for (int k : ks) {
    const int V = scenes[k]->vertices();
    std::printf("| %d |", V);
    for (const auto& op : ops) {
      const auto it = rep.us.find(key(V, op));
      if (it == rep.us.end()) {
        std::printf(" - |");
        continue;
      }
      std::printf(" %.3f |", it->second / 1e3);
      fit[op].first.push_back(V);
      fit[op].second.push_back(it->second);
    }
    std::printf("\n");
  }
  std::printf("| fitted exponent |");
  for (const auto& op : ops) {
    const auto& [x, y] = fit[op];
    if (x.size() >= 2) std::printf(" %.2f (%g-%g) |", fittedExponent(x, y), x.front(), x.back());
    else std::printf(" - |");
  }
  std::printf("\n");

  std::printf("\nCoupled System (3-link chain + block), CPU milliseconds per bdf1 step\n\n"
              "| vertices | coordinates | dense | sparse | dense / sparse |\n|---|---|---|---|---|\n");
  std::vector<double> xs, yd, ys, xd;
  for (int k : kc) {
    const Coupled& c = *coupled[k];
    const auto d = rep.us.find(ckey(c.vertices, "dense")), sp = rep.us.find(ckey(c.vertices, "sparse"));
    std::printf("| %d | %d |", c.vertices, c.sys.ndof());
    if (d != rep.us.end()) std::printf(" %.3f |", d->second / 1e3), xd.push_back(c.vertices), yd.push_back(d->second);
    else std::printf(" - |");
    if (sp != rep.us.end()) std::printf(" %.3f |", sp->second / 1e3), xs.push_back(c.vertices), ys.push_back(sp->second);
    else std::printf(" - |");
    if (d != rep.us.end() && sp != rep.us.end()) std::printf(" %.2f |\n", d->second / sp->second);
    else std::printf(" - |\n");
  }
  if (xd.size() >= 2 && xs.size() >= 2)
    std::printf("| fitted exponent | | %.2f | %.2f | |\n", fittedExponent(xd, yd), fittedExponent(xs, ys));
  return 0;
}
