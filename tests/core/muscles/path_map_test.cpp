// Path maps (core/muscles/path_map.hpp): mass points as functions of the path points' world
// positions, for Type I and Type II paths with 1-5 via points.
//   x_a(x)        vs the arc-fraction construction written here independently        1e-12
//   J_ax          vs central differences of x_a(x) per point coordinate (h = 1e-6)     1e-6 rel
//   Jdot_ax xdot  vs central differences of J_ax along xdot, times xdot (h = 1e-6)     1e-6 rel
//   accelerations vs second differences of x_a along x(t) = x + t v + t^2/2 a (h = 2e-5) 1e-6 rel
//   consistency with the core: J_ax J_xr == J_ar and Jdot_ax J_xr + J_ax Jdot_xr == Jdot_ar at random
//   states of random trees with fixed, via, moving and conditional points                1e-12 rel
// Relative errors are |a - b| / (1 + |b|) (nearRel).
#include "core/muscles/path_map.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <stdexcept>

#include "core/muscles/muscle_kinematics.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

constexpr double kH = 1e-6;
constexpr double kTol = 1e-6;

std::vector<Vec3> randomPoints(int P, std::mt19937& rng) {
  // a zig-zag along x so that segments keep a length well away from zero
  std::vector<Vec3> x(P);
  for (int i = 0; i < P; ++i) x[i] = Vec3(0.2 * i, 0.0, 0.0) + test::randomVec(rng, 0.08);
  return x;
}

std::vector<Vec3> randomVectors(int P, std::mt19937& rng, double scale) {
  std::vector<Vec3> v(P);
  for (auto& e : v) e = test::randomVec(rng, scale);
  return v;
}

std::vector<Vec3> unstack(const VecX& v) {
  std::vector<Vec3> x(v.size() / 3);
  for (size_t i = 0; i < x.size(); ++i) x[i] = v.segment<3>(3 * static_cast<int>(i));
  return x;
}

// random alphas over [0, 1] (ends included) and the uniform fibre layout, alternately
MassPoints randomMassPoints(std::mt19937& rng, int variant) {
  if (variant % 2 == 0) {
    MassPointOptions opt;
    opt.count = 11;
    opt.region = MassPointOptions::Region::WholePath;
    return makeMassPoints(0.7, 0.3, 0.2, opt);
  }
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> alpha{0.0, 1.0}, mass{0.1, 0.1};
  for (int k = 0; k < 7; ++k) {
    alpha.push_back(u(rng));
    mass.push_back(0.05 + 0.1 * u(rng));
  }
  return makeMassPoints(alpha, mass);
}

VecX positionsAt(const std::vector<Vec3>& x, const MassPoints& mp) {
  PathMap pm;
  calcPathMap(x, nullptr, mp, pm, "fd");
  return stackPoints(pm.x_a);
}

PathMap mapAt(const std::vector<Vec3>& x, const std::vector<Vec3>& v, const MassPoints& mp) {
  PathMap pm;
  calcPathMap(x, &v, mp, pm, "fd");
  return pm;
}

// segments of every mass point at x (to skip stencils that move a point past a via point)
std::vector<int> segmentsAt(const std::vector<Vec3>& x, const MassPoints& mp) {
  PathMap pm;
  calcPathMap(x, nullptr, mp, pm, "fd");
  return pm.mk.segment;
}

class PathMapFd : public ::testing::TestWithParam<int> {};  // parameter: via points (0 = Type I)

TEST_P(PathMapFd, PositionsJacobianAndBiasMatchDifferences) {
  const int nvia = GetParam();
  const int P = nvia + 2;
  std::mt19937 rng(1000 + nvia);
  int checked = 0;
  for (int trial = 0; trial < 6; ++trial) {
    SCOPED_TRACE(trial);
    const std::vector<Vec3> x = randomPoints(P, rng);
    const std::vector<Vec3> v = randomVectors(P, rng, 1.5);
    const std::vector<Vec3> acc = randomVectors(P, rng, 3.0);
    const MassPoints mp = randomMassPoints(rng, trial);
    const int N = mp.size();
    const VecX xs = stackPoints(x), vs = stackPoints(v), as = stackPoints(acc);
    const PathMap pm = mapAt(x, v, mp);
    ASSERT_EQ(pm.J_ax.rows(), 3 * N);
    ASSERT_EQ(pm.J_ax.cols(), 3 * P);

    // positions: the point at arc fraction alpha of the polyline, computed independently
    for (int a = 0; a < N; ++a)
      EXPECT_TRUE(nearRel(pm.x_a[a], test::pointAtArcFraction(x, mp.alpha[a]), 1e-12)) << "point " << a;

    // a mass point sitting on a via point changes segment inside the stencil: skip such draws
    const std::vector<int> seg = pm.mk.segment;
    const auto sameSegments = [&](const VecX& y) { return segmentsAt(unstack(y), mp) == seg; };

    // J_ax column by column
    MatX J_fd(3 * N, 3 * P);
    bool ok = true;
    for (int c = 0; c < 3 * P && ok; ++c) {
      VecX xp = xs, xm = xs;
      xp[c] += kH;
      xm[c] -= kH;
      ok = sameSegments(xp) && sameSegments(xm);
      J_fd.col(c) = (positionsAt(unstack(xp), mp) - positionsAt(unstack(xm), mp)) / (2 * kH);
    }
    if (!ok || !sameSegments(xs + kH * vs) || !sameSegments(xs - kH * vs)) continue;
    ++checked;
    EXPECT_TRUE(nearRel(pm.J_ax, J_fd, kTol)) << "J_ax\n" << pm.J_ax << "\nfd\n" << J_fd;

    // Jdot_ax along xdot, and the bias Jdot_ax xdot
    const PathMap pp = mapAt(unstack(xs + kH * vs), v, mp), pmn = mapAt(unstack(xs - kH * vs), v, mp);
    const MatX Jdot_fd = (pp.J_ax - pmn.J_ax) / (2 * kH);
    EXPECT_TRUE(nearRel(pm.Jdot_ax, Jdot_fd, kTol));
    EXPECT_TRUE(nearRel(pm.Jdot_ax_xdot, VecX(Jdot_fd * vs), kTol));

    // accelerations along x(t) = x + t v + t^2/2 a, second differences (h = 2e-5: O(h^2) truncation, round-off 1e-16 / h^2)
    const double h = 2e-5;
    const auto path = [&](double t) { return unstack(xs + t * vs + 0.5 * t * t * as); };
    const VecX a_fd = (positionsAt(path(h), mp) - 2.0 * positionsAt(path(0.0), mp) + positionsAt(path(-h), mp)) / (h * h);
    if (!sameSegments(stackPoints(path(h))) || !sameSegments(stackPoints(path(-h)))) continue;
    const VecX a_an = calcMassPointAccelerations(pm, as);
    EXPECT_TRUE(nearRel(a_an, a_fd, kTol)) << (a_an - a_fd).norm() << " of " << a_fd.norm();
  }
  EXPECT_GE(checked, 4) << "too many draws had a mass point on a via point";
}

INSTANTIATE_TEST_SUITE_P(TypesIAndII, PathMapFd, ::testing::Values(0, 1, 2, 3, 4, 5),
                         [](const ::testing::TestParamInfo<int>& i) { return std::to_string(i.param) + "_via_points"; });

TEST(PathMap, BadInputThrows) {
  const MassPoints mp = makeMassPoints({0.5}, {1.0});
  PathMap pm;
  EXPECT_THROW(calcPathMap({Vec3::Zero()}, nullptr, mp, pm), std::invalid_argument);
  const std::vector<Vec3> x{Vec3::Zero(), Vec3::UnitX()};
  const std::vector<Vec3> v{Vec3::Zero()};
  EXPECT_THROW(calcPathMap(x, &v, mp, pm), std::invalid_argument);
  EXPECT_THROW(calcPathMap(x, nullptr, MassPoints{}, pm), std::invalid_argument);
  // coincident ends (Type I) and a zero-length segment (Type II) are MuscleErrors naming the muscle
  try {
    calcPathMap({Vec3::Zero(), Vec3::Zero()}, nullptr, mp, pm, "degenerate");
    ADD_FAILURE() << "no throw";
  } catch (const MuscleError& e) {
    EXPECT_NE(std::string(e.what()).find("degenerate"), std::string::npos);
  }
  EXPECT_THROW(calcPathMap({Vec3::Zero(), Vec3::UnitX(), Vec3::UnitX()}, nullptr, mp, pm), MuscleError);
  // no velocity stage: no accelerations
  calcPathMap(x, nullptr, mp, pm);
  EXPECT_THROW(calcMassPointAccelerations(pm, VecX::Zero(6)), std::logic_error);
}

// -------------------------------------------------------------------------------------------
// consistency with the core's J_ar on random trees

int randomBody(const Model& m, std::mt19937& rng, bool allow_world) {
  const int lo = allow_world ? -1 : 0;
  return lo + static_cast<int>(rng() % static_cast<unsigned>(m.nb() - lo));
}

// 0-5 fixed via points; variant 6 adds moving points, 7 conditional points (one active at s)
Muscle randomMuscle(const Model& m, int variant, std::mt19937& rng, const State& s) {
  Muscle mu;
  mu.name = "random" + std::to_string(variant);
  auto& pts = mu.path.points;
  pts.push_back(makeFixedPoint(randomBody(m, rng, true), test::randomVec(rng, 0.3)));
  const int nvia = variant <= 5 ? variant : 1;
  for (int k = 0; k < nvia; ++k) pts.push_back(makeFixedPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3)));
  const int c = static_cast<int>(rng() % m.nr());
  if (variant == 6) {
    auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.05, -0.1, 0.2, 0.1});
    auto line = std::make_shared<LinearFunction>(0.3, 0.2);
    pts.push_back(makeMovingPoint(randomBody(m, rng, false), c, {cubic, nullptr, line}, Vec3(0, 0.1, 0)));
    pts.push_back(makeMovingPoint(-1, static_cast<int>(rng() % m.nr()), {line, cubic, nullptr}, Vec3(0, 0, 0.2)));
  }
  if (variant == 7) {
    pts.push_back(makeConditionalPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3), c, s.q[c] - 0.3, s.q[c] + 0.3));
    pts.push_back(makeConditionalPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3), c, s.q[c] + 1.0, s.q[c] + 2.0));
  }
  pts.push_back(makeFixedPoint(randomBody(m, rng, false), test::randomVec(rng, 0.3)));
  MassPointOptions opt;
  opt.count = 8;
  mu.mass_points = makeMassPoints(0.9, 0.5, 0.3, opt);
  mu.optimal_fiber_length = 0.5;
  mu.tendon_slack_length = 0.3;
  validateMuscle(m, mu);
  return mu;
}

TEST(PathMap, FactorsTheCoreMuscleJacobian) {
  using scenes::TreeJoints;
  const std::vector<Model> models{scenes::randomTree(6, 11, TreeJoints::SimbodyComparable),
                                  scenes::randomTree(8, 37, TreeJoints::All), scenes::doublePendulum()};
  std::mt19937 rng(7);
  double worst = 0.0;
  int checked = 0;
  for (size_t mi = 0; mi < models.size(); ++mi) {
    const Model& m = models[mi];
    for (int variant = 0; variant <= 7; ++variant) {
      for (int trial = 0; trial < 3; ++trial) {
        SCOPED_TRACE("model " + std::to_string(mi) + " variant " + std::to_string(variant));
        const State s = test::randomState(m.nr(), rng);
        const Muscle mu = randomMuscle(m, variant, rng, s);
        MuscleKinematics mk;
        try {
          mk = test::evalMuscle(m, mu, s);
        } catch (const MuscleError&) {
          continue;  // two random points coincided (a via point on the origin's body at the same spot)
        }
        PathMap pm;
        calcPathMap(mk.x_w, &mk.xdot_w, mu.mass_points, pm, mu.name);
        const MatX J_ar = pm.J_ax * mk.J_xr;
        const MatX Jdot_ar = pm.Jdot_ax * mk.J_xr + pm.J_ax * mk.Jdot_xr;
        EXPECT_TRUE(nearRel(J_ar, mk.J_ar, 1e-12));
        EXPECT_TRUE(nearRel(Jdot_ar, mk.Jdot_ar, 1e-12));
        EXPECT_TRUE(nearRel(stackPoints(pm.x_a), stackPoints(mk.x_a), 1e-12));
        // the bias the Simbody plugin uses: Jdot_ax xdot + J_ax Jdot_xr qdot == Jdot_ar qdot
        EXPECT_TRUE(nearRel(VecX(pm.Jdot_ax_xdot + pm.J_ax * mk.Jdot_xr * s.qdot), VecX(mk.Jdot_ar * s.qdot), 1e-12));
        worst = std::max(worst, (J_ar - mk.J_ar).norm() / (1.0 + mk.J_ar.norm()));
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 60);
  RecordProperty("worst_rel_J_ar", std::to_string(worst));
}

}  // namespace
}  // namespace redmax
