// Energy with two cylinders on one segment under the smooth composition (issue 22,
// core/muscles/wrap/smooth_composite.hpp): the double pendulum of validation/scenes (two 1 m, 1 kg
// rods, gravity -y) with a muscle from link 1 to link 2 on the -x side over a cylinder on each
// link near the middle joint (quadrant -x, radius 0.05 m, 0.12 m from the joint), a 1 kg muscle
// of 20 points, undamped rk45 at rtol = atol = 1e-12 for 3 s: each cylinder's contact changes
// several times (the mass matrix is C2 across each), and the energy is conserved as well as the
// one-surface smooth model conserves it on these cylinders (below).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/mass_points.hpp"
#include "core/muscles/wrap/smooth_composite.hpp"
#include "core/muscles/wrap_composite.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

Muscle twoCylinderMuscle(WrapModel model) {
  Muscle mu;
  mu.name = "two_cylinders";
  mu.path.points = {makeFixedPoint(0, Vec3(-0.1, -0.6, 0.0), "origin"), makeFixedPoint(1, Vec3(-0.1, -0.4, 0.0), "insertion")};
  PathWrap a, b;
  a.name = "thigh_cylinder";
  a.surface = WrapSurface::makeCylinder(0.05, 0.2, 0, -1);
  a.body = 0;
  a.E_bs = makeE(Mat3::Identity(), Vec3(0.0, -0.88, 0.0));
  b.name = "shank_cylinder";
  b.surface = WrapSurface::makeCylinder(0.05, 0.2, 0, -1);
  b.body = 1;
  // tilted: with parallel axes and every point in their common normal plane the fixed point is
  // degenerate (the path may slide along the axes; an error, docs/wrapping.md §3.3)
  b.E_bs = makeE(Eigen::AngleAxisd(0.1, Vec3::UnitY()).toRotationMatrix(), Vec3(0.0, -0.12, 0.0));
  mu.path.wraps = {a, b};
  mu.path.num_wraps = 2;
  mu.optimal_fiber_length = 0.5;
  mu.tendon_slack_length = 0.3;
  mu.mass_points = makeMassPoints(1.0, 0.5, 0.3);
  mu.wrap.model = model;
  return mu;
}

// each cylinder's blend weight on the composed segment at q
std::vector<double> weightsAt(const Model& m, const Muscle& mu, const VecX& q) {
  std::vector<Mat4> E_wi;
  calcBodyPoses(m, q, E_wi);
  std::vector<CompositeWrapSurface> s;
  for (const PathWrap& w : mu.path.wraps) {
    const Mat4 E = E_wi[w.body] * w.E_bs;
    CompositeWrapSurface c;
    c.surface = &w.surface;
    c.R = E.topLeftCorner<3, 3>();
    c.p = E.topRightCorner<3, 1>();
    s.push_back(c);
  }
  const Vec3 p1 = transformPoint(E_wi[0], mu.path.points[0].location);
  const Vec3 p2 = transformPoint(E_wi[1], mu.path.points[1].location);
  CompositeWrapResult r;
  calcSmoothCompositeWrap(s, p1, p2, Vec3::Zero(), Vec3::Zero(), {}, {}, mu.wrap.width, r);
  return r.weights;
}

struct EnergyRun {
  double E0 = 0.0, drift = 0.0;
  int changes[2] = {0, 0};
  long steps = 0;
};

EnergyRun run(WrapModel model, double duration, double tol = 1e-12) {
  const Model m = scenes::doublePendulum();
  const Muscle mu = twoCylinderMuscle(model);
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{mu}));
  DynamicsWorkspace ws(m);
  auto energy = [&](const State& s) { return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws); };
  State s = sys.defaultState();
  s.q << 0.3, 0.9;
  s.qdot.setZero();
  IntegratorOptions io;
  io.rtol = io.atol = tol;
  auto integ = makeIntegrator("rk45", io);
  EnergyRun r;
  r.E0 = energy(s);
  std::vector<double> w_prev = weightsAt(m, mu, s.q);
  const int n = static_cast<int>(std::lround(duration * 100));
  for (int k = 1; k <= n; ++k) {
    integ->advance(sys, s, 0.01 * k);
    const double E = energy(s);
    r.drift = std::max(r.drift, std::abs(E - r.E0));
    const std::vector<double> w = weightsAt(m, mu, s.q);
    for (int c = 0; c < 2; ++c) r.changes[c] += (w[c] > 0.0) != (w_prev[c] > 0.0);
    w_prev = w;
  }
  r.steps = integ->stats().steps;
  return r;
}

TEST(WrapSmoothCompositeEnergy, PendulumOverTwoCylindersOnOneSegment) {
  const double duration = 3.0;
  const EnergyRun s = run(WrapModel::Smooth, duration);
  std::printf("[ measured ] two cylinders on one segment, %.0f s rk45 1e-12, E0 %.6f J: smooth composition drift "
              "%.3e J, %ld steps, contact changes %d (thigh) and %d (shank)\n",
              duration, s.E0, s.drift, s.steps, s.changes[0], s.changes[1]);
  EXPECT_GE(s.changes[0], 2);
  EXPECT_GE(s.changes[1], 2);
  // measured 1.25e-8 J in 4388 steps, the same at rtol 1e-13 (1.1e-8 J: not the integrator's
  // tolerance): the one-surface smooth model on this scene's shank cylinder alone drifts 2.1e-8 J
  // (the thigh's alone 9.3e-10 J), from the quadrant cylinder's own unsmoothed switches (smooth.hpp),
  // so the composition adds nothing measurable; the single wrapping pendulum's 7e-11 J has
  // end points far from its quadrant plane
  EXPECT_LE(s.drift, 2e-8);
}

}  // namespace
}  // namespace redmax
