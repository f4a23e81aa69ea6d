// Type III mass points on general paths (core/muscles/wrap_muscle.hpp): via points and wraps over
// segments of a longer path. J_ar and Jdot_ar against central differences on a knee-like scene
// (origin and via point on the thigh, cylinder at the knee, insertion on the shank) and on a 3-D
// chain with two wraps on different segments; the smooth model's points lie on the exact library's
// whole wrapped path (wrap_path.hpp) at the same arc fraction outside the band; the exact model
// (differences in q over OpenSim's path) agrees with the smooth chain rule there; validation of
// shapes; and energy of the knee-like pendulum under gravity (smooth model: integrator error).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/dynamics/muscle_term.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/spatial/se3.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

constexpr double kKneeRadius = 0.08;

bool nearRel(const MatX& A, const MatX& B, double tol) { return (A - B).norm() <= tol * (1.0 + B.norm()); }

// knee-like: the double pendulum (links 1 m, joints about z), origin and via point behind the
// thigh, a quadrant -x cylinder at the knee (range over the whole path: either segment may take
// it), insertion behind the shank; the via -> insertion segment wraps when the knee flexes
Muscle kneeMuscle(WrapModel model, double mass = 1.0) {
  Muscle mu;
  mu.name = "gastroc_like";
  mu.path.points = {makeFixedPoint(0, Vec3(-0.1, -0.3, 0), "origin"), makeFixedPoint(0, Vec3(-0.11, -0.7, 0.0), "via"),
                    makeFixedPoint(1, Vec3(-0.1, -0.4, 0), "insertion")};
  PathWrap w;
  w.name = "knee_cylinder";
  w.surface = WrapSurface::makeCylinder(kKneeRadius, 0.2, 0, -1);
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

// a 3-D chain (revoluteChain(3): axes z, x, y, links 0.5 m): origin on link 0, via point on link 1,
// insertion on link 2; a cylinder (axis along x) at joint 1 on link 0 acts on the first segment
// (range 1-2), a sphere at joint 2 on link 1 on the second (range 2-3)
Muscle chainTwoWrapMuscle(WrapModel model) {
  Muscle mu;
  mu.name = "two_wraps";
  mu.path.points = {makeFixedPoint(0, Vec3(0.01, -0.15, 0.06), "origin"), makeFixedPoint(1, Vec3(-0.01, -0.2, 0.06), "via"),
                    makeFixedPoint(2, Vec3(0.02, -0.2, 0.06), "insertion")};
  PathWrap c;
  c.name = "cyl_joint1";
  c.surface = WrapSurface::makeCylinder(0.03, 0.3);
  c.body = 0;
  c.E_bs = makeE(expSO3(Vec3(0, 0.5 * M_PI, 0)), Vec3(0, -0.5, 0.035));  // local z along x
  c.range_begin = 1;
  c.range_end = 2;
  PathWrap s;
  s.name = "sphere_joint2";
  s.surface = WrapSurface::makeSphere(0.03);
  s.body = 1;
  s.E_bs = makeTranslation(Vec3(0, -0.5, 0.04));
  s.range_begin = 2;
  s.range_end = 3;
  mu.path.wraps = {c, s};
  mu.path.num_wraps = 2;
  mu.optimal_fiber_length = 0.4;
  mu.tendon_slack_length = 0.2;
  mu.mass_points = makeMassPoints(0.5, 0.4, 0.2, {15, MassPointOptions::Region::WholePath});
  mu.wrap.model = model;
  return mu;
}

// penetration of segment i's straight line into wrap w (frame s), at state s
double segmentPenetration(const Model& m, const Muscle& mu, const State& st, int w, int i) {
  SkeletonWorkspace sk(m);
  calcKinematics(m, st, sk);
  MuscleKinematics mk;
  initMuscleKinematics(m, mu.path, mk);
  calcPathPoints(m, st, sk, mu.path, mk, false);
  const PathWrap& pw = mu.path.wraps[w];
  const Mat4 E_sw = inverseE(pw.body >= 0 ? Mat4(sk.E_wi[pw.body] * pw.E_bs) : pw.E_bs);
  return calcWrapPenetration(pw.surface, transformPoint(E_sw, mk.x_w[i]), transformPoint(E_sw, mk.x_w[i + 1]));
}

// central differences of x_a in q (J_ar) and of J_ar along qdot (Jdot_ar), all nr columns
void checkAgainstFd(const Model& m, const Muscle& mu, const State& s, double tol, const std::string& what) {
  const double h = 1e-6;
  const MuscleKinematics mk = test::evalMuscle(m, mu, s);
  const MatX J_fd = test::calcJarFd(m, mu, s, h);
  EXPECT_TRUE(nearRel(mk.J_ar, J_fd, tol)) << what << ": J_ar vs x_a, |diff| " << (mk.J_ar - J_fd).norm() << " |J| "
                                           << J_fd.norm();
  const MatX Jdot_fd = test::calcJdotArFd(m, mu, s, h);
  EXPECT_TRUE(nearRel(mk.Jdot_ar, Jdot_fd, tol)) << what << ": Jdot_ar vs J_ar, |diff| " << (mk.Jdot_ar - Jdot_fd).norm()
                                                 << " |Jdot| " << Jdot_fd.norm();
}

// the exact library's whole wrapped path at each mass point's alpha (world)
std::vector<Vec3> exactPathPoints(const Model& m, const Muscle& mu, const State& s) {
  std::vector<Mat4> E_wi;
  calcBodyPoses(m, s.q, E_wi);
  const WrappedPath wp = calcWrappedPath(m, mu.path, s.q, E_wi);
  std::vector<Vec3> xs;
  for (double a : mu.mass_points.alpha) xs.push_back(calcWrappedPathPointWorld(mu.path, wp, E_wi, a));
  return xs;
}

// band classification of a penetration d for band width `width`: 0 straight, 1 band, 2 wrapped,
// -1 too close to a band edge (the smooth model is C2 there, third derivatives jump)
int classify(double d, double width) {
  if (std::abs(d) < 1e-4 * width || std::abs(d - width) < 1e-4 * width) return -1;
  return d <= 0 ? 0 : d < width ? 1 : 2;
}

TEST(WrapPathMuscle, ViaPointAndWrapJacobiansMatchCentralDifferences) {
  const Model m = scenes::doublePendulum();
  const Muscle mu = kneeMuscle(WrapModel::Smooth);
  validateMuscle(m, mu);
  const double width = 0.05 * kKneeRadius;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int count[3] = {0, 0, 0};
  for (int trial = 0; trial < 60; ++trial) {
    State s;
    s.q = Vec2(u(rng), 0.2 + 0.5 * u(rng));
    s.qdot = Vec2(2 * u(rng), 2 * u(rng));
    const int c = classify(segmentPenetration(m, mu, s, 0, 1), width);
    if (c < 0) continue;
    ++count[c];
    checkAgainstFd(m, mu, s, 1e-6, c == 0 ? "straight" : c == 1 ? "band" : "wrapped");
  }
  int in_band = 0;
  for (double q2 = 0.0; q2 < 0.4; q2 += 0.002) {
    State s;
    s.q = Vec2(0.3, q2);
    s.qdot = Vec2(-0.7, 1.3);
    const double d = segmentPenetration(m, mu, s, 0, 1);
    if (!(d > 0.1 * width && d < 0.9 * width)) continue;
    ++in_band;
    checkAgainstFd(m, mu, s, 1e-6, "band sweep");
  }
  std::printf("[ measured ] knee-like via + wrap: %d straight, %d band, %d wrapped random states; %d in the band sweep\n",
              count[0], count[1], count[2], in_band);
  EXPECT_GE(count[0], 5);
  EXPECT_GE(count[2], 5);
  EXPECT_GE(in_band, 1);
}

// the knee muscle with a conditional point on the thigh (active for knee angle q2 in [-0.5, 0.25])
// and the via point moving with the knee, x_b = (-0.11 + 0.02 q2^2, -0.7 + 0.03 q2, 0)
Muscle kneeMovingMuscle(WrapModel model) {
  Muscle mu = kneeMuscle(model);
  mu.path.points[1] = makeMovingPoint(0, 1,
                                      {std::make_shared<PolynomialFunction>(std::vector<double>{0.02, 0.0, -0.11}),
                                       std::make_shared<PolynomialFunction>(std::vector<double>{0.03, -0.7}), nullptr},
                                      Vec3::Zero(), "moving_via");
  mu.path.points.insert(mu.path.points.begin() + 1,
                        makeConditionalPoint(0, Vec3(-0.105, -0.5, 0.01), 1, -0.5, 0.25, "conditional"));
  return mu;
}

TEST(WrapPathMuscle, ConditionalAndMovingPointsWithWrapJacobiansMatchCentralDifferences) {
  const Model m = scenes::doublePendulum();
  const Muscle mu = kneeMovingMuscle(WrapModel::Smooth);
  validateMuscle(m, mu);
  const double width = 0.05 * kKneeRadius;
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int count[3] = {0, 0, 0}, active = 0;
  for (int trial = 0; trial < 60; ++trial) {
    State s;
    s.q = Vec2(u(rng), 0.2 + 0.5 * u(rng));
    s.qdot = Vec2(2 * u(rng), 2 * u(rng));
    if (std::abs(s.q[1] - 0.25) < 1e-3) continue;  // the conditional point switches there
    const bool cond = s.q[1] <= 0.25 + kConditionalTolerance;
    const int c = classify(segmentPenetration(m, mu, s, 0, cond ? 2 : 1), width);
    if (c < 0) continue;
    ++count[c];
    active += cond;
    checkAgainstFd(m, mu, s, 1e-6, std::string(c == 0 ? "straight" : c == 1 ? "band" : "wrapped") +
                                       (cond ? ", conditional active" : ""));
  }
  std::printf("[ measured ] knee-like with conditional + moving points: %d straight, %d band, %d wrapped; conditional "
              "point active in %d\n",
              count[0], count[1], count[2], active);
  EXPECT_GE(count[0], 5);
  EXPECT_GE(count[2], 5);
  EXPECT_GE(active, 5);
}

TEST(WrapPathMuscle, WithoutContactEqualsTheTypeIIConstruction) {
  // while the straight line misses the surface the wrap model is the straight segment, so the
  // segment construction must reproduce via_point.hpp's EOL (its own J_sx = -L^-1 DeltaS DeltaXbar)
  const Model m = scenes::doublePendulum();
  for (const Muscle& mu : {kneeMuscle(WrapModel::Smooth), kneeMovingMuscle(WrapModel::Smooth)}) {
    Muscle plain = mu;
    plain.path.wraps.clear();
    plain.path.num_wraps = 0;
    std::mt19937 rng(43);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int n = 0;
    for (int trial = 0; trial < 60; ++trial) {
      State s;
      s.q = Vec2(u(rng), 0.2 + 0.5 * u(rng));
      s.qdot = Vec2(2 * u(rng), 2 * u(rng));
      const MuscleKinematics mk0 = test::evalMuscle(m, plain, s);
      const int P = static_cast<int>(mk0.x_w.size());
      if (!(segmentPenetration(m, mu, s, 0, P - 2) < 0.0)) continue;
      ++n;
      const MuscleKinematics mk = test::evalMuscle(m, mu, s);
      for (int a = 0; a < mu.mass_points.size(); ++a) EXPECT_LT((mk.x_a[a] - mk0.x_a[a]).norm(), 1e-14);
      EXPECT_TRUE(nearRel(mk.J_ar, mk0.J_ar, 1e-12)) << (mk.J_ar - mk0.J_ar).norm();
      EXPECT_TRUE(nearRel(mk.Jdot_ar, mk0.Jdot_ar, 1e-12)) << (mk.Jdot_ar - mk0.Jdot_ar).norm();
    }
    EXPECT_GE(n, 10) << mu.path.points.size();
  }
}

TEST(WrapPathMuscle, TwoWrapsOnDifferentSegmentsJacobiansMatchCentralDifferences) {
  const Model m = scenes::revoluteChain(3);
  const Muscle mu = chainTwoWrapMuscle(WrapModel::Smooth);
  validateMuscle(m, mu);
  std::mt19937 rng(23);
  int both = 0, one = 0, none = 0;
  for (int trial = 0; trial < 80; ++trial) {
    const State s = test::randomState(m.nr(), rng, 1.2, 2.0);
    const int c0 = classify(segmentPenetration(m, mu, s, 0, 0), 0.05 * 0.03);
    const int c1 = classify(segmentPenetration(m, mu, s, 1, 1), 0.05 * 0.03);
    if (c0 < 0 || c1 < 0) continue;
    const int wrapped = (c0 > 0) + (c1 > 0);
    (wrapped == 2 ? both : wrapped == 1 ? one : none)++;
    checkAgainstFd(m, mu, s, 1e-6, "chain, wraps in contact: " + std::to_string(wrapped));
  }
  std::printf("[ measured ] chain with two wraps: %d states with both wrapping, %d with one, %d with none\n", both, one,
              none);
  EXPECT_GE(both, 5);
  EXPECT_GE(one, 5);
  EXPECT_GE(none, 3);
}

TEST(WrapPathMuscle, SmoothPointsLieOnTheExactWrappedPathOutsideTheBand) {
  struct Case {
    Model model;
    Muscle muscle;
    std::vector<std::pair<int, int>> wraps;  // (wrap, segment)
    double width;
  };
  std::vector<Case> cases;
  cases.push_back({scenes::doublePendulum(), kneeMuscle(WrapModel::Smooth), {{0, 1}}, 0.05 * kKneeRadius});
  cases.push_back({scenes::revoluteChain(3), chainTwoWrapMuscle(WrapModel::Smooth), {{0, 0}, {1, 1}}, 0.05 * 0.03});
  std::mt19937 rng(29);
  for (const Case& c : cases) {
    int n = 0, wrapped = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 200 && n < 40; ++trial) {
      State s = test::randomState(c.model.nr(), rng, 1.2, 0.0);
      if (c.model.nr() == 2) s.q[1] = 0.2 + 0.5 * s.q[1];
      bool outside = true;
      int in_contact = 0;
      for (auto [w, i] : c.wraps) {
        const double d = segmentPenetration(c.model, c.muscle, s, w, i);
        outside = outside && (d <= 0 || d >= c.width * (1 + 1e-6));
        in_contact += d > 0;
      }
      if (!outside) continue;
      ++n;
      wrapped += in_contact > 0;
      const MuscleKinematics mk = test::evalMuscle(c.model, c.muscle, s, false);
      const std::vector<Vec3> xs = exactPathPoints(c.model, c.muscle, s);
      for (int a = 0; a < c.muscle.mass_points.size(); ++a) worst = std::max(worst, (mk.x_a[a] - xs[a]).norm());
    }
    std::printf("[ measured ] %s: %d states outside the band (%d wrapping), max |x_a - exact path point| %.2e m\n",
                c.muscle.name.c_str(), n, wrapped, worst);
    EXPECT_GE(n, 20);
    EXPECT_GE(wrapped, 5);
    EXPECT_LT(worst, 1e-9) << c.muscle.name;
  }
}

TEST(WrapPathMuscle, ExactModelAgreesWithSmoothChainRuleOutsideTheBand) {
  // two independent routes: the smooth model's analytic chain rule over segments, and the exact
  // model's differences in q over OpenSim's whole wrapped path
  const Model m = scenes::doublePendulum();
  const Muscle smooth = kneeMuscle(WrapModel::Smooth), exact = kneeMuscle(WrapModel::Exact);
  validateMuscle(m, exact);
  const double width = 0.05 * kKneeRadius;
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int n = 0;
  for (int trial = 0; trial < 60; ++trial) {
    State s;
    s.q = Vec2(u(rng), 0.2 + 0.5 * u(rng));
    s.qdot = Vec2(2 * u(rng), 2 * u(rng));
    const double d = segmentPenetration(m, smooth, s, 0, 1);
    if (std::abs(d) < 0.05 * width || (d > 0 && d < 1.05 * width)) continue;  // away from the band
    ++n;
    const MuscleKinematics a = test::evalMuscle(m, smooth, s), b = test::evalMuscle(m, exact, s);
    for (int k = 0; k < smooth.mass_points.size(); ++k) EXPECT_LT((a.x_a[k] - b.x_a[k]).norm(), 1e-12);
    EXPECT_TRUE(nearRel(b.J_ar, a.J_ar, 1e-6)) << "d " << d << " |diff| " << (b.J_ar - a.J_ar).norm();
    EXPECT_TRUE(nearRel(b.Jdot_ar, a.Jdot_ar, 1e-4)) << "d " << d << " |diff| " << (b.Jdot_ar - a.Jdot_ar).norm();
  }
  EXPECT_GE(n, 20);
}

TEST(WrapPathMuscle, ValidationSaysWhichShapesEachModelTakes) {
  const Model m = scenes::doublePendulum();
  // two wraps that can land on one segment: exact composes them (OpenSim's order and passes),
  // smooth by the composition of its surfaces (issue 22, wrap/smooth_composite.hpp)
  Muscle same = kneeMuscle(WrapModel::Smooth);
  PathWrap sphere;
  sphere.name = "knee_sphere";
  sphere.surface = WrapSurface::makeSphere(0.05);
  sphere.body = 1;
  sphere.E_bs = makeTranslation(Vec3(0, 0, 0));
  same.path.wraps.push_back(sphere);
  same.path.num_wraps = 2;
  EXPECT_NO_THROW(validateMuscle(m, same));
  same.wrap.model = WrapModel::Exact;
  EXPECT_NO_THROW(validateMuscle(m, same));
  // disjoint ranges (sharing one point) are different segments: smooth takes them
  same.wrap.model = WrapModel::Smooth;
  same.path.wraps[0].range_begin = 2;
  same.path.wraps[0].range_end = 3;
  same.path.wraps[1].range_begin = 1;
  same.path.wraps[1].range_end = 2;
  EXPECT_NO_THROW(validateMuscle(m, same));
  // a range with no segment
  same.path.wraps[1].range_begin = same.path.wraps[1].range_end = 2;
  EXPECT_THROW(validateMuscle(m, same), ModelError);
}

TEST(WrapPathMuscle, ExactModelWithTwoWrapsOnOneSegmentFollowsTheOpenSimPath) {
  // cylinder at the knee and a sphere on the shank over the same via -> insertion segment: the
  // exact model's points are the whole path's points (wrap_path.hpp), its J the q-derivative of
  // them (central differences with a step 10x the model's, tolerance 1e-5)
  const Model m = scenes::doublePendulum();
  Muscle mu = kneeMuscle(WrapModel::Exact);
  PathWrap sphere;
  sphere.name = "shank_sphere";
  sphere.surface = WrapSurface::makeSphere(0.04);
  sphere.body = 1;
  sphere.E_bs = makeTranslation(Vec3(-0.06, -0.2, 0));
  mu.path.wraps.push_back(sphere);
  mu.path.num_wraps = 2;
  validateMuscle(m, mu);
  std::mt19937 rng(37);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int n = 0, both = 0;
  for (int trial = 0; trial < 30; ++trial) {
    State s;
    s.q = Vec2(u(rng), 0.2 + 0.5 * u(rng));
    s.qdot = Vec2(2 * u(rng), 2 * u(rng));
    std::vector<Mat4> E_wi;
    calcBodyPoses(m, s.q, E_wi);
    const WrappedPath wp = calcWrappedPath(m, mu.path, s.q, E_wi);
    const MuscleKinematics mk = test::evalMuscle(m, mu, s);
    const std::vector<Vec3> xs = exactPathPoints(m, mu, s);
    for (int a = 0; a < mu.mass_points.size(); ++a) EXPECT_LT((mk.x_a[a] - xs[a]).norm(), 1e-15);
    const double h = 1e-5;
    MatX J_fd(3 * mu.mass_points.size(), 2);
    for (int j = 0; j < 2; ++j) {
      State sp = s, sm = s;
      sp.q[j] += h;
      sm.q[j] -= h;
      const std::vector<Vec3> xp = exactPathPoints(m, mu, sp), xm = exactPathPoints(m, mu, sm);
      for (int a = 0; a < mu.mass_points.size(); ++a) J_fd.block<3, 1>(3 * a, j) = (xp[a] - xm[a]) / (2 * h);
    }
    ++n;
    both += wp.used[0] && wp.used[1];
    EXPECT_TRUE(nearRel(mk.J_ar, J_fd, 1e-5)) << "|diff| " << (mk.J_ar - J_fd).norm();
  }
  std::printf("[ measured ] two wraps on one segment (exact): %d states, %d with both surfaces in the path\n", n, both);
  EXPECT_GE(both, 3);
}

// energy: gravity only, rk45 (rtol = atol = 1e-12), 2 s, total energy sampled every 10 ms
struct KneeEnergy {
  double E0 = 0.0, drift = 0.0, T_max = 0.0;
  int contact_changes = 0, via_crossings = 0;
  long steps = 0;
};

KneeEnergy runKnee(const Muscle& mu) {
  const Model m = scenes::doublePendulum();
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{mu}));
  DynamicsWorkspace ws(m);
  auto energy = [&](const State& s) { return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws); };
  // number of mass points beyond the via point (its Eulerian coordinate s_1)
  auto beyond = [&](const State& s) {
    const MuscleKinematics mk = test::evalMuscle(m, mu, s, false);
    int n = 0;
    for (double a : mu.mass_points.alpha) n += a >= mk.s[1];
    return n;
  };
  State s = sys.defaultState();
  s.q << 0.3, 0.35;  // released from rest with the via -> insertion segment wrapped
  s.qdot << 0.0, 0.0;
  IntegratorOptions io;
  io.rtol = 1e-12;
  io.atol = 1e-12;
  auto integ = makeIntegrator("rk45", io);
  KneeEnergy r;
  r.E0 = energy(s);
  double d_prev = segmentPenetration(m, mu, s, 0, 1);
  int beyond_prev = beyond(s);
  for (int k = 1; k <= 200; ++k) {
    integ->advance(sys, s, 0.01 * k);
    r.drift = std::max(r.drift, std::abs(energy(s) - r.E0));
    const double d = segmentPenetration(m, mu, s, 0, 1);
    r.contact_changes += (d > 0) != (d_prev > 0);
    d_prev = d;
    const int b = beyond(s);
    r.via_crossings += std::abs(b - beyond_prev);
    beyond_prev = b;
    r.T_max = std::max(r.T_max, muscleKineticEnergy(mu.mass_points, test::evalMuscle(m, mu, s), s.qdot));
  }
  r.steps = integ->stats().steps;
  return r;
}

TEST(WrapPathMuscle, KneeEnergySmoothConservedToIntegratorError) {
  // (a) 10 points of 0.1 kg at alpha 0.5-0.95, all beyond the via point (s_1 ~ 0.36): they slide
  // over the wrapped segment, its contact changes and tangent points, but never past a corner
  Muscle mu = kneeMuscle(WrapModel::Smooth);
  std::vector<double> alpha, mass;
  for (int k = 0; k < 10; ++k) {
    alpha.push_back(0.5 + 0.05 * k);
    mass.push_back(0.1);
  }
  mu.mass_points = makeMassPoints(alpha, mass);
  const KneeEnergy a = runKnee(mu);
  std::printf("[ measured ] knee-like via + wrap, smooth, points beyond the via point, rk45 1e-12, 2 s: |E| %.3f J, "
              "max drift %.2e J, %d contact changes, muscle T up to %.3f J, %ld steps\n",
              std::abs(a.E0), a.drift, a.contact_changes, a.T_max, a.steps);
  EXPECT_EQ(a.via_crossings, 0);
  EXPECT_GE(a.contact_changes, 2);
  EXPECT_GT(a.T_max, 1e-2);
  EXPECT_LT(a.drift, 1e-8);
  // the exact model on the same points (OpenSim's whole path, J by differences in q): J jumps at the
  // contact changes, so the energy does (the dissertation's motivation for a smooth model)
  mu.wrap.model = WrapModel::Exact;
  const KneeEnergy e = runKnee(mu);
  std::printf("[ measured ] the same with the exact model: max drift %.2e J over %d contact changes, %ld steps\n",
              e.drift, e.contact_changes, e.steps);
  EXPECT_GE(e.contact_changes, 2);
  EXPECT_GT(e.drift, 100.0 * a.drift);
  // (b) the fibre region (20 points) spans the via point: points slide past its corner, where J_ar
  // jumps as in any Type II path (path.hpp), so the energy jumps there whatever the wrap model
  const KneeEnergy b = runKnee(kneeMuscle(WrapModel::Smooth));
  std::printf("[ measured ] the same with 20 fibre points spanning the via point: max drift %.2e J over %d via-point "
              "crossings\n",
              b.drift, b.via_crossings);
  EXPECT_GE(b.via_crossings, 1);
}

}  // namespace
}  // namespace redmax
