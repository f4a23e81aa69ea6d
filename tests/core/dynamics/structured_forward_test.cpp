// Forward dynamics by the tree's structure (core/dynamics/structured_forward.hpp) against the dense
// route (M = J_mr^T M_m J_mr + terms, dense LDLT), which stays the reference:
//   - CRBA equals calcSkeletonMass on random trees of every joint type;
//   - ABA equals the dense route on bare random trees, with joint springs and dampers, external
//     loads and massless terms (actuators);
//   - LTDL over the tree equals the dense route with inertial muscles that keep the tree's pattern,
//     and a muscle coupling two branches makes the System fall back to dense (ws.last_route);
//   - Auto picks the documented route (bare -> Articulated, mass terms -> TreeSparse from
//     kTreeSparseMinDof coordinates else Dense, constraints / map / extra coordinates -> Dense);
//   - an implicit integrator (sdirk2) that reads M after forwardDynamics gets it on every route.
// Accelerations are compared relative to |qddot| and normalised by cond(M) (the dense solve's own
// error grows with it): err = |qddot_route - qddot_dense|_inf / (|qddot_dense|_inf eps cond(M)).
// Measured worst err 0.32 (ABA) and 0.14 (LTDL) (printed); bound 1. CRBA measured to 4.5e-16 of
// max |M|; bound 1e-14.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <random>

#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/coordinate_actuator_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/structured_forward.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/humanoid.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

double cond(const MatX& M) {
  Eigen::JacobiSVD<MatX> svd(M);
  const VecX& s = svd.singularValues();
  return s[0] / s[s.size() - 1];
}

// |a - b|_inf / (|b|_inf eps cond(M))
double normalisedError(const VecX& a, const VecX& b, const MatX& M) {
  return (a - b).lpNorm<Eigen::Infinity>() / (std::max(b.lpNorm<Eigen::Infinity>(), 1e-300) * kEps * cond(M));
}

// random tree with joint springs and dampers on every coordinate
Model springyTree(int n, std::uint32_t seed) {
  ModelBuilder b(scenes::randomTree(n, seed));
  std::mt19937 rng(seed + 17);
  std::uniform_real_distribution<double> u(0.0, 5.0);
  for (int k = 0; k < b.nr(); ++k) {
    b.coordinateAt(k).stiffness = u(rng);
    b.coordinateAt(k).damping = 0.2 * u(rng);
    b.coordinateAt(k).rest_value = 0.1 * u(rng);
  }
  return b.finalize();
}

// an inertial Type II muscle along the root-to-`leaf` path: fixed points on an ancestor and on the
// leaf, a moving point on the leaf driven by an ancestor's coordinate, so that its coordinates lie
// on one path of the tree (the pattern LTDL keeps)
Muscle pathMuscle(const Model& m, int leaf, std::mt19937& rng, const std::string& name) {
  const std::vector<int>& anc = m.ancestors(leaf);
  const int first = anc[rng() % anc.size()];
  std::vector<int> coords;
  for (int a : anc)
    for (int k = 0; k < m.joints()[a].nq; ++k) coords.push_back(m.joints()[a].q_index + k);
  Muscle mu;
  mu.name = name;
  auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.05, -0.1, 0.2, 0.1});
  mu.path.points = {makeFixedPoint(first == anc.front() && rng() % 2 ? -1 : first, test::randomVec(rng, 0.3)),
                    coords.empty() ? makeFixedPoint(leaf, test::randomVec(rng, 0.3))
                                   : makeMovingPoint(leaf, coords[rng() % coords.size()], {cubic, nullptr, cubic},
                                                     Vec3(0, 0.1, 0)),
                    makeFixedPoint(leaf, test::randomVec(rng, 0.3))};
  mu.optimal_fiber_length = 0.3;
  mu.tendon_slack_length = 0.2;
  MassPointOptions opt;
  opt.count = 8;
  mu.mass_points = makeMassPoints(0.5, 0.3, 0.2, opt);
  return mu;
}

// a muscle from one leaf to another: couples two branches (not the tree's pattern)
Muscle crossMuscle(const Model& m, int a, int b, std::mt19937& rng) {
  Muscle mu;
  mu.name = "cross";
  mu.path.points = {makeFixedPoint(a, test::randomVec(rng, 0.3)), makeFixedPoint(b, test::randomVec(rng, 0.3))};
  mu.mass_points = makeMassPoints(0.5, 0.3, 0.2);
  return mu;
}

// true if a joint on the root-to-`a` path with coordinates is not on the root-to-`b` path
bool hasOwnCoordinates(const Model& m, int a, int b) {
  for (int j : m.ancestors(a))
    if (m.joints()[j].nq > 0 && !m.isAncestor(j, b)) return true;
  return false;
}

// bodies without children
std::vector<int> leaves(const Model& m) {
  std::vector<bool> parent(m.nb(), false);
  for (const JointSlot& s : m.joints())
    if (s.parent >= 0) parent[s.parent] = true;
  std::vector<int> out;
  for (int i = 0; i < m.nb(); ++i)
    if (!parent[i]) out.push_back(i);
  return out;
}

// qddot of `sys` on `route` and on Dense at the same state and workspace inputs; returns the
// normalised error and checks the route taken
double compareRoutes(System& sys, const State& s, const ExternalLoads& loads, const VecX& controls,
                     ForwardRoute route, ForwardRoute expect_taken) {
  DynamicsWorkspace wa(sys), wd(sys);
  wa.loads = wd.loads = loads;
  wa.controls = wd.controls = controls;
  sys.forward_route = route;
  const VecX qa = sys.forwardDynamics(s, wa);
  EXPECT_EQ(wa.last_route, expect_taken) << forwardRouteName(wa.last_route);
  sys.forward_route = ForwardRoute::Dense;
  const VecX qd = sys.forwardDynamics(s, wd);
  EXPECT_EQ(wd.last_route, ForwardRoute::Dense);
  EXPECT_TRUE(qa.allFinite());
  return normalisedError(qa, qd, wd.M);
}

TEST(StructuredForward, CrbaEqualsTheDenseMassMatrix) {
  double worst = 0.0;
  for (std::uint32_t seed = 1; seed <= 12; ++seed) {
    const Model m = scenes::randomTree(3 + static_cast<int>(seed) * 3, seed);
    std::mt19937 rng(seed);
    const State s = test::randomState(m.nr(), rng);
    SkeletonWorkspace sk(m);
    calcKinematics(m, s, sk);
    MatX Md, Mc;
    StructuredForwardWorkspace fw;
    calcSkeletonMass(m, sk, Md);
    calcSkeletonMassCrba(m, sk, fw, Mc);
    worst = std::max(worst, (Mc - Md).lpNorm<Eigen::Infinity>() / Md.lpNorm<Eigen::Infinity>());
    // the skeleton's M always has the tree's pattern
    std::vector<int> lambda, stamp;
    coordinateParents(m, lambda);
    EXPECT_TRUE(hasTreePattern(Md, lambda, stamp)) << "seed " << seed;
  }
  std::printf("CRBA vs J^T M J: worst %.2e of max |M|\n", worst);
  EXPECT_LT(worst, 1e-14);
}

TEST(StructuredForward, ArticulatedEqualsDenseOnBareTreesWithSpringsLoadsAndActuators) {
  double worst = 0.0;
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    const Model m = springyTree(2 + static_cast<int>(seed) * 3, seed);
    std::mt19937 rng(seed * 31);
    const State s = test::randomState(m.nr(), rng);
    System bare(m);
    EXPECT_EQ(bare.plannedForwardRoute(), ForwardRoute::Articulated);
    worst = std::max(worst, compareRoutes(bare, s, {}, {}, ForwardRoute::Auto, ForwardRoute::Articulated));
    // loads and a massless term with controls: still the articulated route
    ExternalLoads loads;
    for (int k = 0; k < 3; ++k) {
      const int b = static_cast<int>(rng() % static_cast<unsigned>(m.nb()));
      loads.point_forces.push_back({b, test::randomVec(rng, 0.3), test::randomVec(rng, 50.0)});
      loads.wrenches.push_back({b, test::randomVec(rng, 5.0), test::randomVec(rng, 20.0)});
    }
    std::vector<CoordinateActuatorTerm::Actuator> acts;
    for (int k = 0; k < m.nr(); k += 2) acts.push_back({"a" + std::to_string(k), k, 10.0});
    System driven(m);
    driven.addTerm(std::make_shared<CoordinateActuatorTerm>(m, acts));
    const VecX u = VecX::Random(driven.numControls());
    EXPECT_EQ(driven.plannedForwardRoute(), ForwardRoute::Articulated);
    worst = std::max(worst, compareRoutes(driven, s, loads, u, ForwardRoute::Auto, ForwardRoute::Articulated));
  }
  std::printf("ABA vs dense: worst %.3f eps cond(M) of |qddot|\n", worst);
  EXPECT_LT(worst, 1.0);
}

TEST(StructuredForward, TreeSparseEqualsDenseWithInertialMusclesAndFallsBackAcrossBranches) {
  double worst = 0.0;
  int coupled = 0, uncoupled = 0;
  for (std::uint32_t seed = 1; seed <= 8; ++seed) {
    const Model m = springyTree(6 + static_cast<int>(seed) * 3, seed + 100);
    std::mt19937 rng(seed * 7);
    const State s = test::randomState(m.nr(), rng, 0.5);
    std::vector<Muscle> muscles;
    const std::vector<int> lv = leaves(m);
    for (int k = 0; k < 4; ++k) muscles.push_back(pathMuscle(m, lv[rng() % lv.size()], rng, "m" + std::to_string(k)));
    System sys(m);
    sys.addTerm(std::make_shared<MuscleTerm>(m, muscles));
    // the bare skeleton too: every route applies
    System bare(m);
    for (ForwardRoute r : {ForwardRoute::TreeSparse, ForwardRoute::Articulated})
      worst = std::max(worst, compareRoutes(bare, s, {}, {}, r, r));
    worst = std::max(worst, compareRoutes(sys, s, {}, {}, ForwardRoute::TreeSparse, ForwardRoute::TreeSparse));
    // Articulated does not apply with mass terms: dense
    sys.forward_route = ForwardRoute::Articulated;
    EXPECT_EQ(sys.plannedForwardRoute(), ForwardRoute::Dense);
    compareRoutes(sys, s, {}, {}, ForwardRoute::Articulated, ForwardRoute::Dense);
    // a muscle between two leaves: where each has coordinates the other lacks, it couples two
    // branches and the pattern check falls back to dense
    if (lv.size() >= 2) {
      muscles.push_back(crossMuscle(m, lv[0], lv[1], rng));
      System cross(m);
      cross.addTerm(std::make_shared<MuscleTerm>(m, muscles));
      const bool couples = hasOwnCoordinates(m, lv[0], lv[1]) && hasOwnCoordinates(m, lv[1], lv[0]);
      ++(couples ? coupled : uncoupled);
      compareRoutes(cross, s, {}, {}, ForwardRoute::TreeSparse, couples ? ForwardRoute::Dense : ForwardRoute::TreeSparse);
    }
  }
  std::printf("tree-sparse / ABA vs dense: worst %.3f eps cond(M) of |qddot|; %d trees with a coupling "
              "muscle, %d without\n", worst, coupled, uncoupled);
  EXPECT_LT(worst, 1.0);
  EXPECT_GT(coupled, 0);
}

TEST(StructuredForward, AutoPicksTheDocumentedRoute) {
  const Model small = scenes::limbChain(kTreeSparseMinDof - 1);
  const Model large = scenes::limbChain(kTreeSparseMinDof);
  std::mt19937 rng(5);
  for (const Model* m : {&small, &large}) {
    System bare(*m);
    EXPECT_EQ(bare.plannedForwardRoute(), ForwardRoute::Articulated);
    System with_mass(*m);
    with_mass.addTerm(std::make_shared<MuscleTerm>(*m, std::vector<Muscle>{pathMuscle(*m, m->nb() - 1, rng, "m")}));
    const ForwardRoute expect = m->nr() >= kTreeSparseMinDof ? ForwardRoute::TreeSparse : ForwardRoute::Dense;
    EXPECT_EQ(with_mass.plannedForwardRoute(), expect) << m->nr() << " DoF";
    const State s = with_mass.defaultState();
    DynamicsWorkspace ws(with_mass);
    with_mass.forwardDynamics(s, ws);
    EXPECT_EQ(ws.last_route, expect);
    EXPECT_TRUE(ws.has_mass);
    // a muscle whose points are all massless adds nothing: still articulated
    Muscle zero = pathMuscle(*m, m->nb() - 1, rng, "z");
    for (double& mass : zero.mass_points.mass) mass = 0.0;
    System zero_mass(*m);
    zero_mass.addTerm(std::make_shared<MuscleTerm>(*m, std::vector<Muscle>{zero}));
    EXPECT_EQ(zero_mass.plannedForwardRoute(), ForwardRoute::Articulated);
    // constraints, a coordinate map, extra coordinates: dense whatever was asked
    System locked(*m);
    locked.addConstraint(PrescribedCoordinate::makeLocked(*m, 0, 0.1));
    System mapped(*m);
    mapped.setCoordinateMap(std::make_shared<CoordinateMap>(*m));
    System extra(*m);
    extra.addExtraCoordinates(1);
    for (System* sys : {&locked, &mapped, &extra})
      for (ForwardRoute r : {ForwardRoute::Auto, ForwardRoute::TreeSparse, ForwardRoute::Articulated}) {
        sys->forward_route = r;
        EXPECT_EQ(sys->plannedForwardRoute(), ForwardRoute::Dense) << forwardRouteName(r);
      }
    DynamicsWorkspace wl(locked);
    locked.forwardDynamics(locked.defaultState(), wl);
    EXPECT_EQ(wl.last_route, ForwardRoute::Dense);
  }
}

TEST(StructuredForward, TheArticulatedRouteLeavesMUnformedAndSdirk2FormsIt) {
  const Model m = springyTree(9, 3);
  System aba(m), dense(m);
  dense.forward_route = ForwardRoute::Dense;
  std::mt19937 rng(3);
  const State s0 = test::randomState(m.nr(), rng, 0.5);
  DynamicsWorkspace ws(aba);
  aba.calcMassAndForce(s0, ws);
  EXPECT_TRUE(ws.has_mass);
  aba.forwardDynamics(s0, ws);
  EXPECT_EQ(ws.last_route, ForwardRoute::Articulated);
  EXPECT_FALSE(ws.has_mass);
  // sdirk2's Newton matrix needs M after forwardDynamics: same steps on both routes
  IntegratorOptions io;
  io.dt = 2e-3;
  State a = s0, d = s0;
  auto ia = makeIntegrator("sdirk2", io), id = makeIntegrator("sdirk2", io);
  ia->advance(aba, a, 0.1);
  id->advance(dense, d, 0.1);
  EXPECT_EQ(ia->stats().steps, id->stats().steps);
  EXPECT_LT((a.q - d.q).lpNorm<Eigen::Infinity>(), 1e-10 * (1.0 + d.q.lpNorm<Eigen::Infinity>()));
}

TEST(StructuredForward, FactorLTDLRejectsAMatrixThatIsNotPositiveDefinite) {
  const Model m = scenes::limbChain(4);
  std::vector<int> lambda, stamp;
  coordinateParents(m, lambda);
  MatX M = MatX::Identity(4, 4), LD;
  EXPECT_TRUE(factorLTDL(M, lambda, LD));
  M(2, 2) = -1.0;
  EXPECT_FALSE(factorLTDL(M, lambda, LD));
  // on a branched tree a coupling of two branches breaks the pattern
  const Model h = scenes::humanoid();
  coordinateParents(h, lambda);
  MatX H = MatX::Identity(h.nr(), h.nr());
  EXPECT_TRUE(hasTreePattern(H, lambda, stamp));
  std::vector<int> lv;
  for (int i : leaves(h))
    if (h.joints()[i].nq > 0) lv.push_back(i);
  ASSERT_GE(lv.size(), 2u);
  const int a = h.joints()[lv[0]].q_index, b = h.joints()[lv[1]].q_index;
  H(std::max(a, b), std::min(a, b)) = H(std::min(a, b), std::max(a, b)) = 0.1;
  EXPECT_FALSE(hasTreePattern(H, lambda, stamp));
}

}  // namespace
}  // namespace redmax
