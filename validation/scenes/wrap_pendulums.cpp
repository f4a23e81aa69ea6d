#include "validation/scenes/wrap_pendulums.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <stdexcept>

#include "core/dynamics/muscle_term.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax::scenes {

Muscle makeWrapPendulumMuscle(const WrapPendulumSpec& spec, const WrapMassOptions& wrap) {
  Muscle mu;
  mu.name = "wrap_muscle";
  mu.path.points = {makeFixedPoint(0, spec.origin, "origin"), makeFixedPoint(1, spec.insertion, "insertion")};
  PathWrap w;
  w.name = "joint_cylinder";
  w.surface = WrapSurface::makeCylinder(spec.radius, 0.2, 0, -1);
  w.body = 0;
  w.E_bs = makeE(Eigen::AngleAxisd(spec.tilt, Vec3::UnitY()).toRotationMatrix(), Vec3(0, -1, 0));
  mu.path.wraps = {w};
  mu.path.num_wraps = 1;
  mu.optimal_fiber_length = 0.5;
  mu.tendon_slack_length = 0.3;
  mu.mass_points = makeMassPoints(1.0, 0.5, 0.3);
  mu.wrap = wrap;
  return mu;
}

std::vector<WrapPendulumSpec> makeWrapPendulumGroup(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto in = [&](double lo, double hi) { return lo + (hi - lo) * u(rng); };
  std::vector<WrapPendulumSpec> out(n);
  for (auto& s : out) {
    s.origin = Vec3(-in(0.08, 0.13), -1.0 + in(0.12, 0.2), 0.0);
    s.insertion = Vec3(-in(0.08, 0.13), -in(0.12, 0.2), 0.0);
    s.radius = in(0.065, 0.085);
    s.tilt = in(-0.3, 0.3);
    s.q1 = 0.3;
    s.q2 = in(0.3, 0.5);
  }
  return out;
}

double wrapPenetration(const Model& model, const Muscle& muscle, const State& s) {
  if (muscle.path.wraps.size() != 1)
    throw std::invalid_argument("wrapPenetration: muscle '" + muscle.name + "' does not have one wrap surface");
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  MuscleKinematics mk;
  initMuscleKinematics(model, muscle.path, mk);
  calcPathPoints(model, s, sk, muscle.path, mk, false);
  const PathWrap& w = muscle.path.wraps[0];
  const Mat4 E_sw = inverseE(w.body >= 0 ? Mat4(sk.E_wi[w.body] * w.E_bs) : w.E_bs);
  return calcWrapPenetration(w.surface, transformPoint(E_sw, mk.x_w.front()), transformPoint(E_sw, mk.x_w.back()));
}

WrapPendulumRun runWrapPendulum(const WrapPendulumSpec& spec, WrapMassOptions wrap, double duration, double tol) {
  const auto t0 = std::chrono::steady_clock::now();
  // Neural: the run's counts, summed from the integrator's and the energies' workspaces
  std::optional<WrapFallbackMonitor> monitor;
  if (wrap.model == WrapModel::Neural) monitor.emplace();
  const Model m = doublePendulum();
  const Muscle mu = makeWrapPendulumMuscle(spec, wrap);
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{mu}));
  DynamicsWorkspace ws(m);
  auto energy = [&](const State& s) { return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws); };
  State s = sys.defaultState();
  s.q << spec.q1, spec.q2;
  s.qdot.setZero();
  IntegratorOptions io;
  io.rtol = tol;
  io.atol = tol;
  auto integ = makeIntegrator("rk45", io);
  WrapPendulumRun r;
  r.spec = spec;
  const int n = static_cast<int>(std::lround(duration * 100));
  double E_prev = r.E0 = energy(s);
  double d_prev = wrapPenetration(m, mu, s);
  for (int k = 1; k <= n; ++k) {
    integ->advance(sys, s, 0.01 * k);
    const double E = energy(s), d = wrapPenetration(m, mu, s);
    if (monitor) {
      takeWrapFallbackCounts(sys, *integ->lastWorkspace(), *monitor);
      takeWrapFallbackCounts(sys, ws, *monitor);
    }
    r.max_drift = std::max(r.max_drift, std::abs(E - r.E0));
    r.max_step_change = std::max(r.max_step_change, std::abs(E - E_prev));
    r.contact_changes += (d > 0) != (d_prev > 0);
    E_prev = E;
    d_prev = d;
  }
  r.steps = integ->stats().steps;
  if (monitor) {
    r.evaluations = monitor->evaluations(mu.name);
    r.fallbacks = monitor->fallbacks(mu.name);
    const auto c = monitor->counts();
    if (auto it = c.find(mu.name); it != c.end()) r.first_fallback = it->second.first;
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::string formatWrapPendulumTable(const std::vector<WrapPendulumRun>& runs) {
  std::string out =
      "  #  origin (x, y)    insertion (x, y)  R (m)   tilt    q2_0   E0 (J)     drift (J)  max 10ms dE  contact  steps  "
      "fallbacks/evals\n";
  char buf[400];
  for (size_t i = 0; i < runs.size(); ++i) {
    const WrapPendulumRun& r = runs[i];
    const WrapPendulumSpec& s = r.spec;
    std::snprintf(buf, sizeof buf, "%3zu  %6.3f %6.3f    %6.3f %6.3f    %.4f %6.3f  %5.3f  %9.4f  %9.2e  %9.2e  %7d  %6ld  %ld/%ld%s%s\n",
                  i, s.origin.x(), s.origin.y(), s.insertion.x(), s.insertion.y(), s.radius, s.tilt, s.q2, r.E0,
                  r.max_drift, r.max_step_change, r.contact_changes, r.steps, r.fallbacks, r.evaluations,
                  r.first_fallback.empty() ? "" : "  first: ", r.first_fallback.c_str());
    out += buf;
  }
  return out;
}

}  // namespace redmax::scenes
