// Type III mass points (core/muscles/wrap_muscle.hpp): the chain rule through a wrap surface on a
// moving body [D Eq. 5.39-5.57] checked by central differences, the smooth model against the exact
// library away from the contact band, validation of the supported shape, and the dissertation's
// energy experiment (Sec. 6.2.5): the wrapping double pendulum with the smooth model conserves energy
// to integrator error, with the exact library and finite-difference Jacobians it jumps at contact
// changes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/dynamics/muscle_term.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/spatial/se3.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

constexpr double kRadius = 0.08;
constexpr double kWidth = 0.05 * kRadius;  // the smooth model's default band

bool nearRel(const MatX& A, const MatX& B, double tol) { return (A - B).norm() <= tol * (1.0 + B.norm()); }

// the wrapping double pendulum of osim_models/double_pendulum_wrap.osim on the code-built pendulum:
// cylinder (quadrant -x) centred on the middle joint, origin on link 1, insertion on link 2, both
// 0.1 m on the -x side and 0.4 m from the joint; 1 kg muscle (as heavy as a link), 20 points
Muscle pendulumWrapMuscle(WrapModel model, double mass = 1.0) {
  Muscle mu;
  mu.name = "wrap_muscle";
  mu.path.points = {makeFixedPoint(0, Vec3(-0.1, -0.6, 0), "origin"), makeFixedPoint(1, Vec3(-0.1, -0.4, 0), "insertion")};
  PathWrap w;
  w.name = "joint_cylinder";
  w.surface = WrapSurface::makeCylinder(kRadius, 0.2, 0, -1);
  w.body = 0;
  w.E_bs = makeTranslation(Vec3(0, -1, 0));
  mu.path.wraps = {w};
  mu.path.num_wraps = 1;
  mu.optimal_fiber_length = 0.5;
  mu.tendon_slack_length = 0.3;
  mu.mass_points = makeMassPoints(mass, 0.5, 0.3);
  mu.wrap.model = model;
  return mu;
}

// end points in the surface frame and the penetration, at state s
double penetrationAt(const Model& m, const Muscle& mu, const State& s) {
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  MuscleKinematics mk;
  initMuscleKinematics(m, mu.path, mk);
  calcPathPoints(m, s, sk, mu.path, mk, false);
  const PathWrap& w = mu.path.wraps[0];
  const Mat4 E_sw = inverseE(w.body >= 0 ? Mat4(sk.E_wi[w.body] * w.E_bs) : w.E_bs);
  return calcWrapPenetration(w.surface, transformPoint(E_sw, mk.x_w[0]), transformPoint(E_sw, mk.x_w[1]));
}

// central differences of x_a in q (J_ar) and of J_ar along qdot (Jdot_ar), all nr columns
void checkAgainstFd(const Model& m, const Muscle& mu, const State& s, double tol, const char* what) {
  const double h = 1e-6;
  const MuscleKinematics mk = test::evalMuscle(m, mu, s);
  const MatX J_fd = test::calcJarFd(m, mu, s, h);
  EXPECT_TRUE(nearRel(mk.J_ar, J_fd, tol)) << what << ": J_ar vs x_a, |diff| " << (mk.J_ar - J_fd).norm()
                                           << " |J| " << J_fd.norm();
  const MatX Jdot_fd = test::calcJdotArFd(m, mu, s, h);
  EXPECT_TRUE(nearRel(mk.Jdot_ar, Jdot_fd, tol)) << what << ": Jdot_ar vs J_ar, |diff| " << (mk.Jdot_ar - Jdot_fd).norm()
                                                 << " |Jdot| " << Jdot_fd.norm();
}

TEST(WrapMuscle, PendulumJacobiansMatchCentralDifferences) {
  const Model m = scenes::doublePendulum();
  const Muscle mu = pendulumWrapMuscle(WrapModel::Smooth);
  validateMuscle(m, mu);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int straight = 0, band = 0, wrapped = 0;
  for (int trial = 0; trial < 60; ++trial) {
    State s;
    s.q = Vec2(u(rng), 0.2 + 0.5 * u(rng));  // q2 in [-0.3, 0.7]: no forced wrap round the quadrant
    s.qdot = Vec2(2 * u(rng), 2 * u(rng));
    const double d = penetrationAt(m, mu, s);
    // away from the band edges, where the smooth model is only C2 (third derivatives jump)
    if (std::abs(d) < 1e-4 * kRadius || std::abs(d - kWidth) < 1e-4 * kRadius) continue;
    (d <= 0 ? straight : d < kWidth ? band : wrapped)++;
    checkAgainstFd(m, mu, s, 1e-6, d <= 0 ? "straight" : d < kWidth ? "band" : "wrapped");
  }
  EXPECT_GE(straight, 10);
  EXPECT_GE(wrapped, 10);
  // the band is narrow (d in (0, 0.004 m)): sample it on purpose, q2 just past the contact
  int in_band = 0;
  for (double q2 = 0.0; q2 < 0.3; q2 += 0.002) {
    State s;
    s.q = Vec2(0.3, q2);
    s.qdot = Vec2(-0.7, 1.3);
    const double d = penetrationAt(m, mu, s);
    if (!(d > 0.1 * kWidth && d < 0.9 * kWidth)) continue;
    ++in_band;
    checkAgainstFd(m, mu, s, 1e-6, "band sweep");
  }
  std::printf("pendulum: %d straight, %d in the band, %d wrapped random configurations; %d in the band sweep\n",
              straight, band, wrapped, in_band);
  EXPECT_GE(in_band, 1);
}

// a 3-D chain (joint axes z, x, y; links 0.5 m): surfaces on the middle link between the end points'
// links, and on link 2, which moves neither end point (origin on link 0, insertion on link 1), so
// its coordinate must join the muscle's columns; rotated surfaces
Muscle chainMuscle(const WrapSurface& surface, int wrap_body, int ori_body, int ins_body, const Vec3& x_bs,
                   WrapModel model) {
  Muscle mu;
  mu.name = "chain";
  mu.path.points = {makeFixedPoint(ori_body, Vec3(0.35, -0.25, 0.05)), makeFixedPoint(ins_body, Vec3(-0.3, -0.4, -0.05))};
  PathWrap w;
  w.name = "surf";
  w.surface = surface;
  w.body = wrap_body;
  w.E_bs = makeE(expSO3(Vec3(0.3, -0.2, 0.1)), x_bs);
  mu.path.wraps = {w};
  mu.path.num_wraps = 1;
  mu.mass_points = makeMassPoints(0.3, 0.5, 0.2, {7});
  mu.wrap.model = model;
  return mu;
}

TEST(WrapMuscle, SurfaceOnAnotherBodyJacobiansMatchCentralDifferences) {
  const Model m = scenes::revoluteChain(3);
  std::mt19937 rng(11);
  struct Case {
    WrapSurface surface;
    int wrap_body, ori_body, ins_body;
    Vec3 x_bs;
  };
  const Case cases[] = {{WrapSurface::makeCylinder(0.1, 2.0), 1, 0, 2, Vec3(0.02, -0.3, 0.01)},
                        {WrapSurface::makeSphere(0.12), 1, 0, 2, Vec3(0.02, -0.3, 0.01)},
                        {WrapSurface::makeCylinder(0.1, 2.0), 2, 0, 1, Vec3(0.03, 0.42, 0.01)},
                        {WrapSurface::makeSphere(0.12), 2, 0, 1, Vec3(0.03, 0.42, 0.01)}};
  for (const Case& c : cases) {
    const Muscle mu = chainMuscle(c.surface, c.wrap_body, c.ori_body, c.ins_body, c.x_bs, WrapModel::Smooth);
    validateMuscle(m, mu);
    // the columns cover the surface's body (all three coordinates here)
    const MuscleKinematics mk0 = [&] {
      SkeletonWorkspace sk(m);
      State s = test::randomState(m.nr(), rng);
      calcKinematics(m, s, sk);
      MuscleWorkspace ws(m, {mu});
      calcMuscleKinematics(m, s, sk, mu, ws.muscles[0]);
      return ws.muscles[0];
    }();
    EXPECT_EQ(mk0.cols.size(), 3u);
    int n_wrapped = 0, n_straight = 0;
    for (int trial = 0; trial < 400 && (n_wrapped < 6 || n_straight < 6); ++trial) {
      const State s = test::randomState(m.nr(), rng, 1.2, 2.0);
      const double width = 0.05 * c.surface.radius;
      double d;
      try {
        d = penetrationAt(m, mu, s);
        test::evalMuscle(m, mu, s);  // end points inside the surface throw
      } catch (const MuscleError&) {
        continue;
      }
      if (std::abs(d) < 1e-3 * width || std::abs(d - width) < 1e-3 * width) continue;
      if (d > 0 && n_wrapped >= 6) continue;
      if (d <= 0 && n_straight >= 6) continue;
      (d > 0 ? n_wrapped : n_straight)++;
      checkAgainstFd(m, mu, s, 1e-6, c.surface.type == WrapType::Cylinder ? "chain cylinder" : "chain sphere");
    }
    EXPECT_GE(n_wrapped, 3) << "wrap body " << c.wrap_body << ", type " << int(c.surface.type);
    EXPECT_GE(n_straight, 3) << "wrap body " << c.wrap_body << ", type " << int(c.surface.type);
  }
}

TEST(WrapMuscle, SmoothEqualsExactLibraryOutsideTheBand) {
  // positions: the smooth model is the exact library for d <= 0 and d >= width; its J equals the
  // exact library's finite-difference J there (1e-5: the FD's own truncation and round-off)
  const Model m = scenes::doublePendulum();
  const Muscle smooth = pendulumWrapMuscle(WrapModel::Smooth), exact = pendulumWrapMuscle(WrapModel::Exact);
  validateMuscle(m, exact);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int n = 0;
  for (int trial = 0; trial < 40; ++trial) {
    State s;
    s.q = Vec2(u(rng), 0.2 + 0.5 * u(rng));
    s.qdot = Vec2(2 * u(rng), 2 * u(rng));
    const double d = penetrationAt(m, smooth, s);
    if (std::abs(d) < 1e-2 * kRadius || (d > 0 && d < kWidth + 1e-2 * kRadius)) continue;
    const MuscleKinematics a = test::evalMuscle(m, smooth, s), b = test::evalMuscle(m, exact, s);
    for (int k = 0; k < smooth.mass_points.size(); ++k) EXPECT_LT((a.x_a[k] - b.x_a[k]).norm(), 1e-12);
    EXPECT_TRUE(nearRel(b.J_ar, a.J_ar, 1e-5)) << "d " << d << " |diff| " << (b.J_ar - a.J_ar).norm();
    EXPECT_TRUE(nearRel(b.Jdot_ar, a.Jdot_ar, 1e-4)) << "d " << d << " |diff| " << (b.Jdot_ar - a.Jdot_ar).norm();
    ++n;
  }
  EXPECT_GE(n, 20);
}

TEST(WrapMuscle, ValidationNamesTheUnsupportedShape) {
  const Model m = scenes::doublePendulum();
  auto expectThrow = [&](const Muscle& mu, const std::string& part) {
    try {
      validateMuscle(m, mu);
      ADD_FAILURE() << "accepted: " << part;
    } catch (const ModelError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("wrap_muscle"), std::string::npos) << e.what();
    }
  };
  Muscle three = pendulumWrapMuscle(WrapModel::Smooth);
  three.path.points.insert(three.path.points.begin() + 1, makeFixedPoint(0, Vec3(-0.15, -0.8, 0)));
  EXPECT_NO_THROW(validateMuscle(m, three));  // via points: supported (wrap_path_muscle_test.cpp)
  Muscle two_wraps = pendulumWrapMuscle(WrapModel::Smooth);
  two_wraps.path.wraps.push_back(two_wraps.path.wraps[0]);
  two_wraps.path.num_wraps = 2;
  EXPECT_NO_THROW(validateMuscle(m, two_wraps));  // the smooth model composes them (issue 22)
  Muscle four = two_wraps;  // beyond the composition's three per segment
  four.path.wraps.push_back(four.path.wraps[0]);
  four.path.wraps.push_back(four.path.wraps[0]);
  four.path.num_wraps = 4;
  expectThrow(four, "at most 3 wrap objects on one segment");
  four.wrap.model = WrapModel::Exact;
  EXPECT_NO_THROW(validateMuscle(m, four));
  two_wraps.wrap.model = WrapModel::Exact;  // the exact model composes them as OpenSim does
  EXPECT_NO_THROW(validateMuscle(m, two_wraps));
  Muscle sphere = pendulumWrapMuscle(WrapModel::Smooth);
  sphere.path.wraps[0].surface = WrapSurface::makeSphere(0.1, 0, -1);
  EXPECT_NO_THROW(validateMuscle(m, sphere));  // quadrant spheres: smooth since issue 22
  Muscle flat = pendulumWrapMuscle(WrapModel::Smooth);
  flat.path.wraps[0].surface = WrapSurface::makeSphere(0.0, 0, -1);
  expectThrow(flat, "surface dimensions must be positive");
  Muscle counted = pendulumWrapMuscle(WrapModel::Smooth);
  counted.path.wraps.clear();
  expectThrow(counted, "only counts its wrap objects");
  Muscle range = pendulumWrapMuscle(WrapModel::Smooth);
  range.path.wraps[0].range_begin = range.path.wraps[0].range_end = 2;
  expectThrow(range, "excludes the origin-insertion segment");
  // the exact library takes any surface; massless Type III muscles stay valid whatever the shape
  sphere.wrap.model = WrapModel::Exact;
  EXPECT_NO_THROW(validateMuscle(m, sphere));
  three.mass_points = {};
  EXPECT_NO_THROW(validateMuscle(m, three));
}

TEST(WrapMuscle, EndPointInsideTheSurfaceIsAMuscleError) {
  const Model m = scenes::doublePendulum();
  Muscle mu = pendulumWrapMuscle(WrapModel::Smooth);
  mu.path.points[0].location = Vec3(-0.05, -0.98, 0);  // 0.054 m from the axis, radius 0.08
  State s;
  s.q = Vec2(0.1, 0.3);
  s.qdot = Vec2(0.0, 0.0);
  try {
    test::evalMuscle(m, mu, s);
    ADD_FAILURE() << "no error";
  } catch (const MuscleError& e) {
    EXPECT_NE(std::string(e.what()).find("wrap_muscle"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("inside"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// energy: gravity only, rk45 (rtol = atol = 1e-12), total energy (links + mass points) sampled
// every 10 ms

struct EnergyRun {
  double E0 = 0.0;
  double max_drift = 0.0;         // max |E(t) - E(0)| (J)
  double max_jump = 0.0;          // largest net change across a contact change, |E_{k+2} - E_{k-3}| (J)
  double max_transient = 0.0;     // largest |E_k - E_{k-1}| within 4 samples of a contact change (J)
  double max_change_quiet = 0.0;  // largest |E_k - E_{k-1}| with no contact change within 4 samples (J)
  int contact_changes = 0;        // sign changes of the penetration between samples
  double q2_min = 1e9, q2_max = -1e9;
  double muscle_T_max = 0.0;
  long steps = 0;
};

EnergyRun runPendulum(WrapModel model, double duration) {
  const Model m = scenes::doublePendulum();
  const Muscle mu = pendulumWrapMuscle(model);
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{mu}));
  DynamicsWorkspace ws(m);
  auto energy = [&](const State& s) { return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws); };
  State s = sys.defaultState();
  s.q << 0.3, 0.35;  // released from rest with the muscle wrapped
  s.qdot << 0.0, 0.0;
  IntegratorOptions io;
  io.rtol = 1e-12;
  io.atol = 1e-12;
  auto integ = makeIntegrator("rk45", io);
  EnergyRun r;
  const int n = static_cast<int>(std::lround(duration * 100));
  std::vector<double> E(n + 1), d(n + 1);
  E[0] = r.E0 = energy(s);
  d[0] = penetrationAt(m, mu, s);
  for (int k = 1; k <= n; ++k) {
    integ->advance(sys, s, 0.01 * k);
    E[k] = energy(s);
    d[k] = penetrationAt(m, mu, s);
    r.max_drift = std::max(r.max_drift, std::abs(E[k] - r.E0));
    r.q2_min = std::min(r.q2_min, s.q[1]);
    r.q2_max = std::max(r.q2_max, s.q[1]);
    r.muscle_T_max = std::max(r.muscle_T_max, muscleKineticEnergy(mu.mass_points, test::evalMuscle(m, mu, s), s.qdot));
  }
  r.steps = integ->stats().steps;
  // contact changes between samples, and the energy around them
  std::vector<char> change(n + 1, 0);
  for (int k = 1; k <= n; ++k) change[k] = (d[k] > 0) != (d[k - 1] > 0);
  for (int k = 1; k <= n; ++k) {
    if (!change[k]) continue;
    ++r.contact_changes;
    if (k >= 3 && k + 2 <= n) r.max_jump = std::max(r.max_jump, std::abs(E[k + 2] - E[k - 3]));
  }
  for (int k = 1; k <= n; ++k) {
    bool near = false;
    for (int j = std::max(1, k - 4); j <= std::min(n, k + 4); ++j) near = near || change[j];
    double& c = near ? r.max_transient : r.max_change_quiet;
    c = std::max(c, std::abs(E[k] - E[k - 1]));
  }
  return r;
}

TEST(WrapMuscle, PendulumEnergySmoothConservedExactJumpsAtContactChanges) {
  const double duration = 3.0;
  const EnergyRun sm = runPendulum(WrapModel::Smooth, duration);
  const EnergyRun ex = runPendulum(WrapModel::Exact, duration);
  std::printf("wrapping pendulum, %.0f s rk45 (rtol = atol = 1e-12), E0 %.4f J, q2 in [%.3f, %.3f], muscle T max %.3f J:\n"
              "  smooth:   drift %.3e J, %d contact changes, %ld steps\n"
              "  exact+FD: drift %.3e J, net change across a contact change up to %.3e J (transient %.3e J), "
              "largest 10 ms change away from contact changes %.3e J, %d contact changes, %ld steps\n",
              duration, sm.E0, sm.q2_min, sm.q2_max, sm.muscle_T_max, sm.max_drift, sm.contact_changes, sm.steps,
              ex.max_drift, ex.max_jump, ex.max_transient, ex.max_change_quiet, ex.contact_changes, ex.steps);
  ::testing::Test::RecordProperty("smooth_drift_J", std::to_string(sm.max_drift));
  ::testing::Test::RecordProperty("exact_fd_jump_J", std::to_string(ex.max_jump));
  // the run must cross the contact change several times, stay out of the forced-wrap regime of the
  // quadrant (q2 < 0.7) and give the muscle real kinetic energy
  EXPECT_GE(sm.contact_changes, 4);
  EXPECT_GE(ex.contact_changes, 4);
  EXPECT_LT(std::max(sm.q2_max, ex.q2_max), 0.7);
  EXPECT_GT(sm.muscle_T_max, 1e-2);
  // smooth: integrator error only (measured 7e-11 J of |E0| = 27.6 J)
  EXPECT_LE(sm.max_drift, 1e-9);
  // exact + FD: conserved between contact changes as tightly, jumps across them (measured 3.6e-5 to
  // 2.5e-4 J)
  EXPECT_LE(ex.max_change_quiet, 1e-8);
  EXPECT_GE(ex.max_jump, 1e4 * sm.max_drift);
  EXPECT_GE(ex.max_jump, 1e-5);
}

}  // namespace
}  // namespace redmax
