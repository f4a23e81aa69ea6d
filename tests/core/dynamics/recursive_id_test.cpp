// Recursive inverse dynamics (System::inverseDynamicsRecursive, core/muscles/muscle_inverse_dynamics)
// against the REDMAX route tau = M qddot - f (System::inverseDynamics), which stays the reference:
//   - bare skeletons with external point forces and torques: equal to round-off;
//   - Type I and Type II muscles (via, moving and conditional points) with mass: the path-wise
//     mass-point pass equals the mass-matrix route to round-off;
//   - without the quadratic velocity vector (compact-J route) the same;
//   - the routes of the terms: Type I/II muscles need no J_mr (TermIdRoute::Wrenches).
// Measured worst differences 2e-16 to 7e-16 of |tau|; bound 5e-15.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "tests/core/dynamics/random_muscle.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

ExternalLoads randomLoads(const Model& m, std::mt19937& rng) {
  ExternalLoads l;
  for (int k = 0; k < 3; ++k) {
    const int b = static_cast<int>(rng() % static_cast<unsigned>(m.nb()));
    l.point_forces.push_back({b, test::randomVec(rng, 0.3), test::randomVec(rng, 50.0)});
    l.wrenches.push_back({b, test::randomVec(rng, 5.0), test::randomVec(rng, 20.0)});
  }
  return l;
}

// largest |tau_recursive - tau_M| / max(1, |tau_M|_inf) over random states of `sys`
double worstRelative(const System& sys, std::mt19937& rng, bool loads, int trials = 6) {
  const Model& m = sys.model();
  DynamicsWorkspace wa(sys), wb(sys);
  double worst = 0.0;
  VecX tr;
  for (int t = 0; t < trials; ++t) {
    const State s = test::randomState(m.nr(), rng);
    const VecX qddot = test::randomState(m.nr(), rng).qdot;
    if (loads) wa.loads = wb.loads = randomLoads(m, rng);
    const VecX tm = sys.inverseDynamics(s, qddot, wa);
    sys.inverseDynamicsRecursive(s, qddot, wb, tr);
    worst = std::max(worst, (tr - tm).lpNorm<Eigen::Infinity>() / std::max(1.0, tm.lpNorm<Eigen::Infinity>()));
  }
  return worst;
}

TEST(RecursiveId, BareSkeletonWithLoadsEqualsTheMassMatrixRoute) {
  std::mt19937 rng(11);
  double worst = 0.0;
  for (int seed = 0; seed < 4; ++seed) {
    const System sys(scenes::randomTree(9, 500 + seed, scenes::TreeJoints::All));
    worst = std::max(worst, worstRelative(sys, rng, true));
  }
  EXPECT_LE(worst, 5e-15);
  std::printf("[ measured ] bare trees with loads: recursive vs M route, worst %.2e of |tau|\n", worst);
}

TEST(RecursiveId, MusclesWithMassEqualTheMassMatrixRoute) {
  std::mt19937 rng(7);
  double worst = 0.0, effect = 0.0;
  for (int seed = 0; seed < 4; ++seed) {
    const Model m = scenes::randomTree(8, 600 + seed, scenes::TreeJoints::All);
    std::vector<Muscle> muscles = {test::straightMuscle(m, rng, 0.8), test::conditionalMuscle(m, rng, 1.5)};
    for (int k = 0; k < 3; ++k) muscles.push_back(test::randomViaMuscle(m, rng, 0.5 + k, "via" + std::to_string(k)));
    System sys(m);
    auto term = std::make_shared<MuscleTerm>(m, muscles);
    EXPECT_EQ(term->idRoute(), TermIdRoute::Wrenches);
    sys.addTerm(term);
    worst = std::max(worst, worstRelative(sys, rng, seed % 2 == 0));
    // the muscles matter: their share against the bare skeleton's at one state
    const System bare(m);
    DynamicsWorkspace wa(bare), wb(sys);
    const State s = test::randomState(m.nr(), rng);
    const VecX qddot = test::randomState(m.nr(), rng).qdot;
    const VecX t0 = bare.inverseDynamics(s, qddot, wa), t1 = sys.inverseDynamics(s, qddot, wb);
    effect = std::max(effect, (t1 - t0).lpNorm<Eigen::Infinity>() / t1.lpNorm<Eigen::Infinity>());
  }
  EXPECT_LE(worst, 5e-15);
  EXPECT_GT(effect, 1e-2);
  std::printf("[ measured ] Type I/II muscles with mass: recursive vs M route, worst %.2e of |tau| "
              "(muscles' share up to %.1f%% of |tau|)\n", worst, 100 * effect);
}

TEST(RecursiveId, MassPointsInAnyOrderAndOfUnequalMassEqualTheMassMatrixRoute) {
  // the path-wise pass sums the moments of a segment's points as one run when alpha increases
  // (makeMassPoints' order) and point by point otherwise: both against the reference, and the
  // same points in either order against each other
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Model m = scenes::randomTree(7, 701, scenes::TreeJoints::All);
  std::vector<double> alpha(17), mass(17);
  for (size_t a = 0; a < alpha.size(); ++a) {
    alpha[a] = u01(rng);
    mass[a] = 0.05 + 0.3 * u01(rng);
  }
  alpha[3] = 0.0;  // on the origin, and on the insertion
  alpha[9] = 1.0;
  std::vector<size_t> order(alpha.size());
  for (size_t a = 0; a < order.size(); ++a) order[a] = a;
  std::sort(order.begin(), order.end(), [&](size_t i, size_t j) { return alpha[i] < alpha[j]; });
  std::vector<double> alpha_sorted, mass_sorted;
  for (size_t a : order) {
    alpha_sorted.push_back(alpha[a]);
    mass_sorted.push_back(mass[a]);
  }
  Muscle shuffled = test::randomViaMuscle(m, rng, 1.0, "shuffled");
  Muscle sorted = shuffled;
  shuffled.mass_points = makeMassPoints(alpha, mass);
  sorted.mass_points = makeMassPoints(alpha_sorted, mass_sorted);
  ASSERT_FALSE(std::is_sorted(alpha.begin(), alpha.end()));
  System sys_shuffled(m), sys_sorted(m);
  sys_shuffled.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{shuffled}));
  sys_sorted.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{sorted}));
  const double worst = std::max(worstRelative(sys_shuffled, rng, false), worstRelative(sys_sorted, rng, false));
  EXPECT_LE(worst, 5e-15);
  DynamicsWorkspace wa(sys_shuffled), wb(sys_sorted);
  double apart = 0.0;
  VecX ta, tb;
  for (int t = 0; t < 4; ++t) {
    const State s = test::randomState(m.nr(), rng);
    const VecX qddot = test::randomState(m.nr(), rng).qdot;
    sys_shuffled.inverseDynamicsRecursive(s, qddot, wa, ta);
    sys_sorted.inverseDynamicsRecursive(s, qddot, wb, tb);
    apart = std::max(apart, (ta - tb).lpNorm<Eigen::Infinity>() / std::max(1.0, tb.lpNorm<Eigen::Infinity>()));
  }
  // a sweep between two states in 60 small steps, one workspace each: the sorted muscle keeps a
  // segment's run (and its centred moments) while no point crosses a path point and rebuilds it
  // when one does; the shuffled muscle sums point by point every call
  const State s0 = test::randomState(m.nr(), rng), s1 = test::randomState(m.nr(), rng);
  const VecX qddot = test::randomState(m.nr(), rng).qdot;
  double swept = 0.0;
  for (int t = 0; t <= 60; ++t) {
    State s = s0;
    s.q = s0.q + (t / 60.0) * (s1.q - s0.q);
    s.qdot = s0.qdot + (t / 60.0) * (s1.qdot - s0.qdot);
    sys_shuffled.inverseDynamicsRecursive(s, qddot, wa, ta);
    sys_sorted.inverseDynamicsRecursive(s, qddot, wb, tb);
    swept = std::max(swept, (ta - tb).lpNorm<Eigen::Infinity>() / std::max(1.0, tb.lpNorm<Eigen::Infinity>()));
  }
  EXPECT_LE(apart, 5e-15);
  EXPECT_LE(swept, 5e-15);
  std::printf("[ measured ] shuffled, unequal mass points: recursive vs M route worst %.2e, "
              "shuffled vs sorted %.2e of |tau| (random states), %.2e (a sweep of 61 states)\n", worst, apart, swept);
}

TEST(RecursiveId, WithoutTheQuadraticVelocityVectorTheCompactRouteEqualsTheMassMatrixRoute) {
  std::mt19937 rng(3);
  const Model m = scenes::randomTree(6, 77, scenes::TreeJoints::All);
  std::vector<Muscle> muscles = {test::straightMuscle(m, rng, 1.0), test::randomViaMuscle(m, rng, 1.0, "via")};
  System sys(m);
  MuscleTermOptions o;
  o.quadratic_velocity = false;
  auto term = std::make_shared<MuscleTerm>(m, muscles, o);
  EXPECT_EQ(term->idRoute(), TermIdRoute::WrenchesWithKinematics);
  sys.addTerm(term);
  const double worst = worstRelative(sys, rng, true);
  EXPECT_LE(worst, 5e-15);
  std::printf("[ measured ] no QVV (compact J_ar): recursive vs M route, worst %.2e of |tau|\n", worst);
}

}  // namespace
}  // namespace redmax
