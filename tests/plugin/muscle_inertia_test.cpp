// Muscle inertia inside Simbody (plugin/simbody/muscle_inertia.hpp, SimbodyIdEngine with muscles)
// against the core's MuscleTerm [D Eq. 5.6-5.7]. The Simbody side takes the path points' motion from
// Simbody's station Jacobians and biases, the core side from J_mr; both share only the path maps.
//   - component: T^T f_u (Simbody, mapped to core velocities) == M_muscle qddot - f_muscle (core),
//     and the mass points' kinetic and potential energies, on random trees (Gimbal, Ball, Free
//     mobilizers) with Type I, Type II (1-5 via points), moving and conditional points, and Type III
//     (one cylinder or sphere on the origin's body, a third body or the world; fixed or moving ends;
//     and two surfaces on the two segments of origin -> middle point -> insertion, the middle point
//     fixed, moving, or conditional on or off); the exact wrap model on longer paths (via + wrap +
//     via, two surfaces on one segment, two on different segments) against the core's exact and
//     smooth models, to the differences' error (kExactTol, kExactVsSmoothTol);
//   - engine: SimbodyIdEngine(model, muscles) == core System + MuscleTerm inverse dynamics on the
//     project's scenes (double pendulums with a Type I, II and III muscle, finger, running leg with its
//     wrapping gastrocnemii; double_pendulum_wrap_via with a via point before the cylinder, as
//     authored, with the via point conditional and with a moving insertion) and
//     on set F (gait10dof18musc) with 20% and 80% of tibia_r's mass moved into its muscles.
// Agreement: max |a - b| <= 1e-9 max |b| (relative to the peak of the reference column) at random
// states. Each case also checks that the muscles change the torques by more than 1e-4 of the peak,
// so a plugin that dropped them would fail.
#include "plugin/simbody/muscle_inertia.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>
#include <string>

#include <Eigen/LU>

#include "converter/build/build_core_model.hpp"
#include "converter/build/muscle_mass.hpp"
#include "converter/id/core_id_engine.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/spatial/se3.hpp"
#include "core/skeleton/kinematics.hpp"
#include "plugin/simbody/id_engine.hpp"
#include "tests/plugin/wrap_test_geometry.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

constexpr double kTol = 1e-9;

double g_worst = 0.0;  // largest max|a - b| / max|b| of the current test, printed at its end
class WorstLog : public ::testing::EmptyTestEventListener {
  void OnTestStart(const ::testing::TestInfo&) override { g_worst = 0.0; }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    if (g_worst > 0.0)
      std::printf("  [%s.%s] largest difference / peak: %.3e\n", info.test_suite_name(), info.name(), g_worst);
  }
};
const bool g_log_installed = [] {
  ::testing::UnitTest::GetInstance()->listeners().Append(new WorstLog);
  return true;
}();

::testing::AssertionResult closeToPeak(const VecX& a, const VecX& b, double tol) {
  const double err = (a - b).cwiseAbs().maxCoeff();
  const double peak = b.cwiseAbs().maxCoeff();
  g_worst = std::max(g_worst, err / peak);
  if (err <= tol * peak) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "max difference " << err << " > " << tol << " x peak " << peak
                                       << "\nsimbody " << a.transpose() << "\ncore    " << b.transpose();
}

Vec3 randomVec(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return Vec3(u(rng), u(rng), u(rng)) * scale;
}

State randomState(int nr, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.q = VecX::NullaryExpr(nr, [&] { return u(rng); });
  s.qdot = VecX::NullaryExpr(nr, [&] { return 2.0 * u(rng); });
  return s;
}

// the muscle-mass part of inverse dynamics in the core: M_muscle qddot - f_muscle
VecX coreMuscleTau(const Model& model, const MuscleTerm& term, const State& s, const VecX& qddot) {
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  MatX M = MatX::Zero(model.nr(), model.nr());
  VecX f = VecX::Zero(model.nr());
  term.addMass(model, s, sk, M);
  term.addForce(model, s, sk, f);
  return M * qddot - f;
}

// the same from the Simbody component, mapped to core velocities: tau = T^T f_u(udot = T qddot + Tdot qdot)
VecX simbodyMuscleTau(const simbody::SimbodyModel& sm, simbody::MuscleInertia& mi, const Model& model,
                      const State& s, const VecX& qddot) {
  SimTK::State sb = sm.default_state;
  simbody::setSimbodyState(sm, model, s, sb);
  sm.system.realize(sb, SimTK::Stage::Velocity);
  MatX T, Tdot;
  simbody::calcVelocityMap(sm, model, s, T, &Tdot);
  const VecX udot = T * qddot + Tdot * s.qdot;
  return T.transpose() * mi.calcGeneralizedForces(sb, udot);
}

int randomBody(const Model& m, std::mt19937& rng, bool allow_world) {
  const int lo = allow_world ? -1 : 0;
  return lo + static_cast<int>(rng() % static_cast<unsigned>(m.nb() - lo));
}

// variant 0: Type I; 1-5: that many via points; 6: moving points; 7: conditional points
Muscle randomMuscle(const Model& m, int variant, std::mt19937& rng, const State& s) {
  Muscle mu;
  mu.name = "random" + std::to_string(variant);
  auto& pts = mu.path.points;
  pts.push_back(makeFixedPoint(randomBody(m, rng, true), randomVec(rng, 0.3)));
  const int nvia = variant <= 5 ? variant : 1;
  for (int k = 0; k < nvia; ++k) pts.push_back(makeFixedPoint(randomBody(m, rng, false), randomVec(rng, 0.3)));
  const int c = static_cast<int>(rng() % m.nr());
  if (variant == 6) {
    auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.05, -0.1, 0.2, 0.1});
    auto line = std::make_shared<LinearFunction>(0.3, 0.2);
    pts.push_back(makeMovingPoint(randomBody(m, rng, false), c, {cubic, nullptr, line}, Vec3(0, 0.1, 0)));
    pts.push_back(makeMovingPoint(-1, static_cast<int>(rng() % m.nr()), {line, cubic, nullptr}, Vec3(0, 0, 0.2)));
  }
  if (variant == 7) {
    pts.push_back(makeConditionalPoint(randomBody(m, rng, false), randomVec(rng, 0.3), c, s.q[c] - 0.3, s.q[c] + 0.3));
    pts.push_back(makeConditionalPoint(randomBody(m, rng, false), randomVec(rng, 0.3), c, s.q[c] + 1.0, s.q[c] + 2.0));
  }
  pts.push_back(makeFixedPoint(randomBody(m, rng, false), randomVec(rng, 0.3)));
  MassPointOptions opt;
  opt.count = 7;
  mu.mass_points = makeMassPoints(0.8, 0.5, 0.3, opt);
  mu.optimal_fiber_length = 0.5;
  mu.tendon_slack_length = 0.3;
  return mu;
}

using MakeMuscles = std::function<std::vector<Muscle>(const Model&, int variant, int trial, const State&, std::mt19937&)>;
using OnCompared = std::function<void(const Model&, const std::vector<Muscle>&, const State&, int variant)>;

// the component against the core on random trees (a Gimbal and a Ball tree; with_pendulum: also the
// double pendulum): per system, variants x trials random states, make() giving the muscles at each;
// T^T f_u == M_muscle qddot - f_muscle to kTol of the peak, and the mass points' kinetic and
// potential energies. Returns how many states were compared: one where the core finds a path
// degenerate (two random points coincide, an end inside a surface) is skipped.
int compareOnRandomTrees(bool with_pendulum, std::uint32_t seed, int variants, int trials, const MakeMuscles& make,
                         const OnCompared& on_compared = {}, double tol = kTol) {
  using scenes::TreeJoints;
  using simbody::SphericalAs;
  struct Case {
    Model model;
    SphericalAs spherical;
  };
  std::vector<Case> cases{{scenes::randomTree(6, 11, TreeJoints::SimbodyComparable), SphericalAs::Gimbal},
                          {scenes::randomTree(8, 29, TreeJoints::SimbodyComparable), SphericalAs::Ball}};
  if (with_pendulum) cases.push_back({scenes::doublePendulum(), SphericalAs::Gimbal});
  std::mt19937 rng(seed);
  int checked = 0;
  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const Model& m = cases[ci].model;
    simbody::SimbodyBuildOptions opt;
    opt.spherical = cases[ci].spherical;
    const auto sm = simbody::makeSimbodyModel(m, opt);
    for (int variant = 0; variant < variants; ++variant) {
      for (int trial = 0; trial < trials; ++trial) {
        SCOPED_TRACE("case " + std::to_string(ci) + " variant " + std::to_string(variant) + " trial " +
                     std::to_string(trial));
        const State s = randomState(m.nr(), rng);
        std::vector<Muscle> muscles = make(m, variant, trial, s, rng);
        for (Muscle& mu : muscles) validateMuscle(m, mu);
        const MuscleTerm term(m, muscles);
        simbody::MuscleInertia mi(*sm, makeMusculoskeletalModel(m, muscles));
        const VecX qddot = VecX::NullaryExpr(m.nr(), [&] { return randomVec(rng, 3.0)[0]; });
        VecX core;
        try {
          core = coreMuscleTau(m, term, s, qddot);
        } catch (const MuscleError&) {
          continue;
        }
        const VecX sb = simbodyMuscleTau(*sm, mi, m, s, qddot);
        EXPECT_TRUE(closeToPeak(sb, core, tol));
        // energies of the mass points (the core's from its own kinematics)
        SkeletonWorkspace sk(m);
        calcKinematics(m, s, sk);
        SimTK::State st = sm->default_state;
        simbody::setSimbodyState(*sm, m, s, st);
        sm->system.realize(st, SimTK::Stage::Velocity);
        const double T_core = term.kineticEnergy(m, s, sk), V_core = term.potentialEnergy(m, s, sk);
        EXPECT_NEAR(mi.kineticEnergy(st), T_core, tol * (1.0 + std::abs(T_core)));
        EXPECT_NEAR(mi.potentialEnergy(st), V_core, kTol * (1.0 + std::abs(V_core)));
        if (on_compared) on_compared(m, muscles, s, variant);
        ++checked;
      }
    }
  }
  return checked;
}

TEST(SimbodyMuscleInertia, MatchesCoreMuscleTermOnRandomTrees) {
  // two muscles per system, so the batch of stations spans muscles
  const int checked = compareOnRandomTrees(true, 2024, 8, 2, [](const Model& m, int variant, int, const State& s,
                                                                  std::mt19937& rng) {
    return std::vector<Muscle>{randomMuscle(m, variant, rng, s), randomMuscle(m, (variant + 3) % 8, rng, s)};
  });
  EXPECT_GE(checked, 40);
}

// a path point's world position at state s (sk: the skeleton at s)
Vec3 worldPoint(const PathPoint& p, const State& s, const SkeletonWorkspace& sk) {
  Vec3 x_b, dx, ddx;
  calcPointLocation(p, s.q, x_b, dx, ddx);
  return p.body < 0 ? x_b : Vec3((sk.E_wi[p.body] * x_b.homogeneous()).head<3>());
}

// a surface (radius 0.03 m) on body `body` (-1: world) that the segment x1 -> x2 (world, at the
// state of sk) wraps (test::surfacePoseAcross), perpendicular to it from a random side, with a
// random turn about its axis
PathWrap wrapAcross(const Vec3& x1, const Vec3& x2, int body, bool sphere, const SkeletonWorkspace& sk,
                    std::mt19937& rng) {
  const Vec3 side = randomVec(rng, 1.0);
  const double turn = randomVec(rng, 3.0)[0];
  const Mat4 E_ws = test::surfacePoseAcross(x1, x2, side, turn);
  PathWrap w;
  w.name = sphere ? "ball" : "drum";
  w.surface = sphere ? WrapSurface::makeSphere(0.03) : WrapSurface::makeCylinder(0.03, 2.0);
  w.body = body;
  w.E_bs = body >= 0 ? Mat4(sk.E_wi[body].inverse() * E_ws) : E_ws;
  return w;
}

// mass points and fibre data of the random wrapping muscles
void giveMass(Muscle& mu, int count) {
  MassPointOptions opt;
  opt.count = count;
  mu.mass_points = makeMassPoints(0.7, 0.5, 0.3, opt);
  mu.optimal_fiber_length = 0.5;
  mu.tendon_slack_length = 0.3;
}

// Type III: origin -> one surface -> insertion. The surface (wrapAcross) on the origin's body
// (variant 0), a body that moves neither end (1), the world (2), or with a moving insertion (3);
// smooth wrap model.
Muscle randomWrapMuscle(const Model& m, int variant, std::mt19937& rng, const State& s, bool sphere) {
  Muscle mu;
  mu.name = "wrap" + std::to_string(variant);
  const int b1 = randomBody(m, rng, true);
  int b2 = randomBody(m, rng, false);
  mu.path.points.push_back(makeFixedPoint(b1, randomVec(rng, 0.3)));
  if (variant == 3) {
    auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.05, -0.1, 0.2, 0.1});
    auto line = std::make_shared<LinearFunction>(0.3, 0.2);
    mu.path.points.push_back(makeMovingPoint(b2, static_cast<int>(rng() % m.nr()), {cubic, nullptr, line}, Vec3(0, 0.1, 0)));
  } else {
    mu.path.points.push_back(makeFixedPoint(b2, randomVec(rng, 0.3)));
  }
  int bs = b1;
  if (variant == 1) bs = randomBody(m, rng, false);
  if (variant == 2) bs = -1;
  // the ends at this state (world), the surface centred between them
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  mu.path.wraps = {wrapAcross(worldPoint(mu.path.points[0], s, sk), worldPoint(mu.path.points[1], s, sk), bs, sphere,
                              sk, rng)};
  mu.path.num_wraps = 1;
  giveMass(mu, 6);
  return mu;
}

TEST(SimbodyMuscleInertia, TypeIIIMatchesCoreMuscleTermOnRandomTrees) {
  // a wrapping muscle next to a Type II one, so the batches span both kinds
  const int checked = compareOnRandomTrees(true, 77, 4, 4, [](const Model& m, int variant, int trial, const State& s,
                                                                std::mt19937& rng) {
    return std::vector<Muscle>{randomWrapMuscle(m, variant, rng, s, trial % 2 == 1), randomMuscle(m, 1, rng, s)};
  });
  EXPECT_GE(checked, 30);
}

TEST(SimbodyMuscleInertia, MasslessMusclesAddNothingAndBadMusclesThrow) {
  const Model m = scenes::doublePendulum();
  const auto sm = simbody::makeSimbodyModel(m);
  Muscle mu;
  mu.name = "lumped";
  mu.path.points = {makeFixedPoint(-1, Vec3(0.1, 0, 0)), makeFixedPoint(1, Vec3(0, -0.5, 0))};
  simbody::MuscleInertia mi(*sm, makeMusculoskeletalModel(m, {mu}));
  SimTK::State sb = sm->default_state;
  sm->system.realize(sb, SimTK::Stage::Velocity);
  EXPECT_EQ(mi.calcGeneralizedForces(sb, VecX::Ones(2)).norm(), 0.0);
  // a point on a body the model does not have
  mu.path.points.back().body = 5;
  EXPECT_THROW(simbody::MuscleInertia(*sm, makeMusculoskeletalModel(m, {mu})), ModelError);
}

// OpenSim's Euler-rate speeds (IdEngineOptions::rates_as_u) with muscles: for marked Ball/Free joints
// the engine is given u and udot and answers conjugate to u. Reference: the core engine without
// muscles (which converts to the core's qdot, qddot: lastState, lastQddot) plus the core MuscleTerm's
// share at that (qdot, qddot), mapped per marked joint by tau_u = T^-T tau_qdot.
TEST(SimbodyIdEngineMuscles, RatesAsUMatchesCoreOnRandomTrees) {
  using scenes::TreeJoints;
  std::mt19937 rng(99);
  int marked_total = 0, compared = 0;
  for (std::uint32_t seed : {5u, 41u, 77u}) {
    const Model m = scenes::randomTree(7, seed, TreeJoints::SimbodyComparable);
    osim::IdEngineOptions opt;
    opt.rates_as_u.assign(m.nb(), false);
    for (int j = 0; j < m.nb(); ++j) opt.rates_as_u[j] = osim::hasOpenSimSpeedMap(m.joints()[j].joint);
    for (int j = 0; j < m.nb(); ++j) marked_total += opt.rates_as_u[j] ? 1 : 0;
    const State s_any = randomState(m.nr(), rng);
    std::vector<Muscle> muscles{randomMuscle(m, 2, rng, s_any), randomMuscle(m, 6, rng, s_any)};
    for (Muscle& mu : muscles) validateMuscle(m, mu);
    simbody::SimbodyIdEngine sb_engine(makeMusculoskeletalModel(m, muscles), opt);
    osim::CoreIdEngine core_engine(m, opt);
    const MuscleTerm term(m, muscles);
    for (int k = 0; k < 3; ++k) {
      SCOPED_TRACE("seed " + std::to_string(seed) + " state " + std::to_string(k));
      const State s = randomState(m.nr(), rng);
      const VecX vdot = VecX::NullaryExpr(m.nr(), [&] { return randomVec(rng, 3.0)[0]; });
      VecX tau_sb, tau_core;
      sb_engine.calcGeneralizedForces(0.0, s.q, s.qdot, vdot, {}, tau_sb);
      core_engine.calcGeneralizedForces(0.0, s.q, s.qdot, vdot, {}, tau_core);
      // the muscles' share in the core's convention, then conjugate to u on marked joints
      VecX tau_mus;
      try {
        tau_mus = coreMuscleTau(m, term, core_engine.lastState(), core_engine.lastQddot());
      } catch (const MuscleError&) {
        continue;
      }
      for (int j = 0; j < m.nb(); ++j) {
        if (!opt.marked(j)) continue;
        const JointSlot& slot = m.joints()[j];
        MatJ T;
        osim::calcOpenSimSpeedMap(slot.joint, s.q.segment(slot.q_index, slot.nq),
                                  core_engine.lastState().qdot.segment(slot.q_index, slot.nq), T, nullptr);
        tau_mus.segment(slot.q_index, slot.nq) =
            T.transpose().partialPivLu().solve(VecJ(tau_mus.segment(slot.q_index, slot.nq)));
      }
      EXPECT_TRUE(closeToPeak(tau_sb, VecX(tau_core + tau_mus), kTol));
      // the muscles' share must be visible at the tolerance, else the skeleton alone would pass
      EXPECT_GT(tau_mus.cwiseAbs().maxCoeff(), 1e3 * kTol * VecX(tau_core + tau_mus).cwiseAbs().maxCoeff());
      ++compared;
    }
  }
  EXPECT_GT(marked_total, 0) << "no Ball/Free joint in the random trees: the test proves nothing";
  // every state skipped (a degenerate path) would compare nothing
  EXPECT_GE(compared, 6);
}

// a path that degenerates (origin and insertion at the same spot: link1's end is link2's origin) is
// a frame the engine cannot solve: IdEngineError naming the muscle, no crash
TEST(SimbodyIdEngineMuscles, DegeneratePathIsAnEngineError) {
  const Model m = scenes::doublePendulum();
  Muscle mu;
  mu.name = "collapsed";
  mu.path.points = {makeFixedPoint(0, Vec3(0, -1, 0)), makeFixedPoint(1, Vec3::Zero())};
  mu.mass_points = makeMassPoints({0.5}, {0.1});
  simbody::SimbodyIdEngine engine(makeMusculoskeletalModel(m, {mu}));
  VecX tau;
  try {
    engine.calcGeneralizedForces(0.25, Vec2(0.1, 0.2), Vec2::Zero(), Vec2::Zero(), {}, tau);
    ADD_FAILURE() << "no error";
  } catch (const osim::IdEngineError& e) {
    EXPECT_NE(std::string(e.what()).find("collapsed"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// engines on the project's scenes and on set F

std::string scenePath(const std::string& file) { return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + file; }

// engine with muscles vs the core's System + MuscleTerm, at random states with q within the
// coordinates' ranges; returns how many states were compared
int compareEngines(const osim::ModelDescription& d, const Model& model, const std::vector<Muscle>& muscles,
                   int states, std::uint32_t seed, const std::function<void(const State&)>& on_state = {}) {
  simbody::SimbodyIdEngine with(makeMusculoskeletalModel(model, muscles)), without(model);
  System sys(model);
  sys.addTerm(std::make_shared<MuscleTerm>(model, muscles));
  DynamicsWorkspace ws(sys.model());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int compared = 0;
  for (int k = 0; k < states; ++k) {
    SCOPED_TRACE("state " + std::to_string(k));
    State s;
    s.q.resize(model.nr());
    for (int c = 0; c < model.nr(); ++c) {
      const auto& cd = d.coordinates[c];
      const double lo = std::max(cd.range_min, -1.5), hi = std::min(cd.range_max, 1.5);
      s.q[c] = lo + (hi - lo) * u(rng);
    }
    s.qdot = VecX::NullaryExpr(model.nr(), [&] { return 4.0 * (u(rng) - 0.5); });
    const VecX qddot = VecX::NullaryExpr(model.nr(), [&] { return 20.0 * (u(rng) - 0.5); });
    VecX tau_sb, tau_plain;
    with.calcGeneralizedForces(s.t, s.q, s.qdot, qddot, {}, tau_sb);
    without.calcGeneralizedForces(s.t, s.q, s.qdot, qddot, {}, tau_plain);
    const VecX tau_core = sys.inverseDynamics(s, qddot, ws);
    EXPECT_TRUE(closeToPeak(tau_sb, tau_core, kTol));
    if (on_state) on_state(s);
    // the muscles matter at this state (else the comparison above proves little)
    EXPECT_GT((tau_sb - tau_plain).cwiseAbs().maxCoeff(), 1e-4 * tau_core.cwiseAbs().maxCoeff());
    ++compared;
  }
  return compared;
}

// every muscle gets `mass` kg over 10 points (Type III directly: addMusclePointMasses refuses them)
std::vector<Muscle> withMass(const std::vector<Muscle>& muscles, double mass) {
  std::vector<double> masses;
  for (const Muscle& mu : muscles) masses.push_back(pathType(mu.path) == PathType::III ? 0.0 : mass);
  MassPointOptions opt;
  opt.count = 10;
  std::vector<Muscle> out = osim::addMusclePointMasses(muscles, masses, opt);
  for (Muscle& mu : out)
    if (pathType(mu.path) == PathType::III)
      mu.mass_points = makeMassPoints(mass, mu.optimal_fiber_length, mu.tendon_slack_length, opt);
  return out;
}

TEST(SimbodyIdEngineMuscles, MatchesCoreOnProjectScenes) {
  struct Scene {
    const char* file;
    double mass;
  };
  for (const Scene& sc : {Scene{"double_pendulum_straight.osim", 0.5}, Scene{"double_pendulum_via.osim", 0.5},
                          Scene{"double_pendulum_wrap.osim", 0.5}, Scene{"finger.osim", 0.2},
                          Scene{"running_leg.osim", 0.4}}) {
    SCOPED_TRACE(sc.file);
    const osim::ModelDescription d = osim::readOsimModel(scenePath(sc.file));
    osim::BuildOptions bo;
    bo.simbody_compat = true;  // CustomJoints: Simbody's velocity terms (model_to_simbody.hpp)
    bo.constraints = false;
    const osim::BuildResult r = osim::buildCoreModel(d, bo);
    const std::vector<Muscle> muscles = withMass(r.model.muscles(), sc.mass);
    EXPECT_EQ(compareEngines(d, r.model, muscles, 6, 5), 6);
  }
}

// the wrapped segments of `mu` at state s (core kinematics): how many have a straight line that
// penetrates their surface, i.e. really wrap
int wrappedSegments(const Model& model, const Muscle& mu, const State& s) {
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  std::vector<int> active;
  std::vector<Vec3> x;
  for (int k = 0; k < static_cast<int>(mu.path.points.size()); ++k) {
    const PathPoint& p = mu.path.points[k];
    if (!isPathPointActive(p, s.q)) continue;
    Vec3 x_b, dx, ddx;
    calcPointLocation(p, s.q, x_b, dx, ddx);
    active.push_back(k);
    x.push_back(p.body < 0 ? x_b : Vec3((sk.E_wi[p.body] * x_b.homogeneous()).head<3>()));
  }
  const std::vector<int> seg_wrap = calcSegmentWraps(mu, active, x, sk.E_wi);
  int n = 0;
  for (size_t i = 0; i < seg_wrap.size(); ++i) {
    if (seg_wrap[i] < 0) continue;
    const PathWrap& pw = mu.path.wraps[seg_wrap[i]];
    const Mat4 E_ws = pw.body >= 0 ? Mat4(sk.E_wi[pw.body] * pw.E_bs) : pw.E_bs;
    const Mat3 Rt = E_ws.topLeftCorner<3, 3>().transpose();
    const Vec3 p = E_ws.topRightCorner<3, 1>();
    if (calcWrapPenetration(pw.surface, Rt * (x[i] - p), Rt * (x[i + 1] - p)) > 0.0) ++n;
  }
  return n;
}

// general Type III in Simbody: osim_models/double_pendulum_wrap_via.osim (origin, via point, cylinder
// on the via -> insertion segment), as authored, with its via point conditional on q2 and with a
// moving insertion; the engine with muscles against the core at random states (1e-9 of the peak),
// and the cylinder wraps at some of them
TEST(SimbodyIdEngineMuscles, ViaPointAndWrapMatchCoreOnWrapViaPendulum) {
  const osim::ModelDescription d = osim::readOsimModel(scenePath("double_pendulum_wrap_via.osim"));
  osim::BuildOptions bo;
  bo.constraints = false;
  const osim::BuildResult r = osim::buildCoreModel(d, bo);
  const Model& m = r.model;
  int gastroc = -1;
  for (size_t k = 0; k < r.model.muscles().size(); ++k)
    if (r.model.muscles()[k].name == "gastroc_like") gastroc = static_cast<int>(k);
  ASSERT_GE(gastroc, 0);
  ASSERT_EQ(r.model.muscles()[gastroc].path.points.size(), 3u);
  ASSERT_EQ(r.model.muscles()[gastroc].path.wraps.size(), 1u);
  const int q2 = 1;
  for (int variant = 0; variant < 3; ++variant) {
    SCOPED_TRACE(variant == 0 ? "as authored" : variant == 1 ? "conditional via point" : "moving insertion");
    std::vector<Muscle> muscles = r.model.muscles();
    auto& pts = muscles[gastroc].path.points;
    if (variant == 1) {
      const PathPoint& via = pts[1];
      pts[1] = makeConditionalPoint(via.body, via.location, q2, -0.4, 0.6, via.name);
    }
    if (variant == 2) {
      const PathPoint& ins = pts[2];
      auto line = std::make_shared<LinearFunction>(0.02, ins.location.x());
      auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{ins.location.y(), 0.01, -0.02, 0.01});
      pts[2] = makeMovingPoint(ins.body, q2, {line, cubic, nullptr}, Vec3::Zero(), ins.name);
    }
    for (Muscle& mu : muscles) validateMuscle(m, mu);
    const std::vector<Muscle> massive = withMass(muscles, 0.5);
    int wrapped = 0, via_off = 0;
    const int n = compareEngines(d, m, massive, 16, 23 + variant, [&](const State& s) {
      wrapped += wrappedSegments(m, massive[gastroc], s) > 0 ? 1 : 0;
      via_off += isPathPointActive(massive[gastroc].path.points[1], s.q) ? 0 : 1;
    });
    EXPECT_EQ(n, 16);
    std::printf("  [variant %d] %d of 16 states wrap the cylinder, %d with the via point off\n", variant, wrapped,
                via_off);
    EXPECT_GE(wrapped, 3);
    if (variant == 1) {
      EXPECT_GE(via_off, 3);
    }
  }
}

// two wraps on different segments: origin -> (surface 0) -> middle point -> (surface 1) ->
// insertion on random trees, each surface centred near its segment at the state (radius 0.03 m,
// 0.012 m off the line: the path wraps), on random bodies or the world; the middle point fixed (0),
// moving (1), conditional and on (2) or off (3, then neither range holds a segment); the cylinder
// and the sphere swap with the trial; smooth model. Component vs core to 1e-9 of the peak, energies.
Muscle randomTwoWrapMuscle(const Model& m, int variant, std::mt19937& rng, const State& s, bool swap) {
  Muscle mu;
  mu.name = "two_wraps" + std::to_string(variant);
  auto& pts = mu.path.points;
  pts.push_back(makeFixedPoint(randomBody(m, rng, true), randomVec(rng, 0.3)));
  const int bm = randomBody(m, rng, false);
  const int c = static_cast<int>(rng() % m.nr());
  if (variant == 1) {
    auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.05, -0.1, 0.2, 0.1});
    auto line = std::make_shared<LinearFunction>(0.3, 0.2);
    pts.push_back(makeMovingPoint(bm, c, {cubic, nullptr, line}, Vec3(0, 0.1, 0)));
  } else if (variant >= 2) {
    const double lo = variant == 2 ? s.q[c] - 0.3 : s.q[c] + 1.0;
    pts.push_back(makeConditionalPoint(bm, randomVec(rng, 0.3), c, lo, lo + 0.6));
  } else {
    pts.push_back(makeFixedPoint(bm, randomVec(rng, 0.3)));
  }
  pts.push_back(makeFixedPoint(randomBody(m, rng, false), randomVec(rng, 0.3)));
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  for (int w = 0; w < 2; ++w) {
    const int body = randomBody(m, rng, true);
    PathWrap pw = wrapAcross(worldPoint(pts[w], s, sk), worldPoint(pts[w + 1], s, sk), body, (w == 1) != swap, sk, rng);
    pw.range_begin = w + 1;  // OpenSim's 1-based point range: the segment (w, w + 1)
    pw.range_end = w + 2;
    mu.path.wraps.push_back(pw);
  }
  mu.path.num_wraps = 2;
  giveMass(mu, 8);
  return mu;
}

TEST(SimbodyMuscleInertia, TwoWrapsMatchCoreMuscleTermOnRandomTrees) {
  int both_wrapped = 0;
  const int checked = compareOnRandomTrees(
      false, 4242, 4, 3,
      [](const Model& m, int variant, int trial, const State& s, std::mt19937& rng) {
        std::vector<Muscle> muscles{randomTwoWrapMuscle(m, variant, rng, s, trial % 2 == 1),
                                    randomWrapMuscle(m, 0, rng, s, false)};
        EXPECT_EQ(simbody::simbodyWrapShapeUnsupportedReason(muscles[0]), "");
        return muscles;
      },
      [&](const Model& m, const std::vector<Muscle>& muscles, const State& s, int variant) {
        if (variant <= 2 && wrappedSegments(m, muscles[0], s) == 2) ++both_wrapped;
      });
  std::printf("  %d states compared, %d with both surfaces wrapping\n", checked, both_wrapped);
  EXPECT_GE(checked, 18);
  EXPECT_GE(both_wrapped, 8);
}

// the exact wrap model beyond origin -> surface -> insertion: OpenSim's whole wrapped path, which
// the Simbody side differentiates in the path map's inputs (points, surface frames) and the core in
// q. Shapes (variant): 0 origin -> via -> (surface) -> via -> insertion; 1 the same with two
// surfaces on that segment (OpenSim applies them in turn and iterates); 2 two surfaces on
// different segments with a fixed middle point; 3 the same with the middle point conditional and
// on. Both sides take differences (the core: J with a step of 1e-6 in q, Jdot with a mixed stencil
// of 1e-5), so they agree to those differences' error, not to round-off: kExactTol of the peak.
// Where the smooth model takes the path (0, 2, 3; every random state here is outside its blend
// band or the surface is not in contact) its analytic J and Jdot give the same path: the Simbody
// side agrees with that to kExactVsSmoothTol, the core's exact model (a wider stencil in q) less
// closely. Two surfaces on one segment (1): kSameSegmentTol (one state sits near a kink of
// OpenSim's iteration, where path_map.cpp's bias stencil shrinks and is noisier).
constexpr double kExactTol = 5e-6, kExactVsSmoothTol = 3e-7, kSameSegmentTol = 2e-5;

Muscle randomViaWrapViaMuscle(const Model& m, std::mt19937& rng, const State& s, bool two_surfaces) {
  Muscle mu;
  mu.name = two_surfaces ? "via_two_wraps_via" : "via_wrap_via";
  auto& pts = mu.path.points;
  pts.push_back(makeFixedPoint(randomBody(m, rng, true), randomVec(rng, 0.3)));
  for (int k = 0; k < 3; ++k) pts.push_back(makeFixedPoint(randomBody(m, rng, false), randomVec(rng, 0.3)));
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  const Vec3 a = worldPoint(pts[1], s, sk), b = worldPoint(pts[2], s, sk);
  std::vector<std::pair<Vec3, Vec3>> spans{{a, b}};
  if (two_surfaces) spans = {{a, 0.5 * (a + b)}, {0.5 * (a + b), b}};  // centred at a quarter and three quarters
  for (size_t w = 0; w < spans.size(); ++w) {
    PathWrap pw = wrapAcross(spans[w].first, spans[w].second, randomBody(m, rng, true), w == 1, sk, rng);
    pw.name += std::to_string(w);
    pw.range_begin = 2;  // the segment (1, 2): between the two via points
    pw.range_end = 3;
    mu.path.wraps.push_back(pw);
  }
  mu.path.num_wraps = static_cast<int>(mu.path.wraps.size());
  giveMass(mu, 8);
  mu.wrap.model = WrapModel::Exact;
  return mu;
}

TEST(SimbodyMuscleInertia, ExactModelOnLongerPathsMatchesCoreMuscleTerm) {
  using scenes::TreeJoints;
  struct Case {
    Model model;
    simbody::SphericalAs spherical;
  };
  const std::vector<Case> cases{{scenes::randomTree(6, 11, TreeJoints::SimbodyComparable), simbody::SphericalAs::Gimbal},
                                {scenes::randomTree(8, 29, TreeJoints::SimbodyComparable), simbody::SphericalAs::Ball}};
  std::mt19937 rng(515);
  double worst_smooth = 0.0, worst_core = 0.0, worst_same_segment = 0.0;
  int compared = 0, same_segment = 0, wrapped = 0;
  for (const Case& c : cases) {
    const Model& m = c.model;
    simbody::SimbodyBuildOptions opt;
    opt.spherical = c.spherical;
    const auto sm = simbody::makeSimbodyModel(m, opt);
    for (int variant = 0; variant < 4; ++variant) {
      for (int trial = 0; trial < 3; ++trial) {
        SCOPED_TRACE("variant " + std::to_string(variant) + " trial " + std::to_string(trial));
        const State s = randomState(m.nr(), rng);
        Muscle mu = variant <= 1 ? randomViaWrapViaMuscle(m, rng, s, variant == 1)
                                 : randomTwoWrapMuscle(m, variant == 2 ? 0 : 2, rng, s, trial % 2 == 1);
        mu.wrap.model = WrapModel::Exact;
        std::vector<Muscle> muscles{mu, randomMuscle(m, 1, rng, s)};
        for (Muscle& x : muscles) validateMuscle(m, x);
        EXPECT_EQ(simbody::simbodyWrapShapeUnsupportedReason(muscles[0]), "");
        const VecX qddot = VecX::NullaryExpr(m.nr(), [&] { return randomVec(rng, 3.0)[0]; });
        VecX core;
        try {
          core = coreMuscleTau(m, MuscleTerm(m, muscles), s, qddot);
        } catch (const MuscleError&) {
          continue;
        }
        simbody::MuscleInertia mi(*sm, makeMusculoskeletalModel(m, muscles));
        const VecX sb = simbodyMuscleTau(*sm, mi, m, s, qddot);
        const double peak = core.cwiseAbs().maxCoeff(), d_core = (sb - core).cwiseAbs().maxCoeff() / peak;
        std::vector<Mat4> E_wi;
        calcBodyPoses(m, s.q, E_wi);
        const WrappedPath wp = calcWrappedPath(m, muscles[0].path, s.q, E_wi);
        wrapped += std::count(wp.used.begin(), wp.used.end(), true) > 0 ? 1 : 0;
        ++compared;
        if (variant == 1) {
          // two surfaces on one segment: no smooth reference; OpenSim's passes make the path
          // piecewise smooth at a fine scale (path_map.cpp shrinks its bias stencil at a kink)
          ++same_segment;
          worst_same_segment = std::max(worst_same_segment, d_core);
          EXPECT_LT(d_core, kSameSegmentTol);
          continue;
        }
        // the smooth model's analytic map on the same path: the exact path outside its blend band
        std::vector<Muscle> smooth = muscles;
        for (Muscle& x : smooth) x.wrap.model = WrapModel::Smooth;
        const VecX ref = coreMuscleTau(m, MuscleTerm(m, smooth), s, qddot);
        worst_smooth = std::max(worst_smooth, (sb - ref).cwiseAbs().maxCoeff() / peak);
        worst_core = std::max(worst_core, d_core);
        EXPECT_LT((sb - ref).cwiseAbs().maxCoeff(), kExactVsSmoothTol * peak);
        EXPECT_LT(d_core, kExactTol);
      }
    }
  }
  std::printf("  %d states (%d with a surface in the path); vs the core's smooth model %.2e, vs the core's exact "
              "model %.2e of the peak; two surfaces on one segment %.2e (%d states)\n",
              compared, wrapped, worst_smooth, worst_core, worst_same_segment, same_segment);
  EXPECT_GE(compared, 20);
  EXPECT_GE(wrapped, 16);
  EXPECT_GE(same_segment, 4);
}

// CPU time per inverse-dynamics call (printed, not asserted): Simbody with and without the muscles,
// and the core with them
void printIdCost(const Model& model, const std::vector<Muscle>& muscles) {
  simbody::SimbodyIdEngine with(makeMusculoskeletalModel(model, muscles)), without(model);
  System sys(model);
  sys.addTerm(std::make_shared<MuscleTerm>(model, muscles));
  DynamicsWorkspace ws(sys.model());
  std::mt19937 rng(3);
  const State s = randomState(model.nr(), rng);
  const VecX qddot = VecX::Constant(model.nr(), 0.5);
  VecX tau;
  const int n = 300;
  auto time = [&](auto&& f) {
    const std::clock_t t0 = std::clock();
    for (int k = 0; k < n; ++k) f();
    return 1e6 * double(std::clock() - t0) / CLOCKS_PER_SEC / n;
  };
  const double t_with = time([&] { with.calcGeneralizedForces(0.0, s.q, s.qdot, qddot, {}, tau); });
  const double t_without = time([&] { without.calcGeneralizedForces(0.0, s.q, s.qdot, qddot, {}, tau); });
  const double t_core = time([&] { tau = sys.inverseDynamics(s, qddot, ws); });
  int points = 0;
  for (const Muscle& mu : muscles) points += mu.mass_points.size();
  std::printf("  ID per call (%d mass points): simbody %.1f us with muscles, %.1f us without; core %.1f us with muscles\n",
              points, t_with, t_without, t_core);
}

// set F: gait10dof18musc (OpenSim's 2017 copy), with 20% and 80% of tibia_r's mass moved into the
// muscles that span it (converter/build/muscle_mass.hpp), CustomJoints in Simbody-compatible form
TEST(SimbodyIdEngineMuscles, MatchesCoreOnSetFWithTibiaTransfer) {
  const std::string file = std::string(REDMAX_SHARED_DIR) +
                           "/opensim/opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim";
  if (!std::filesystem::exists(file))
    GTEST_SKIP() << "shared OpenSim data not found at " << file << "; this test needs set F's model";
  const osim::ModelDescription d = osim::readOsimModel(file);
  osim::BuildOptions bo;
  bo.simbody_compat = true;
  bo.constraints = false;
  for (double fraction : {0.2, 0.8}) {
    SCOPED_TRACE("tibia_r transfer " + std::to_string(fraction));
    osim::MuscleMassOptions mo;
    mo.source = osim::MuscleMassOptions::Source::Transfer;
    mo.transfer_body = "tibia_r";
    mo.transfer_fraction = fraction;
    const osim::MuscleMassModel mm = osim::applyMuscleMass(d, bo, mo);
    ASSERT_GT(mm.plan.total_muscle_mass, 0.0);
    EXPECT_EQ(compareEngines(mm.description, mm.build.model, mm.build.model.muscles(), 8, 17), 8);
    if (fraction == 0.8) printIdCost(mm.build.model, mm.build.model.muscles());
  }
}

}  // namespace
}  // namespace redmax
