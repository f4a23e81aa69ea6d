// redmax's hard contact beside MuJoCo's soft contact on the same scenes (issue 21, docs/contact.md
// §6.4a): ball-drop, block-slide and box-stack of validation/scenes/contact_scenes.hpp, built in
// MuJoCo by validation/peers/mujoco_scenes.hpp with the same masses, sizes, drop height, initial
// speed, friction 0.5, step 1 ms and gravity 9.81.
//   redmax/<scene>     the scene's own function (bdf1 with the contact QP), whole run
//   mujoco/<scene>     MuJoCo's defaults (solref 0.02 1, solimp 0.9 0.95 0.001, pyramidal cone,
//                      Newton solver, semi-implicit Euler), whole run, model loaded once
//   mujoco/<scene>/elliptic   the same with the elliptic friction cone
//   mujoco/ball-drop/bouncy   solref in the direct format (-stiffness, -damping), the damping of a
//                      linear spring-damper with restitution 0.5 (MuJoCo has no restitution)
// Each iteration runs a whole scene; the tables after Google Benchmark's output give CPU
// microseconds per step (iteration time / steps) and the ratio redmax / MuJoCo, then the physical
// results side by side. Not run by ctest; tests/validation/mujoco_contact_test.cpp asserts the
// physics, nothing here is asserted.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "validation/bench/cpu_reporter.hpp"
#include "validation/peers/mujoco_scenes.hpp"
#include "validation/scenes/contact_scenes.hpp"

namespace {

using namespace redmax;
using peers::MjContactParams;

constexpr double kG = 9.81;

MjContactParams elliptic() {
  MjContactParams p;
  p.elliptic_cone = true;
  return p;
}

struct Case {
  std::string name;
  long steps;
  std::function<void()> run;
};

// the largest |a(t) - b(t)| over the samples both records share (same step, same times)
double maxDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0;
  for (size_t k = 0; k < std::min(a.size(), b.size()); ++k) d = std::max(d, std::abs(a[k] - b[k]));
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  const scenes::BallDropOptions bo;
  const scenes::BlockSlideOptions so;
  const scenes::BoxStackOptions xo;
  const long nb = std::lround(bo.duration / bo.dt), ns = std::lround(so.duration / so.dt),
             nx = std::lround(xo.duration / xo.dt);
  // models loaded once (mj_loadXML compiles; not part of a step)
  peers::MujocoModel mb(peers::ballDropMjcf(bo, {})), mbb(peers::ballDropMjcf(bo, peers::bouncyContact(bo.restitution))),
      ms(peers::blockSlideMjcf(so, {})), mse(peers::blockSlideMjcf(so, elliptic())), mx(peers::boxStackMjcf(xo, {})),
      mxe(peers::boxStackMjcf(xo, elliptic()));

  std::vector<Case> cases = {
      {"redmax/ball-drop", nb, [&] { benchmark::DoNotOptimize(scenes::runBallDrop(bo)); }},
      {"mujoco/ball-drop", nb, [&] { benchmark::DoNotOptimize(peers::runBallDrop(mb, bo)); }},
      {"mujoco/ball-drop/bouncy", nb, [&] { benchmark::DoNotOptimize(peers::runBallDrop(mbb, bo)); }},
      {"redmax/block-slide", ns, [&] { benchmark::DoNotOptimize(scenes::runBlockSlide(so)); }},
      {"mujoco/block-slide", ns, [&] { benchmark::DoNotOptimize(peers::runBlockSlide(ms, so)); }},
      {"mujoco/block-slide/elliptic", ns, [&] { benchmark::DoNotOptimize(peers::runBlockSlide(mse, so)); }},
      {"redmax/box-stack", nx, [&] { benchmark::DoNotOptimize(scenes::runBoxStack(xo)); }},
      {"mujoco/box-stack", nx, [&] { benchmark::DoNotOptimize(peers::runBoxStack(mx, xo)); }},
      {"mujoco/box-stack/elliptic", nx, [&] { benchmark::DoNotOptimize(peers::runBoxStack(mxe, xo)); }},
  };
  for (const Case& c : cases) {
    auto run = c.run;
    benchmark::RegisterBenchmark(c.name.c_str(), [run](benchmark::State& st) {
      for (auto _ : st) run();
    })->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  redmax::bench::CpuReporter rep;
  benchmark::RunSpecifiedBenchmarks(&rep);

  // ---- time per step
  auto us = [&](const std::string& name, long steps) {
    auto it = rep.us.find(name);
    return it == rep.us.end() ? 0.0 : it->second / double(steps);
  };
  std::printf("\nMuJoCo %s beside redmax, CPU microseconds per step (whole run / steps, h = 1 ms)\n\n",
              peers::mujocoVersion().c_str());
  std::printf("| scene | steps | redmax bdf1 | MuJoCo default | ratio | MuJoCo variant | ratio |\n|---|---|---|---|---|---|---|\n");
  struct Row {
    const char* scene;
    long steps;
    const char* variant;
  };
  for (const Row& r : {Row{"ball-drop", nb, "bouncy"}, Row{"block-slide", ns, "elliptic"}, Row{"box-stack", nx, "elliptic"}}) {
    const std::string s = r.scene;
    const double a = us("redmax/" + s, r.steps), b = us("mujoco/" + s, r.steps),
                 c = us("mujoco/" + s + "/" + r.variant, r.steps);
    if (a <= 0.0 || b <= 0.0 || c <= 0.0) continue;  // filtered out
    std::printf("| %s | %ld | %.2f | %.2f | %.1f | %.2f (%s) | %.1f |\n", r.scene, r.steps, a, b, a / b, c, r.variant,
                a / c);
  }

  // ---- physics side by side (one run each)
  const scenes::BallDropResult rb = scenes::runBallDrop(bo);
  const peers::MjBallDropResult jb = peers::runBallDrop(mb, bo), jbb = peers::runBallDrop(mbb, bo);
  std::vector<double> rt, rh, rv;
  for (const VecX& row : rb.run.rows) rt.push_back(row[0]), rh.push_back(row[2] - bo.radius), rv.push_back(row[8]);
  const double r_impact = peers::firstImpactTime(rt, rv, kG);
  double r_pen = 0.0;
  for (double h : rh) r_pen = std::max(r_pen, -h);
  auto apexes = [](const std::vector<double>& a) {
    std::string s;
    for (size_t k = 0; k < a.size() && k < 3; ++k) s += (k ? ", " : "") + std::to_string(a[k]);
    return s.empty() ? std::string("none") : s;
  };
  std::printf("\nball-drop: r %g m from %g m, redmax e %g; first impact against sqrt(2h/g) = %.5f s\n\n",
              bo.radius, bo.drop_height, bo.restitution, std::sqrt(2 * bo.drop_height / kG));
  std::printf("| | first impact (s) | apexes (m) | rest height (m) | penetration at rest (m) | largest penetration (m) | max |height - redmax's| (m) |\n"
              "|---|---|---|---|---|---|---|\n");
  std::printf("| redmax (e %g) | %.3f | %s | %.9f | %.2e | %.2e | - |\n", bo.restitution, r_impact,
              apexes(rb.apexes).c_str(), rb.rest_height, std::max(0.0, bo.radius - rb.rest_height), r_pen);
  std::printf("| MuJoCo default | %.3f | %s | %.9f | %.2e | %.2e | %.3g |\n", jb.first_impact, apexes(jb.apexes).c_str(),
              jb.rest_height, bo.radius - jb.rest_height, jb.max_penetration, maxDiff(rh, jb.height.y));
  std::printf("| MuJoCo bouncy (solref %s) | %.3f | %s | %.9f | %.2e | %.2e | %.3g |\n",
              peers::bouncyContact(bo.restitution).solref.c_str(), jbb.first_impact, apexes(jbb.apexes).c_str(), jbb.rest_height,
              bo.radius - jbb.rest_height, jbb.max_penetration, maxDiff(rh, jbb.height.y));
  // free fall alone: the samples before either side's first impact
  const size_t ff = static_cast<size_t>(std::lround(std::min(r_impact, jb.first_impact) / bo.dt)) - 1;
  std::printf("free fall before the first impact (%zu steps): max |height difference| %.3g m\n", ff,
              maxDiff(std::vector<double>(rh.begin(), rh.begin() + ff), jb.height.y));

  const scenes::BlockSlideResult rs = scenes::runBlockSlide(so);
  const peers::MjBlockSlideResult js = peers::runBlockSlide(ms, so), jse = peers::runBlockSlide(mse, so);
  std::vector<double> rx;
  for (const VecX& row : rs.run.rows) rx.push_back(row[1]);
  const double dclosed = so.v0 * so.v0 / (2 * so.friction * kG);
  std::printf("\nblock-slide: v0 %g m/s, mu %g; v0^2/(2 mu g) = %.6f m, v0/(mu g) = %.5f s\n\n", so.v0, so.friction,
              dclosed, so.v0 / (so.friction * kG));
  std::printf("| | distance (m) | vs closed form | stopped at (s) | speed at %g s (m/s) | largest penetration (m) | max |x - redmax's| (m) |\n"
              "|---|---|---|---|---|---|---|\n", so.duration);
  std::printf("| redmax | %.6f | %+.2f %% | %.3f | %.2e | - | - |\n", rs.distance, 100 * (rs.distance / dclosed - 1),
              rs.stop_time, rs.final_speed);
  for (const auto& [label, j] : {std::pair<const char*, const peers::MjBlockSlideResult*>{"MuJoCo pyramidal", &js},
                                 {"MuJoCo elliptic", &jse}})
    std::printf("| %s | %.6f | %+.2f %% | %.3f | %.2e | %.2e | %.3g |\n", label, j->distance,
                100 * (j->distance / dclosed - 1), j->stop_time, j->final_speed, j->max_penetration, maxDiff(rx, j->x.y));

  const scenes::BoxStackResult rx3 = scenes::runBoxStack(xo);
  const peers::MjBoxStackResult jx = peers::runBoxStack(mx, xo), jxe = peers::runBoxStack(mxe, xo);
  std::printf("\nbox-stack: %d boxes of %g m, mu %g, %g s; drift over the last second\n\n", xo.boxes, 2 * xo.half,
              xo.friction, xo.duration);
  std::printf("| | drift (m/s) | penetration at the end (m) | largest speed at the end |\n|---|---|---|---|\n");
  std::printf("| redmax | %.2e | %.2e | %.2e |\n", rx3.drift_per_second, rx3.max_penetration, rx3.final_max_speed);
  std::printf("| MuJoCo pyramidal | %.2e | %.2e | %.2e |\n", jx.drift_per_second, jx.max_penetration, jx.final_max_speed);
  std::printf("| MuJoCo elliptic | %.2e | %.2e | %.2e |\n", jxe.drift_per_second, jxe.max_penetration, jxe.final_max_speed);
  benchmark::Shutdown();
  return 0;
}
