// Type III in the Simbody plugin.
//   - calcWrapPathMap (core/muscles/path_map.hpp): J (end points and surface pose, 12 columns)
//     against central differences of x_a (step 1e-6, agreement 1e-6 of max |J|); J v and J vdot + b
//     against first and second central differences of x_a along a trajectory with given velocities
//     and accelerations of the ends and of the surface (five-point stencils, step 2e-4; 1e-6 and
//     1e-5 relative); a wrapped cylinder, a wrapped sphere and a cylinder inside the smooth
//     model's blend band.
//   - forward dynamics: osim_models/double_pendulum_wrap.osim with 1 kg on its wrapping muscle (10
//     points) released from its default pose: Simbody particles held by the wrap path map against
//     the core's MuscleTerm integrated by rk45, q to 1e-6 rad at 0.25, 0.5, 0.75 and 1 s (core rtol
//     1e-11, Simbody accuracy 1e-10); without the muscle's mass q differs by > 1e-3 at 1 s, and the
//     muscle wraps over part of the run (checked), so the agreement covers the surface's terms.
//     CPU times of both are printed (not asserted).
//   - general Type III forward dynamics: osim_models/double_pendulum_wrap_via.osim (via point, then
//     the cylinder) with 1 kg and 0.5 kg on its muscles: particles on the general path map against
//     the core's rk45, q to 1e-6 rad at 0.25 .. 1 s (the cylinder wraps over part of the run);
//   - a conditional via point in the particle mode, switching on and off during the run (a
//     Simbody event at each end of its range re-places the particles): particles against the
//     core's rk45, q to 1e-6 rad;
//   - the exact wrap model on the same via path in the particle mode, over the part of the run
//     before its first contact change (where its J jumps): particles against the core, 1e-6 rad;
//   - taken now: the exact wrap model on a path with a via point, conditional points in particles.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <memory>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/path_map.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "plugin/simbody/muscle_inertia.hpp"
#include "plugin/simbody/particle_muscles.hpp"
#include "plugin/simbody/particle_simulation.hpp"

namespace redmax {
namespace {

struct WrapCase {
  const char* name;
  WrapSurface surface;
  Vec3 p1, p2;  // end points in the surface frame at t = 0
};

std::vector<WrapCase> wrapCases() {
  // penetration of the cylinder case 3: radius - 0.0785 = 0.0015 m, inside the 0.004 m band
  return {{"cylinder", WrapSurface::makeCylinder(0.08, 1.0), Vec3(0.05, 0.3, 0.02), Vec3(0.06, -0.3, -0.01)},
          {"sphere", WrapSurface::makeSphere(0.1), Vec3(0.03, 0.3, 0.05), Vec3(0.02, -0.3, 0.04)},
          {"cylinder in the blend band", WrapSurface::makeCylinder(0.08, 1.0), Vec3(0.0785, 0.3, 0.02),
           Vec3(0.0785, -0.3, -0.01)}};
}

MassPoints wrapMassPoints() {
  MassPointOptions opt;
  opt.count = 5;
  opt.region = MassPointOptions::Region::WholePath;
  return makeMassPoints(1.0, 1.0, 0.0, opt);
}

// the inputs along a trajectory: x_i(t) = x_i + t v_i + t^2/2 a_i, p(t) likewise,
// R(t) = exp([omega t + alpha t^2/2]) R0 (angular velocity omega and acceleration alpha at t = 0)
struct Trajectory {
  Vec3 x1, x2, p, v1, v2, vp, a1, a2, ap, omega, alpha;
  Mat3 R0;
  std::vector<Vec3> at(const WrapSurface& s, const MassPoints& mp, double t) const {
    WrapPathMap out;
    const Mat3 R = expSO3(omega * t + 0.5 * alpha * t * t) * R0;
    calcWrapPathMap(s, WrapMassOptions{}, mp, x1 + t * v1 + 0.5 * t * t * a1, x2 + t * v2 + 0.5 * t * t * a2, R,
                    p + t * vp + 0.5 * t * t * ap, nullptr, out, "test");
    return out.x_a;
  }
};

Trajectory makeTrajectory(const WrapCase& c) {
  Trajectory tr;
  tr.R0 = expSO3(Vec3(0.3, -0.5, 0.2));
  tr.p = Vec3(0.1, 0.2, -0.3);
  tr.x1 = tr.R0 * c.p1 + tr.p;
  tr.x2 = tr.R0 * c.p2 + tr.p;
  tr.v1 = Vec3(0.3, -0.2, 0.1);
  tr.v2 = Vec3(-0.1, 0.4, 0.2);
  tr.vp = Vec3(0.05, 0.1, -0.2);
  tr.a1 = Vec3(1.0, 0.5, -0.7);
  tr.a2 = Vec3(-0.4, 0.9, 0.3);
  tr.ap = Vec3(0.2, -0.6, 0.8);
  tr.omega = Vec3(0.7, -1.1, 0.4);
  tr.alpha = Vec3(-2.0, 0.5, 1.5);
  return tr;
}

TEST(WrapPathMap, JacobianMatchesCentralDifferences) {
  const MassPoints mp = wrapMassPoints();
  for (const WrapCase& c : wrapCases()) {
    SCOPED_TRACE(c.name);
    const Trajectory tr = makeTrajectory(c);
    WrapPathMap map;
    calcWrapPathMap(c.surface, WrapMassOptions{}, mp, tr.x1, tr.x2, tr.R0, tr.p, nullptr, map, "test");
    ASSERT_EQ(map.J.rows(), 15);
    ASSERT_EQ(map.J.cols(), 12);
    const double h = 1e-6;
    MatX J_fd(15, 12);
    for (int col = 0; col < 12; ++col) {
      Vec3 e = Vec3::Zero();
      e[col % 3] = 1.0;
      auto eval = [&](double sgn) {
        Vec3 x1 = tr.x1, x2 = tr.x2, p = tr.p;
        Mat3 R = tr.R0;
        // columns 6..8 turn the surface about its origin (world angular velocity), keeping x1, x2
        if (col < 3) x1 += sgn * h * e;
        else if (col < 6) x2 += sgn * h * e;
        else if (col < 9) R = expSO3(sgn * h * e) * tr.R0;
        else p += sgn * h * e;
        WrapPathMap m2;
        calcWrapPathMap(c.surface, WrapMassOptions{}, mp, x1, x2, R, p, nullptr, m2, "test");
        return stackPoints(m2.x_a);
      };
      J_fd.col(col) = (eval(1.0) - eval(-1.0)) / (2.0 * h);
    }
    const double err = (map.J - J_fd).cwiseAbs().maxCoeff(), peak = J_fd.cwiseAbs().maxCoeff();
    std::printf("  [%s] J vs central differences: %.3e of %.3e\n", c.name, err, peak);
    EXPECT_LT(err, 1e-6 * peak);
    // the path really bends: the wrapped mass points are not the straight-line ones
    EXPECT_GT(calcWrapPenetration(c.surface, c.p1, c.p2), 0.0);
  }
}

TEST(WrapPathMap, VelocityAndBiasMatchCentralDifferences) {
  const MassPoints mp = wrapMassPoints();
  for (const WrapCase& c : wrapCases()) {
    SCOPED_TRACE(c.name);
    const Trajectory tr = makeTrajectory(c);
    WrapSegmentVelocity v{tr.v1, tr.v2, tr.omega, tr.vp};
    WrapPathMap map;
    calcWrapPathMap(c.surface, WrapMassOptions{}, mp, tr.x1, tr.x2, tr.R0, tr.p, &v, map, "test");
    ASSERT_TRUE(map.velocity);
    VecX vv(12), vdot(12);
    vv << tr.v1, tr.v2, tr.omega, tr.vp;
    vdot << tr.a1, tr.a2, tr.alpha, tr.ap;
    // fourth-order five-point stencils: small enough a step for the blend band's large higher
    // derivatives, large enough for round-off
    const double h = 2e-4;
    auto x = [&](double t) { return stackPoints(tr.at(c.surface, mp, t)); };
    const VecX xp = x(h), xm = x(-h), xpp = x(2.0 * h), xmm = x(-2.0 * h), x0 = x(0.0);
    const VecX xdot_fd = (-xpp + 8.0 * xp - 8.0 * xm + xmm) / (12.0 * h);
    const VecX xddot_fd = (-xpp + 16.0 * xp - 30.0 * x0 + 16.0 * xm - xmm) / (12.0 * h * h);
    const VecX xdot = map.J * vv, xddot = map.J * vdot + map.bias;
    const double e1 = (xdot - xdot_fd).cwiseAbs().maxCoeff(), e2 = (xddot - xddot_fd).cwiseAbs().maxCoeff();
    std::printf("  [%s] xdot: %.3e of %.3e; xddot: %.3e of %.3e (bias %.3e)\n", c.name, e1,
                xdot_fd.cwiseAbs().maxCoeff(), e2, xddot_fd.cwiseAbs().maxCoeff(), map.bias.cwiseAbs().maxCoeff());
    EXPECT_LT(e1, 1e-6 * xdot_fd.cwiseAbs().maxCoeff());
    EXPECT_LT(e2, 1e-5 * xddot_fd.cwiseAbs().maxCoeff());
    // the bias is not negligible here (a map without it would fail the line above)
    EXPECT_GT(map.bias.cwiseAbs().maxCoeff(), 1e-2 * xddot_fd.cwiseAbs().maxCoeff());
  }
}

TEST(WrapPathMap, EmptyMassPointsAndEndInsideThrow) {
  WrapPathMap map;
  const WrapSurface cyl = WrapSurface::makeCylinder(0.08, 1.0);
  EXPECT_THROW(calcWrapPathMap(cyl, WrapMassOptions{}, MassPoints{}, Vec3(0.1, 0.3, 0), Vec3(0.1, -0.3, 0),
                               Mat3::Identity(), Vec3::Zero(), nullptr, map, "m"),
               std::invalid_argument);
  // an end point inside the cylinder: the muscle is named
  try {
    calcWrapPathMap(cyl, WrapMassOptions{}, wrapMassPoints(), Vec3(0.01, 0.0, 0), Vec3(0.1, -0.3, 0),
                    Mat3::Identity(), Vec3::Zero(), nullptr, map, "inside_muscle");
    ADD_FAILURE() << "no error for an end point inside the surface";
  } catch (const MuscleError& e) {
    EXPECT_NE(std::string(e.what()).find("inside_muscle"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// forward dynamics: the wrapping double pendulum

struct WrapPendulum {
  osim::BuildResult build;
  std::vector<Muscle> muscles;  // with mass
  State s0;
};

WrapPendulum wrapPendulum(double mass) {
  const osim::ModelDescription d =
      osim::readOsimModel(std::string(REDMAX_SOURCE_DIR) + "/osim_models/double_pendulum_wrap.osim");
  osim::BuildOptions bo;
  bo.constraints = false;
  WrapPendulum w;
  w.build = osim::buildCoreModel(d, bo);
  w.muscles = w.build.model.muscles();
  MassPointOptions opt;
  opt.count = 10;
  for (Muscle& mu : w.muscles)
    if (mass > 0.0) mu.mass_points = makeMassPoints(mass, mu.optimal_fiber_length, mu.tendon_slack_length, opt);
  w.s0.t = 0.0;
  w.s0.q.resize(2);
  for (int c = 0; c < 2; ++c) w.s0.q[c] = w.build.model.skeleton().coordinates()[c].default_value;
  w.s0.qdot = VecX::Zero(2);
  return w;
}

// the core's System with the muscles' MuscleTerm and rk45 (rtol 1e-11, atol 1e-12)
struct CoreRk45 {
  System sys;
  std::unique_ptr<Integrator> integ;
  CoreRk45(const Model& m, const std::vector<Muscle>& muscles) : sys(m) {
    sys.addTerm(std::make_shared<MuscleTerm>(m, muscles));
    IntegratorOptions o;
    o.rtol = 1e-11;
    o.atol = 1e-12;
    integ = makeIntegrator("rk45", o);
  }
};

// the core's MuscleTerm by rk45 (rtol 1e-11) and Simbody particles (accuracy 1e-10) from s0 over
// 1 s: q to 1e-6 rad at 0.25, 0.5, 0.75 and 1 s, and the muscles' mass matters (q differs from the
// run with the massless `plain` muscles by > 1e-3 rad at 1 s). on_core_state sees the core's state
// every 0.01 s. CPU times printed (not asserted).
void compareParticlesWithCore(const Model& m, const std::vector<Muscle>& muscles, const std::vector<Muscle>& plain,
                              const State& s0, const char* label,
                              const std::function<void(const State&)>& on_core_state) {
  const std::vector<double> times{0.25, 0.5, 0.75, 1.0};
  auto core_run = [&](const std::vector<Muscle>& ms, double& cpu, bool watch) {
    CoreRk45 core(m, ms);
    auto& integ = core.integ;
    auto& sys = core.sys;
    State s = s0;
    std::vector<VecX> q;
    const std::clock_t t0 = std::clock();
    for (int k = 1; k <= 100; ++k) {
      integ->advance(sys, s, 0.01 * k);
      if (k % 25 == 0) q.push_back(s.q);
      if (watch) on_core_state(s);
    }
    cpu = double(std::clock() - t0) / CLOCKS_PER_SEC;
    return q;
  };
  double core_s = 0.0, plain_s = 0.0;
  const std::vector<VecX> q_core = core_run(muscles, core_s, true);
  const std::vector<VecX> q_plain = core_run(plain, plain_s, false);

  simbody::ParticleSimulationOptions po;
  po.accuracy = 1e-10;
  po.constraint_tolerance = 1e-11;
  const std::clock_t t0 = std::clock();
  simbody::ParticleSimulation sim(makeMusculoskeletalModel(m, muscles), s0, po);
  double worst = 0.0;
  for (size_t k = 0; k < times.size(); ++k) {
    const State& s = sim.advance(times[k]);
    const double err = (s.q - q_core[k]).cwiseAbs().maxCoeff();
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-6) << "t = " << times[k] << ": simbody " << s.q.transpose() << " core " << q_core[k].transpose();
  }
  const double sb_s = double(std::clock() - t0) / CLOCKS_PER_SEC;
  EXPECT_GT((q_core.back() - q_plain.back()).cwiseAbs().maxCoeff(), 1e-3);
  std::printf("  %s, particles vs core rk45 over 1 s: max |dq| %.3e rad; CPU: simbody %.3f s (%ld steps), core %.3f s\n",
              label, worst, sb_s, sim.steps(), core_s);
}

// penetration of the straight segment between path points i and i + 1 into the muscle's first
// wrap surface (surface frame; > 0: the segment wraps)
double segmentPenetration(const Model& m, const Muscle& mu, const State& s, int i) {
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  const PathWrap& pw = mu.path.wraps[0];
  const Mat4 E_ws = sk.E_wi[pw.body] * pw.E_bs;
  auto in_s = [&](const PathPoint& p) {
    const Vec3 x = (sk.E_wi[p.body] * p.location.homogeneous()).head<3>();
    return Vec3(E_ws.topLeftCorner<3, 3>().transpose() * (x - E_ws.topRightCorner<3, 1>()));
  };
  return calcWrapPenetration(pw.surface, in_s(mu.path.points[i]), in_s(mu.path.points[i + 1]));
}

TEST(SimbodyParticleMuscles, WrappingDoublePendulumMatchesCoreRk45) {
  const WrapPendulum w = wrapPendulum(1.0);
  const Model& m = w.build.model;
  ASSERT_EQ(w.muscles.size(), 1u);
  ASSERT_EQ(pathType(w.muscles[0].path), PathType::III);
  double min_pen = 1e9, max_pen = -1e9;
  compareParticlesWithCore(m, w.muscles, wrapPendulum(0.0).muscles, w.s0, "wrapping pendulum", [&](const State& s) {
    const double pen = segmentPenetration(m, w.muscles[0], s, 0);
    min_pen = std::min(min_pen, pen);
    max_pen = std::max(max_pen, pen);
  });
  std::printf("  straight-line penetration into the cylinder over the run: %.4f .. %.4f m\n", min_pen, max_pen);
  EXPECT_GT(max_pen, 0.0);  // wraps during part of the run
}

// the wrap + via pendulum's muscles with mass (1 kg on the wrapping one, 0.5 kg on the straight
// one, 10 points each), its default pose at rest, and the wrapping muscle's index
struct WrapViaPendulum {
  osim::BuildResult build;
  std::vector<Muscle> muscles;
  State s0;
  int gastroc = -1;
};

WrapViaPendulum wrapViaPendulum() {
  WrapViaPendulum w;
  const osim::ModelDescription d =
      osim::readOsimModel(std::string(REDMAX_SOURCE_DIR) + "/osim_models/double_pendulum_wrap_via.osim");
  osim::BuildOptions bo;
  bo.constraints = false;
  w.build = osim::buildCoreModel(d, bo);
  const Model& m = w.build.model;
  w.muscles = w.build.model.muscles();
  MassPointOptions opt;
  opt.count = 10;
  for (size_t k = 0; k < w.muscles.size(); ++k) {
    Muscle& mu = w.muscles[k];
    const bool wraps = pathType(mu.path) == PathType::III;
    if (wraps) w.gastroc = static_cast<int>(k);
    mu.mass_points = makeMassPoints(wraps ? 1.0 : 0.5, mu.optimal_fiber_length, mu.tendon_slack_length, opt);
  }
  w.s0.q.resize(m.nr());
  for (int c = 0; c < m.nr(); ++c) w.s0.q[c] = m.coordinates()[c].default_value;
  w.s0.qdot = VecX::Zero(m.nr());
  return w;
}

// general Type III forward dynamics: osim_models/double_pendulum_wrap_via.osim (origin, via point,
// cylinder on the via -> insertion segment) with 1 kg on its wrapping muscle and 0.5 kg on its
// straight one (10 points each), released from its default pose (compareParticlesWithCore); the
// cylinder wraps over part of the run
TEST(SimbodyParticleMuscles, WrapViaPendulumMatchesCoreRk45) {
  const WrapViaPendulum w = wrapViaPendulum();
  const Model& m = w.build.model;
  const std::vector<Muscle>& muscles = w.muscles;
  const int gastroc = w.gastroc;
  ASSERT_GE(gastroc, 0);
  ASSERT_EQ(muscles[gastroc].path.points.size(), 3u);
  double min_pen = 1e9, max_pen = -1e9;
  compareParticlesWithCore(m, muscles, w.build.model.muscles(), w.s0, "wrap + via pendulum", [&](const State& s) {
    const double pen = segmentPenetration(m, muscles[gastroc], s, 1);
    min_pen = std::min(min_pen, pen);
    max_pen = std::max(max_pen, pen);
  });
  std::printf("  via -> insertion penetration into the cylinder over the run: %.4f .. %.4f m\n", min_pen, max_pen);
  EXPECT_GT(max_pen, 0.0);  // wraps during part of the run
}

// a conditional via point in the particle mode: the wrap + via pendulum's via point made
// conditional on q2 over a range that q2 enters and leaves during the run (its values at 0.3 s and
// 0.6 s along the run with the via point fixed), so the path switches between origin -> via ->
// (cylinder) -> insertion and origin -> (cylinder) -> insertion. Particles (re-placed at each
// switch event) against the core's rk45, q to 1e-6 rad at 0.25 .. 1 s (compareParticlesWithCore);
// the core's run switches at least twice (checked every 0.01 s).
TEST(SimbodyParticleMuscles, ConditionalViaPointSwitchingMatchesCoreRk45) {
  WrapViaPendulum w = wrapViaPendulum();
  const Model& m = w.build.model;
  const int q2 = 1;
  // q2 along the run with the via point always on
  double lo = 0.0, hi = 0.0;
  {
    CoreRk45 core(m, w.muscles);
    State s = w.s0;
    core.integ->advance(core.sys, s, 0.3);
    lo = s.q[q2];
    core.integ->advance(core.sys, s, 0.6);
    hi = s.q[q2];
    if (lo > hi) std::swap(lo, hi);
  }
  std::vector<Muscle> muscles = w.muscles;
  auto& pts = muscles[w.gastroc].path.points;
  ASSERT_EQ(pts.size(), 3u);
  pts[1] = makeConditionalPoint(pts[1].body, pts[1].location, q2, lo, hi, "cvia");
  for (const Muscle& mu : muscles) validateMuscle(m, mu);
  int switches = 0;
  bool was_on = isPathPointActive(pts[1], w.s0.q);
  compareParticlesWithCore(m, muscles, w.build.model.muscles(), w.s0, "conditional via point", [&](const State& s) {
    const bool on = isPathPointActive(pts[1], s.q);
    switches += on != was_on;
    was_on = on;
  });
  std::printf("  via point range [%.4f, %.4f] rad of q2, %d switches over the core's run\n", lo, hi, switches);
  EXPECT_GE(switches, 2);
}

// the exact wrap model on origin -> via -> (cylinder) -> insertion in the particle mode: the wrap +
// via pendulum over the part of its run before the first contact change of the via -> insertion
// segment (the exact model's J jumps there, which particles cannot follow), particles against the
// core's rk45 at four times in it, q to 1e-6 rad
TEST(SimbodyParticleMuscles, ExactModelOnWrapViaPendulumMatchesCoreRk45) {
  WrapViaPendulum w = wrapViaPendulum();
  const Model& m = w.build.model;
  std::vector<Muscle> muscles = w.muscles;
  muscles[w.gastroc].wrap.model = WrapModel::Exact;
  CoreRk45 core(m, muscles);
  State s = w.s0;
  const bool wrapped0 = segmentPenetration(m, muscles[w.gastroc], s, 1) > 0.0;
  double t_change = 1.0;
  std::vector<State> samples;
  for (int k = 1; k <= 100; ++k) {
    core.integ->advance(core.sys, s, 0.01 * k);
    if ((segmentPenetration(m, muscles[w.gastroc], s, 1) > 0.0) != wrapped0) {
      t_change = 0.01 * (k - 1);
      break;
    }
    samples.push_back(s);
  }
  std::printf("  exact model: the via -> insertion segment %s until %.2f s\n", wrapped0 ? "wraps" : "is free", t_change);
  ASSERT_GE(t_change, 0.1);
  simbody::ParticleSimulationOptions po;
  po.accuracy = 1e-10;
  po.constraint_tolerance = 1e-11;
  simbody::ParticleSimulation sim(makeMusculoskeletalModel(m, muscles), w.s0, po);
  double worst = 0.0;
  for (int j = 1; j <= 4; ++j) {
    const int k = static_cast<int>(std::lround(j * 0.25 * t_change / 0.01)) - 1;
    const State& sb = sim.advance(samples[k].t);
    const double err = (sb.q - samples[k].q).cwiseAbs().maxCoeff();
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-6) << "t = " << samples[k].t;
  }
  std::printf("  exact model, particles vs core rk45 up to %.2f s: max |dq| %.3e rad (%ld Simbody steps)\n",
              samples[static_cast<int>(std::lround(t_change / 0.01)) - 1].t, worst, sim.steps());
}

// the shapes the Simbody side used to refuse, now taken: the exact wrap model on a path with a via
// point (OpenSim's whole path, differences in v: tests/plugin/muscle_inertia_test.cpp compares it
// with the core), and conditional points in the particles; a mass point without mass is still refused
TEST(SimbodyParticleMuscles, ExactModelOnViaPathsAndConditionalParticlesAreTaken) {
  WrapPendulum w = wrapPendulum(1.0);
  const Model& m = w.build.model;
  Muscle mu = w.muscles[0];
  mu.path.points.insert(mu.path.points.begin() + 1, makeFixedPoint(0, Vec3(-0.12, -0.8, 0.0), "via"));
  mu.wrap.model = WrapModel::Exact;
  validateMuscle(m, mu);
  EXPECT_EQ(simbody::simbodyWrapShapeUnsupportedReason(mu), "");
  auto sm = simbody::makeSimbodyModel(m);
  EXPECT_NO_THROW(simbody::MuscleInertia(*sm, makeMusculoskeletalModel(m, {mu})));
  EXPECT_NO_THROW(simbody::ParticleMuscles(*sm, m, {mu}));
  Muscle cond = w.muscles[0];
  cond.path.points.insert(cond.path.points.begin() + 1, makeConditionalPoint(0, Vec3(-0.12, -0.8, 0.0), 1, -1.0, 1.0, "cvia"));
  validateMuscle(m, cond);
  auto sm2 = simbody::makeSimbodyModel(m);
  EXPECT_NO_THROW(simbody::ParticleMuscles(*sm2, m, {cond}));
  Muscle massless = w.muscles[0];
  massless.mass_points.mass[0] = 0.0;
  auto sm3 = simbody::makeSimbodyModel(m);
  try {
    simbody::ParticleMuscles p(*sm3, m, {massless});
    ADD_FAILURE() << "a massless particle was taken";
  } catch (const simbody::SimbodyBuildError& e) {
    EXPECT_NE(std::string(e.what()).find(massless.name), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace redmax
