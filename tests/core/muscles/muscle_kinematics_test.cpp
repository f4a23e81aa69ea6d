// Finite-difference checks of the whole muscle chain on small models (random trees, a revolute
// chain, the double pendulum) and every path kind: Type I, Type II with 1-5 via points on several
// bodies, moving points, conditional points away from their switches.
//   x_w(q)  vs J_xr qdot,   J_xr vs Jdot_xr,   length vs lengthening speed,
//   x_a(q)  vs J_ar qdot,   J_ar vs Jdot_ar     [D Eq. 5.4-5.5]
// by central differences along qdot (h = 1e-6), relative error <= 1e-6 (nearRel); plus the
// equal-strain property (mass points at arc fraction alpha, 1e-12) and the J_xm J_mr factorisation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>

#include "core/muscles/muscle_kinematics.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using test::along;
using test::evalMuscle;

constexpr double kH = 1e-6;
constexpr double kTol = 1e-6;

enum class Scenario { TypeI, Via1, Via2, Via3, Via4, Via5, Moving, Conditional };

const char* scenarioName(Scenario s) {
  switch (s) {
    case Scenario::TypeI: return "TypeI";
    case Scenario::Via1: return "Via1";
    case Scenario::Via2: return "Via2";
    case Scenario::Via3: return "Via3";
    case Scenario::Via4: return "Via4";
    case Scenario::Via5: return "Via5";
    case Scenario::Moving: return "Moving";
    case Scenario::Conditional: return "Conditional";
  }
  return "?";
}

int randomBody(const Model& m, std::mt19937& rng, bool allow_world) {
  const int lo = allow_world ? -1 : 0;
  return lo + static_cast<int>(rng() % static_cast<unsigned>(m.nb() - lo));
}

// coordinate that moves something (first coordinate if the model has one)
int randomCoordinate(const Model& m, std::mt19937& rng) { return static_cast<int>(rng() % m.nr()); }

Muscle makeScenario(const Model& m, Scenario sc, std::mt19937& rng, const State& s) {
  Muscle mu;
  mu.name = scenarioName(sc);
  auto& pts = mu.path.points;
  pts.push_back(makeFixedPoint(randomBody(m, rng, true), test::randomVec(rng, 0.3), "origin"));
  int nvia = 0;
  switch (sc) {
    case Scenario::TypeI: nvia = 0; break;
    case Scenario::Via1: nvia = 1; break;
    case Scenario::Via2: nvia = 2; break;
    case Scenario::Via3: nvia = 3; break;
    case Scenario::Via4: nvia = 4; break;
    case Scenario::Via5: nvia = 5; break;
    default: nvia = 0;
  }
  for (int k = 0; k < nvia; ++k)
    pts.push_back(makeFixedPoint(randomBody(m, rng, k == 0), test::randomVec(rng, 0.3)));
  if (sc == Scenario::Moving) {
    // moving points: a cubic in x and a spline in y on a body, a world point driven by a coordinate
    const int c1 = randomCoordinate(m, rng), c2 = randomCoordinate(m, rng);
    auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.05, -0.1, 0.2, 0.1});
    auto spline = std::make_shared<NaturalCubicSpline>(std::vector<double>{-2.0, -0.5, 0.3, 1.0, 2.5},
                                                       std::vector<double>{0.1, -0.05, 0.12, 0.2, 0.0});
    auto line = std::make_shared<LinearFunction>(0.3, 0.2);
    pts.push_back(makeMovingPoint(randomBody(m, rng, false), c1, {cubic, spline, nullptr}, Vec3(0, 0, 0.15)));
    pts.push_back(makeFixedPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3)));
    pts.push_back(makeMovingPoint(-1, c2, {line, nullptr, cubic}, Vec3(0, 0.4, 0)));
  }
  if (sc == Scenario::Conditional) {
    // one conditional point active with a wide margin around q, one inactive, one fixed between
    const int c1 = randomCoordinate(m, rng), c2 = randomCoordinate(m, rng);
    pts.push_back(makeConditionalPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3), c1,
                                       s.q[c1] - 0.3, s.q[c1] + 0.4));
    pts.push_back(makeFixedPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3)));
    pts.push_back(makeConditionalPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3), c2,
                                       s.q[c2] + 1.0, s.q[c2] + 2.0));
  }
  pts.push_back(makeFixedPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3), "insertion"));
  const bool whole = rng() % 2 == 0;
  MassPointOptions opt;
  opt.count = 9;
  opt.region = whole ? MassPointOptions::Region::WholePath : MassPointOptions::Region::Fibre;
  mu.mass_points = makeMassPoints(1.3, 0.6, 0.4, opt);
  mu.optimal_fiber_length = 0.6;
  mu.tendon_slack_length = 0.4;
  validateMuscle(m, mu);
  return mu;
}

MatX fdJacobianAlong(const Model& m, const Muscle& mu, const State& s, bool mass_points) {
  const MuscleKinematics kp = evalMuscle(m, mu, along(s, kH), false);
  const MuscleKinematics km = evalMuscle(m, mu, along(s, -kH), false);
  return mass_points ? MatX((kp.J_ar - km.J_ar) / (2 * kH)) : MatX((kp.J_xr - km.J_xr) / (2 * kH));
}

VecX stack(const std::vector<Vec3>& v) {
  VecX x(3 * v.size());
  for (size_t i = 0; i < v.size(); ++i) x.segment<3>(3 * i) = v[i];
  return x;
}

struct Counts {
  int checked = 0;
  int skipped = 0;  // a mass point changed segment inside the difference stencil
  double worst = 0.0;  // largest |a - b| / (1 + |b|) seen, reported as a test property
  void note(double e) { worst = std::max(worst, e); }
};

template <class A, class B>
double relErr(const A& a, const B& b) {
  return (a - b).norm() / (1.0 + b.norm());
}

// every check of the header at one (model, muscle, state)
void checkAll(const Model& m, const Muscle& mu, const State& s, Counts& counts) {
  SCOPED_TRACE(mu.name);
  const MuscleKinematics k = evalMuscle(m, mu, s);
  const MuscleKinematics kp = evalMuscle(m, mu, along(s, kH));
  const MuscleKinematics km = evalMuscle(m, mu, along(s, -kH));
  if (kp.segment != k.segment || km.segment != k.segment || kp.active != k.active || km.active != k.active) {
    ++counts.skipped;
    return;
  }
  ++counts.checked;
  // path points: x_w vs J_xr qdot, J_xr vs Jdot_xr
  const VecX xdot_fd = (stack(kp.x_w) - stack(km.x_w)) / (2 * kH);
  EXPECT_TRUE(nearRel(VecX(k.J_xr * s.qdot), xdot_fd, kTol));
  EXPECT_TRUE(nearRel(stack(k.xdot_w), xdot_fd, kTol));
  EXPECT_TRUE(nearRel(k.Jdot_xr, fdJacobianAlong(m, mu, s, false), kTol));
  // length and lengthening speed
  EXPECT_NEAR(k.lengthening_speed, (kp.length - km.length) / (2 * kH), kTol * (1 + std::abs(k.lengthening_speed)));
  // mass points: x_a vs J_ar qdot, J_ar vs Jdot_ar [D Eq. 5.4-5.5]
  const VecX xadot_fd = (stack(kp.x_a) - stack(km.x_a)) / (2 * kH);
  EXPECT_TRUE(nearRel(VecX(k.J_ar * s.qdot), xadot_fd, kTol))
      << (k.J_ar * s.qdot - xadot_fd).norm() << " vs " << xadot_fd.norm();
  const MatX Jdot_fd = fdJacobianAlong(m, mu, s, true);
  counts.note(relErr(VecX(k.J_ar * s.qdot), xadot_fd));
  counts.note(relErr(k.Jdot_ar, Jdot_fd));
  EXPECT_TRUE(nearRel(k.Jdot_ar, Jdot_fd, kTol)) << (k.Jdot_ar - Jdot_fd).norm() << " vs " << Jdot_fd.norm();
  // equal strain: every mass point sits at arc fraction alpha of the current polyline
  for (int a = 0; a < mu.mass_points.size(); ++a)
    EXPECT_TRUE(nearRel(k.x_a[a], test::pointAtArcFraction(k.x_w, mu.mass_points.alpha[a]), 1e-12));
}

struct ModelCase {
  const char* name;
  Model model;
};

// Two random trees use the Simbody-comparable joints (revolute, prismatic, Euler-angle balls,
// free ...), one every joint type (exponential spherical, composite, spline, function-based ...).
std::vector<ModelCase> models() {
  using scenes::TreeJoints;
  return {{"randomTree6", scenes::randomTree(6, 11, TreeJoints::SimbodyComparable)},
          {"randomTree9", scenes::randomTree(9, 23, TreeJoints::SimbodyComparable)},
          {"randomTreeAll7", scenes::randomTree(7, 31, TreeJoints::All)},
          {"revoluteChain4", scenes::revoluteChain(4)},
          {"doublePendulum", scenes::doublePendulum()}};
}

class MuscleKinematicsFd : public ::testing::TestWithParam<Scenario> {};

TEST_P(MuscleKinematicsFd, JacobiansMatchCentralDifferences) {
  const Scenario sc = GetParam();
  Counts counts;
  for (const ModelCase& mc : models()) {
    SCOPED_TRACE(mc.name);
    if (mc.model.nr() == 0) continue;
    std::mt19937 rng(1000 + static_cast<int>(sc));
    for (int trial = 0; trial < 6; ++trial) {
      const State s = test::randomState(mc.model.nr(), rng);
      const Muscle mu = makeScenario(mc.model, sc, rng, s);
      // keep segments well away from zero length so differences are well conditioned
      const MuscleKinematics k0 = evalMuscle(mc.model, mu, s);
      if (k0.l.minCoeff() < 0.02) continue;
      checkAll(mc.model, mu, s, counts);
    }
  }
  EXPECT_GE(counts.checked, 12) << "too few usable samples (" << counts.skipped << " skipped)";
  RecordProperty("samples", counts.checked);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", counts.worst);
  RecordProperty("worst_mass_point_rel_err", buf);
}

INSTANTIATE_TEST_SUITE_P(Paths, MuscleKinematicsFd,
                         ::testing::Values(Scenario::TypeI, Scenario::Via1, Scenario::Via2, Scenario::Via3,
                                           Scenario::Via4, Scenario::Via5, Scenario::Moving,
                                           Scenario::Conditional),
                         [](const auto& info) { return std::string(scenarioName(info.param)); });

TEST(MuscleKinematics, PointJacobianFactorsThroughMaximalCoordinates) {
  // J_xr = J_xm J_mr with J_xm assembled from the per-point blocks R Gamma(x) [D Eq. 5.37]
  const Model m = scenes::randomTree(7, 5);
  std::mt19937 rng(3);
  const State s = test::randomState(m.nr(), rng);
  const Muscle mu = makeScenario(m, Scenario::Via3, rng, s);
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  const MuscleKinematics k = evalMuscle(m, mu, s);
  const int P = static_cast<int>(k.x_w.size());
  MatX J_xm = MatX::Zero(3 * P, m.nm()), Jdot_xm = MatX::Zero(3 * P, m.nm());
  for (int a = 0; a < P; ++a) {
    const int b = mu.path.points[k.active[a]].body;
    if (b < 0) continue;
    J_xm.block<3, 6>(3 * a, 6 * b) = k.J_xm[a];
    Jdot_xm.block<3, 6>(3 * a, 6 * b) = k.Jdot_xm[a];
  }
  EXPECT_TRUE(nearRel(k.J_xr, MatX(J_xm * sk.J_mr), 1e-14));
  EXPECT_TRUE(nearRel(k.Jdot_xr, MatX(Jdot_xm * sk.J_mr + J_xm * sk.Jdot_mr), 1e-14));
}

TEST(MuscleKinematics, PathLengthFromPosesMatchesWorkspace) {
  const Model m = scenes::randomTree(8, 77);
  std::mt19937 rng(8);
  for (int trial = 0; trial < 5; ++trial) {
    const State s = test::randomState(m.nr(), rng);
    const Muscle mu = makeScenario(m, trial % 2 ? Scenario::Conditional : Scenario::Moving, rng, s);
    std::vector<Mat4> E;
    calcBodyPoses(m, s.q, E);
    const MuscleKinematics k = evalMuscle(m, mu, s);
    EXPECT_NEAR(calcPathLength(m, mu.path, s.q, E), k.length, 1e-13 * (1 + k.length));
    double sum = 0.0;
    for (size_t i = 0; i + 1 < k.x_w.size(); ++i) sum += (k.x_w[i + 1] - k.x_w[i]).norm();
    EXPECT_NEAR(k.length, sum, 1e-14 * (1 + sum));
  }
}

TEST(MuscleKinematics, MovingPointClampFreezesOutsideRange) {
  // outside the clamp range the location is constant, so its Jacobian column vanishes
  const Model m = scenes::doublePendulum();
  Muscle mu;
  mu.name = "clamped";
  auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.05, -0.1, 0.2, 0.1});
  PathPoint mp = makeMovingPoint(1, 1, {cubic, cubic, nullptr});
  mp.clamp = true;
  mp.clamp_lo = -0.5;
  mp.clamp_hi = 0.5;
  mu.path.points = {makeFixedPoint(-1, Vec3(0.2, 0.1, 0)), mp};
  mu.mass_points = makeMassPoints({0.5}, {1.0});
  State s;
  s.q = Vec2(0.3, 0.9);      // q2 beyond the clamp range
  s.qdot = Vec2(0.0, 1.0);   // only q2 moves
  const MuscleKinematics k = evalMuscle(m, mu, s);
  EXPECT_NEAR(k.x_b[1].x(), cubic->value1(0.5), 1e-15);
  // the point still rotates with link2, but its location in link2 does not change
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  MatX Jp(3, m.nr());
  pointJacobian(m, sk, 1, k.x_b[1], Jp);
  EXPECT_TRUE(nearRel(MatX(k.J_xr.middleRows<3>(3)), Jp, 1e-14));
}

}  // namespace
}  // namespace redmax
