// The adjoint's analytic step Jacobians (docs/gradients.md §2.1): formed from the derivatives of
// inverse dynamics (core/dynamics/id_derivatives.hpp) through each integrator's equations.
//   - a linear spring-mass: the gradient equals the closed form of the discrete run to round-off
//     (SpringMass.AnalyticRouteEqualsTheClosedFormToRoundOff in adjoint_test.cpp);
//   - random trees with every joint type, gravity, joint springs and dampers, coordinate limit
//     forces and generalized springs: the gradient against central differences of whole runs and
//     against the differenced route, for euler, bdf1 and sdirk2;
//   - the route is reported, with the parts it takes by local differences (wrapping muscles'
//     mass points, Hill-type muscles, force terms and constraint rows without written derivatives).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "core/adjoint/adjoint.hpp"
#include "core/dynamics/constraints/coordinate_coupler.hpp"
#include "core/dynamics/constraints/point_constraint.hpp"
#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/passive_force_terms.hpp"
#include "../dynamics/constraint_scenes.hpp"
#include "tests/core/dynamics/random_muscle.hpp"
#include "tests/core/adjoint/adjoint_test_util.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "validation/scenes/scenes.hpp"
#include "validation/scenes/wrap_pendulums.hpp"

namespace redmax {
namespace {

using adjoint::Objective;
using adjoint::Problem;
using test::problemFor;

// the analytic route against central differences of whole runs and against the differenced route:
// worst relative errors (fd, route); expects the analytic route to apply
struct RouteErrors {
  double fd = 0.0, route = 0.0;
};
RouteErrors compareRoutes(Problem pr, const Objective& obj, const VecX& p) {
  pr.step_jacobians = "analytic";
  const adjoint::Result ra = adjoint::evaluate(pr, obj, p, true);
  EXPECT_TRUE(ra.analytic_jacobians);
  pr.step_jacobians = "differences";
  const adjoint::Result rd = adjoint::evaluate(pr, obj, p, true);
  EXPECT_FALSE(rd.analytic_jacobians);
  const VecX fd = adjoint::finiteDifferenceGradient(pr, obj, p);
  return {adjoint::worstRelativeError(ra.gradient, fd), adjoint::worstRelativeError(ra.gradient, rd.gradient)};
}

// compareRoutes, printed as "<integrator>, <what>: ...", with the bounds of these tests (the
// analytic route within 1e-9 of whole runs and 2e-9 of the differenced route); with `note`, the
// auto route's text must name it (the parts the analytic route takes by local differences)
void checkRoutes(Problem pr, const Objective& obj, const VecX& p, const std::string& what, const char* note = nullptr) {
  const RouteErrors e = compareRoutes(pr, obj, p);
  if (note) {
    pr.step_jacobians = "auto";
    const std::string text = adjoint::stepJacobiansText(adjoint::evaluate(pr, obj, p, true));
    EXPECT_NE(text.find(note), std::string::npos) << text;
  }
  std::printf("[ measured ] %s, %s: analytic vs whole-run differences %.2e, vs the differenced route %.2e\n",
              pr.integrator.c_str(), what.c_str(), e.fd, e.route);
  EXPECT_LE(e.fd, 1e-9) << what;
  EXPECT_LE(e.route, 2e-9) << what;
}

// the objective of these runs: a point of the last body to a target, and come to rest
Objective pointAndRest(const Model& m) {
  Objective obj;
  obj.points.push_back({m.nb() - 1, Vec3(0.1, -0.2, 0.05), Vec3(0.3, -0.4, 0.2), 1.0});
  obj.speed_weight = 0.1;
  return obj;
}
const VecX kFiveParameters = (VecX(5) << 0.4, -0.3, 0.2, 0.1, 0.5).finished();

class AnalyticJacobians : public ::testing::TestWithParam<std::string> {};

// a random tree with every joint type under gravity, joint springs and dampers, coordinate limit
// forces (the runs cross their transitions) and a generalized spring
std::shared_ptr<System> randomSystem(std::uint32_t seed) {
  ModelBuilder b(scenes::randomTree(5, seed, scenes::TreeJoints::All));
  const Model m0 = b.finalize();
  for (int c = 0; c < m0.nr(); ++c) {
    b.coordinateAt(c).stiffness = 2.0 + 0.5 * c;
    b.coordinateAt(c).damping = 0.05;
  }
  const Model m = b.finalize();
  auto sys = std::make_shared<System>(m);
  std::vector<CoordinateLimitForceTerm::Limit> limits;
  for (int c = 0; c < m.nr(); c += 3) limits.push_back({"l" + std::to_string(c), c, 0.05, -0.05, 30.0, 20.0, 0.5, 0.1});
  sys->addTerm(std::make_shared<CoordinateLimitForceTerm>(m, limits));
  sys->addTerm(std::make_shared<SpringGeneralizedForceTerm>(
      m, std::vector<SpringGeneralizedForceTerm::Spring>{{"s", 1, 4.0, 0.1, 0.2}}));
  return sys;
}

TEST_P(AnalyticJacobians, RandomTreesAgainstCentralDifferencesOfWholeRunsAndTheDifferencedRoute) {
  double worst_fd = 0.0, worst_route = 0.0;
  for (std::uint32_t seed : {3u, 8u}) {
    const auto sys = randomSystem(seed);
    const int n = sys->ndof();
    Problem pr = problemFor(sys, GetParam(), 0.06, 0.004);
    pr.forces = {{0, 0, 2}, {0, 1, 2}, {n / 2, 0, 1}, {n - 1, 0, 1}};
    pr.initial_q = {1, n - 2};
    pr.initial_qdot = {0, n - 1};
    const Objective obj = pointAndRest(sys->model());
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    VecX p(8);
    for (int i = 0; i < 8; ++i) p[i] = u(rng);
    const RouteErrors e = compareRoutes(pr, obj, p);
    worst_fd = std::max(worst_fd, e.fd);
    worst_route = std::max(worst_route, e.route);
  }
  std::printf("[ measured ] %s: analytic vs whole-run differences %.2e, vs the differenced route %.2e\n",
              GetParam().c_str(), worst_fd, worst_route);
  // measured 2.2e-11 .. 3.6e-11 (whole runs' fourth-order differences are the larger error) and
  // 2.0e-10 .. 2.3e-10 (the differenced route's ~1e-10 per step Jacobian entry); the issue asks 1e-6
  EXPECT_LE(worst_fd, 1e-9);
  EXPECT_LE(worst_route, 2e-9);
}

// inertial muscles of Types I and II (a straight one, two through via points with a moving point)
// on a random tree: their mass points in M and f, and in the analytic step Jacobians
TEST_P(AnalyticJacobians, TypeOneAndTwoMusclesWithMassAgainstCentralDifferences) {
  std::mt19937 rng(4);
  const Model m = scenes::randomTree(4, 71, scenes::TreeJoints::SimbodyComparable);
  const int n = m.nr();
  std::vector<Muscle> muscles;
  Muscle mu;
  mu.name = "straight";
  mu.path.points = {makeFixedPoint(-1, Vec3(0.1, 0.2, 0.0)), makeFixedPoint(m.nb() - 1, Vec3(0.05, -0.1, 0.1))};
  mu.mass_points = makeMassPoints(0.6, 0.3, 0.2);
  muscles.push_back(mu);
  for (int k = 0; k < 2; ++k) muscles.push_back(test::randomViaMuscle(m, rng, 0.4, "via" + std::to_string(k)));
  auto sys = std::make_shared<System>(m);
  sys->addTerm(std::make_shared<MuscleTerm>(m, muscles));
  Problem pr = problemFor(sys, GetParam(), 0.05, 0.005);
  pr.forces = {{0, 0, 2}, {0, 1, 2}, {n - 1, 0, 1}};
  pr.initial_q = {1};
  pr.initial_qdot = {0};
  const RouteErrors e = compareRoutes(pr, pointAndRest(m), kFiveParameters);
  std::printf("[ measured ] %s, Type I/II muscles with mass: analytic vs whole-run differences %.2e, vs the "
              "differenced route %.2e\n", GetParam().c_str(), e.fd, e.route);
  // measured 2.7e-11 .. 3.6e-11 and 6.7e-11 .. 1.8e-10 (euler, bdf1, sdirk2)
  EXPECT_LE(e.fd, 1e-9);
  EXPECT_LE(e.route, 2e-9);
}

// inertial muscles of Type III (the smooth wrap model over a cylinder and a sphere on a 3-D chain)
// beside a straight one: their share's derivatives by muscle-local differences inside the analytic
// route (addWrappingMuscleIdDerivatives), which says so
TEST_P(AnalyticJacobians, TypeThreeMusclesWithMassAgainstCentralDifferences) {
  std::mt19937 rng(6);
  const Model m = scenes::revoluteChain(3);
  const std::vector<Muscle> muscles = {
      test::chainWrapMuscle(WrapSurface::makeCylinder(0.08, 0.4), WrapModel::Smooth, "cylinder", 0.8),
      test::chainWrapMuscle(WrapSurface::makeSphere(0.1), WrapModel::Smooth, "sphere", 0.5),
      test::straightMuscle(m, rng, 0.4)};
  auto sys = std::make_shared<System>(m);
  sys->addTerm(std::make_shared<MuscleTerm>(m, muscles));
  Problem pr = problemFor(sys, GetParam(), 0.05, 0.005);
  // a start at which both paths wrap (the first of a fixed sequence of random poses)
  std::mt19937 poses(11);
  auto wraps = [&](const State& s, int k) { return test::offStraightLine(test::evalMuscle(m, muscles[k], s)) > 1e-3; };
  for (int trial = 0; trial < 500; ++trial) {
    const State s = test::randomState(m.nr(), poses, 1.2, 0.0);
    try {
      if (wraps(s, 0) && wraps(s, 1)) {
        pr.initial.q = s.q;
        break;
      }
    } catch (const MuscleError&) {  // an end point inside a surface
    }
  }
  ASSERT_TRUE(wraps(pr.initial, 0) && wraps(pr.initial, 1));
  pr.forces = {{0, 0, 2}, {1, 0, 2}, {2, 0, 1}};
  pr.initial_q = {1};
  pr.initial_qdot = {2};
  // measured 1.1e-11 .. 2.2e-11 and 3.4e-11 .. 6.3e-11 (euler, bdf1, sdirk2)
  checkRoutes(pr, pointAndRest(m), kFiveParameters, "Type III muscles with mass",
              "the mass points of 2 wrapping (Type III) muscles ('cylinder', ...) by muscle-local fourth-order "
              "differences");
}

// the network wrap model (the committed cylinder network) on the wrap pendulum, inside its
// training box: the step Jacobians difference the network's share locally as they do the smooth one
TEST_P(AnalyticJacobians, TypeThreeNetworkWrapModelAgainstCentralDifferences) {
  const Model m = scenes::doublePendulum();
  WrapMassOptions neural;
  neural.model = WrapModel::Neural;
  neural.network = loadWrapNetwork(std::string(REDMAX_SOURCE_DIR) + "/osim_models/networks/cylinder_3x64.txt");
  const scenes::WrapPendulumSpec spec;
  const Muscle mu = scenes::makeWrapPendulumMuscle(spec, neural);
  auto sys = std::make_shared<System>(m);
  sys->addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{mu}));
  Problem pr = problemFor(sys, GetParam(), 0.05, 0.005);
  pr.initial.q = (VecX(2) << spec.q1, spec.q2).finished();
  pr.forces = {{0, 0, 1}, {1, 0, 1}};
  pr.initial_qdot = {0, 1};
  // the path wraps at the start and the network (not its smooth fallback) places the points
  const MuscleKinematics mk = test::evalMuscle(m, mu, pr.initial);
  EXPECT_GT(test::offStraightLine(mk), 1e-3);
  EXPECT_GT(mk.wrap_counts.evaluations, 0);
  EXPECT_EQ(mk.wrap_counts.fallbacks, 0);
  Objective obj;
  obj.points.push_back({m.nb() - 1, Vec3(0.0, -1.0, 0.0), Vec3(0.5, -1.5, 0.0), 1.0});
  obj.speed_weight = 0.1;
  // measured 1.2e-11 .. 2.3e-11 and 1.9e-10 .. 2.0e-10
  checkRoutes(pr, obj, (VecX(4) << 0.4, -0.3, 0.2, 0.5).finished(), "network wrap model");
}

// coordinate couplers (OpenSim's CoordinateCouplerConstraint, e.g. a knee's translations or a
// patella following the knee angle): two couplers through a cubic of one coordinate and a
// function of two, on a random tree with springs, dampers and limit forces; with and without
// Baumgarte stabilization
TEST_P(AnalyticJacobians, CoordinateCouplersAgainstCentralDifferences) {
  for (double alpha : {0.0, 5.0}) {
    const auto sys = randomSystem(21);
    const int n = sys->ndof();
    const Model& m = sys->model();
    auto cubic = makeConstraintFunction1([](double x) { return 0.3 * x + 0.2 * x * x - 0.1 * x * x * x; },
                                         [](double x) { return 0.3 + 0.4 * x - 0.3 * x * x; },
                                         [](double x) { return 0.4 - 0.6 * x; });
    sys->addConstraint(std::make_shared<CoordinateCoupler>(m, n - 1, std::vector<int>{0}, cubic, 1.5, "c1"));
    auto two = makeConstraintFunction(
        2, [](const VecX& x) { return std::sin(x[0]) * x[1]; },
        [](const VecX& x) { return VecX((VecX(2) << std::cos(x[0]) * x[1], std::sin(x[0])).finished()); },
        [](const VecX& x) {
          return MatX((MatX(2, 2) << -std::sin(x[0]) * x[1], std::cos(x[0]), std::cos(x[0]), 0.0).finished());
        });
    sys->addConstraint(std::make_shared<CoordinateCoupler>(m, 2, std::vector<int>{1, 3}, two, 1.0, "c2"));
    sys->stabilization.alpha = alpha;
    sys->stabilization.beta = alpha;
    // a consistent start: the dependent coordinates and speeds from the independent ones
    Problem pr = problemFor(sys, GetParam(), 0.05, 0.005);
    pr.initial.q.setZero();
    pr.initial.q[0] = 0.2;
    pr.initial.q[1] = 0.3;
    pr.initial.q[3] = -0.4;
    pr.initial.q[n - 1] = 1.5 * (0.3 * 0.2 + 0.2 * 0.04 - 0.1 * 0.008);
    pr.initial.q[2] = std::sin(0.3) * -0.4;
    pr.forces = {{0, 0, 2}, {0, 1, 2}, {1, 0, 1}, {n / 2, 0, 1}};
    pr.initial_qdot = {0};
    // measured 2.6e-11 .. 2.9e-10 and 1.0e-10 .. 2.8e-10 (euler, bdf1, sdirk2)
    checkRoutes(pr, pointAndRest(m), kFiveParameters,
                "coordinate couplers (stabilization " + std::to_string(static_cast<int>(alpha)) + ")");
  }
}

// a locked coordinate (OpenSim's `locked`, e.g. Rajagopal2016's subtalar and MTP angles) and a
// coordinate prescribed along a sine (a prescribed_function): constant rows, only their errors move
// with the state (and with stabilization, the rhs)
TEST_P(AnalyticJacobians, LockedAndPrescribedCoordinatesAgainstCentralDifferences) {
  for (double alpha : {0.0, 5.0}) {
    const auto sys = randomSystem(21);
    const int n = sys->ndof();
    const Model& m = sys->model();
    ASSERT_GE(n, 5);
    sys->addConstraint(PrescribedCoordinate::makeLocked(m, n - 1, 0.1));
    auto sine = makeConstraintFunction1([](double t) { return 0.2 * std::sin(3.0 * t) - 0.1; },
                                        [](double t) { return 0.6 * std::cos(3.0 * t); },
                                        [](double t) { return -1.8 * std::sin(3.0 * t); });
    sys->addConstraint(std::make_shared<PrescribedCoordinate>(m, n - 2, sine, "sine"));
    sys->stabilization.alpha = alpha;
    sys->stabilization.beta = alpha;
    Problem pr = problemFor(sys, GetParam(), 0.05, 0.005);
    pr.initial.q[n - 1] = 0.1;
    pr.initial.q[n - 2] = -0.1;
    pr.initial.qdot[n - 2] = 0.6;
    pr.forces = {{0, 0, 2}, {0, 1, 2}, {1, 0, 1}, {n / 2 - 1, 0, 1}};
    pr.initial_qdot = {0};
    // measured 6.4e-12 .. 1.9e-11 and 2.9e-11 .. 5.2e-11 (euler, bdf1, sdirk2)
    checkRoutes(pr, pointAndRest(m), kFiveParameters,
                "locked and prescribed coordinates (stabilization " + std::to_string(static_cast<int>(alpha)) + ")");
  }
}

// force terms without written derivatives (a point-to-point spring, a bushing with stiffness and
// damping in all six directions) join the route by central differences of those terms alone,
// and the route says so
TEST_P(AnalyticJacobians, TermsDifferencedAloneAgainstCentralDifferences) {
  const auto sys = randomSystem(5);
  const Model& m = sys->model();
  const int nb = m.nb();
  PointToPointSpringTerm::Spring sp{"p2p", -1, nb - 1, Vec3(0.3, 0.2, 0.1), Vec3(0.05, -0.1, 0.0), 40.0, 0.2};
  sys->addTerm(std::make_shared<PointToPointSpringTerm>(m, std::vector<PointToPointSpringTerm::Spring>{sp}));
  BushingForceTerm::Bushing bu;
  bu.name = "bushing";
  bu.body1 = 0;
  bu.body2 = nb - 1;
  bu.X_2M(1, 3) = -0.1;
  bu.stiffness << 3.0, 2.0, 4.0, 50.0, 40.0, 60.0;
  bu.damping << 0.1, 0.2, 0.1, 1.0, 2.0, 1.5;
  sys->addTerm(std::make_shared<BushingForceTerm>(m, std::vector<BushingForceTerm::Bushing>{bu}));
  const int n = sys->ndof();
  Problem pr = problemFor(sys, GetParam(), 0.05, 0.005);
  pr.forces = {{0, 0, 2}, {0, 1, 2}, {n - 1, 0, 1}};
  pr.initial_q = {1};
  pr.initial_qdot = {0};
  // measured 2.2e-11 .. 7.8e-11 and 1.0e-10 .. 2.9e-10 (euler, bdf1, sdirk2)
  checkRoutes(pr, pointAndRest(m), kFiveParameters, "point-to-point spring and bushing",
              "the forces of 'point_to_point_springs', 'bushing_forces' by central differences of their terms");
}

INSTANTIATE_TEST_SUITE_P(Integrators, AnalyticJacobians, ::testing::Values("euler", "bdf1", "sdirk2"));

// a constraint without written row derivatives (the four-bar's hinge point constraint: a closed
// loop) joins the route by fourth-order differences of its own rows (constraintRowDerivatives);
// `exact` is no route
TEST_P(AnalyticJacobians, PointConstraintRowsDifferencedAloneAgainstCentralDifferences) {
  const redmax::testing::FourBar fb;
  auto sys = std::make_shared<System>(fb.model);
  sys->addConstraint(std::make_shared<HingePointConstraint>(fb.model, fb.rocker_body, fb.tip_rocker(), -1,
                                                            fb.pivot_world(), -1, Vec3::UnitZ()));
  for (double alpha : {0.0, 5.0}) {
    sys->stabilization.alpha = alpha;
    sys->stabilization.beta = alpha;
    Problem pr = problemFor(sys, GetParam(), 0.05, 0.01);
    pr.initial.q = fb.closedQ(0.7);
    pr.forces = {{0, 0, 1}, {1, 0, 1}};
    Objective obj;
    obj.speed_weight = 1.0;
    obj.points.push_back({fb.rocker_body, Vec3::Zero(), Vec3(0.2, 0.3, 0.0), 1.0});
    // measured 1.0e-10 .. 6.5e-10 and 2.5e-10 .. 1.0e-9 (the differenced route's own error on
    // this closed loop)
    checkRoutes(pr, obj, (VecX(2) << 0.5, -0.3).finished(),
                "four-bar hinge point constraint (stabilization " + std::to_string(static_cast<int>(alpha)) + ")");
  }
  Problem pr = problemFor(sys, GetParam(), 0.05, 0.01);
  pr.initial.q = fb.closedQ(0.7);
  pr.forces = {{0, 0, 1}};
  pr.step_jacobians = "exact";
  EXPECT_THROW(adjoint::evaluate(pr, Objective{}, VecX::Constant(1, 0.5), true), adjoint::AdjointError);
}

}  // namespace
}  // namespace redmax
