// plugin/simbody/matter_muscle_inertia.hpp through plugin/opensim's names (always built, no OpenSim
// needed): the OpenSim plugin's mass-point forces on a Simbody system located through a
// body/coordinate map built as a foreign system would give it, against plugin/simbody's MuscleInertia
// on the same system (the same code behind the map SimbodyModel gives) and against the core's
// MuscleTerm [D Eq. 5.6-5.7]:
//   - random trees (Gimbal and Ball mobilizers) with Type I, Type II (1-5 via points), moving and
//     conditional points, and Type III (one cylinder or sphere); MatterMuscleInertia == MuscleInertia
//     to 1e-13 of the peak (same arithmetic, only the lookups differ) and T^T f_u == core
//     M_muscle qddot - f_muscle to 1e-9;
//   - set F (gait10dof18musc) with 80% of tibia_r's mass in its muscles, at random states, against
//     MuscleInertia and the core (1e-9);
//   - the map is checked: wrong sizes, a path body, coordinate or wrap body the system lacks.
#include "plugin/opensim/matter_muscle_inertia.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "converter/build/muscle_mass.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "plugin/simbody/muscle_inertia.hpp"
#include "tests/plugin/wrap_test_geometry.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

double relDiff(const VecX& a, const VecX& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1e-300, b.cwiseAbs().maxCoeff());
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

// Type III: origin -> one surface -> insertion, the surface across the segment between the ends at
// the state (test::surfacePoseAcross: the path wraps), on the origin's body (variant 0), another
// body (1), the world (2), or with a moving insertion (3); smooth wrap model
Muscle randomWrapMuscle(const Model& m, int variant, std::mt19937& rng, const State& s, bool sphere) {
  Muscle mu;
  mu.name = "wrap" + std::to_string(variant);
  const int b1 = randomBody(m, rng, true);
  const int b2 = randomBody(m, rng, false);
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
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  auto world = [&](const PathPoint& p) {
    Vec3 x_b, dx, ddx;
    calcPointLocation(p, s.q, x_b, dx, ddx);
    return p.body < 0 ? x_b : Vec3((sk.E_wi[p.body] * x_b.homogeneous()).head<3>());
  };
  // 0.4 radius off the line, not through the centre: there round-off would pick the wrap's side,
  // differently in the core and in Simbody
  const Vec3 side = randomVec(rng, 1.0);
  const double turn = randomVec(rng, 3.0)[0];
  const Mat4 E_ws = test::surfacePoseAcross(world(mu.path.points[0]), world(mu.path.points[1]), side, turn);
  PathWrap w;
  w.name = sphere ? "ball" : "drum";
  w.surface = sphere ? WrapSurface::makeSphere(0.03) : WrapSurface::makeCylinder(0.03, 2.0);
  w.body = bs;
  w.E_bs = bs >= 0 ? Mat4(sk.E_wi[bs].inverse() * E_ws) : E_ws;
  mu.path.wraps = {w};
  mu.path.num_wraps = 1;
  MassPointOptions opt;
  opt.count = 6;
  mu.mass_points = makeMassPoints(0.7, 0.5, 0.3, opt);
  mu.optimal_fiber_length = 0.5;
  mu.tendon_slack_length = 0.3;
  return mu;
}

// both Simbody-side components at one state; returns the number of compared states (0 or 1)
int compareAt(const simbody::SimbodyModel& sm, const Model& m, const std::vector<Muscle>& muscles,
              const State& s, const VecX& qddot, bool with_core, double& worst_same, double& worst_core) {
  simbody::MuscleInertia reference(sm, makeMusculoskeletalModel(m, muscles));
  // the map a foreign system would give: the SimbodyModel's own mobilized bodies and q slots
  opensim::MatterMuscleInertia ours(sm.matter, simbody::makeMatterMap(sm, m), m, muscles, m.gravity());
  SimTK::State sb = sm.default_state;
  simbody::setSimbodyState(sm, m, s, sb);
  sm.system.realize(sb, SimTK::Stage::Velocity);
  MatX T, Tdot;
  simbody::calcVelocityMap(sm, m, s, T, &Tdot);
  const VecX udot = T * qddot + Tdot * s.qdot;
  VecX f_ref, f_ours;
  try {
    f_ref = reference.calcGeneralizedForces(sb, udot);
  } catch (const MuscleError&) {
    return 0;  // two random points coincide at this state
  }
  SimTK::Vector f;
  ours.calcGeneralizedForces(sb, simbody::toSimTK(udot), f);
  f_ours = simbody::fromSimTK(f);
  EXPECT_GT(f_ref.cwiseAbs().maxCoeff(), 0.0);
  const double same = relDiff(f_ours, f_ref);
  EXPECT_LE(same, 1e-13);
  worst_same = std::max(worst_same, same);
  EXPECT_NEAR(ours.kineticEnergy(sb), reference.kineticEnergy(sb), 1e-12 * (1.0 + reference.kineticEnergy(sb)));
  EXPECT_NEAR(ours.totalMass(), reference.totalMass(), 1e-15);
  if (with_core) {
    SkeletonWorkspace sk(m);
    calcKinematics(m, s, sk);
    const MuscleTerm term(m, muscles);
    MatX M = MatX::Zero(m.nr(), m.nr());
    VecX fc = VecX::Zero(m.nr());
    term.addMass(m, s, sk, M);
    term.addForce(m, s, sk, fc);
    const VecX core = M * qddot - fc;
    const double c = relDiff(T.transpose() * f_ours, core);
    EXPECT_LE(c, 1e-9);
    worst_core = std::max(worst_core, c);
  }
  return 1;
}

using MakeMuscles = std::function<std::vector<Muscle>(const Model&, int variant, int trial, const State&, std::mt19937&)>;

// compareAt on random trees (a Gimbal and a Ball tree, and the double pendulum): per system,
// variants x trials random states, make() giving the muscles at each; returns how many states were
// compared, and the worst relative differences (worst_core: 0 unless with_core)
int compareOnRandomTrees(std::uint32_t seed, int variants, int trials, bool with_core, const MakeMuscles& make,
                         double& worst_same, double& worst_core) {
  using scenes::TreeJoints;
  using simbody::SphericalAs;
  struct Case {
    Model model;
    SphericalAs spherical;
  };
  const std::vector<Case> cases{{scenes::randomTree(6, 11, TreeJoints::SimbodyComparable), SphericalAs::Gimbal},
                                {scenes::randomTree(8, 29, TreeJoints::SimbodyComparable), SphericalAs::Ball},
                                {scenes::doublePendulum(), SphericalAs::Gimbal}};
  std::mt19937 rng(seed);
  int checked = 0;
  worst_same = worst_core = 0.0;
  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const Model& m = cases[ci].model;
    simbody::SimbodyBuildOptions opt;
    opt.spherical = cases[ci].spherical;
    const auto sm = simbody::makeSimbodyModel(m, opt);
    for (int variant = 0; variant < variants; ++variant) {
      for (int trial = 0; trial < trials; ++trial) {
        SCOPED_TRACE("case " + std::to_string(ci) + " variant " + std::to_string(variant));
        const State s = randomState(m.nr(), rng);
        const std::vector<Muscle> muscles = make(m, variant, trial, s, rng);
        const VecX qddot = VecX::NullaryExpr(m.nr(), [&] { return randomVec(rng, 3.0)[0]; });
        checked += compareAt(*sm, m, muscles, s, qddot, with_core, worst_same, worst_core);
      }
    }
  }
  return checked;
}

TEST(MatterMuscleInertia, EqualsMuscleInertiaAndCoreOnRandomTrees) {
  double worst_same = 0.0, worst_core = 0.0;
  const int checked = compareOnRandomTrees(
      4242, 8, 2, true,
      [](const Model& m, int variant, int, const State& s, std::mt19937& rng) {
        return std::vector<Muscle>{randomMuscle(m, variant, rng, s), randomMuscle(m, (variant + 3) % 8, rng, s)};
      },
      worst_same, worst_core);
  EXPECT_GE(checked, 40);
  std::printf("  random trees: %d states; vs MuscleInertia %.2e, vs core MuscleTerm %.2e (of the peak)\n", checked,
              worst_same, worst_core);
}

TEST(MatterMuscleInertia, TypeIIIEqualsMuscleInertiaOnRandomTrees) {
  double worst_same = 0.0, worst_core = 0.0;
  // a wrapping muscle next to a Type II one, so the station and frame batches span both; against
  // the core too (MuscleInertia is this same component behind makeMatterMap: the core is the
  // independent side)
  const int checked = compareOnRandomTrees(
      99, 4, 4, true,
      [](const Model& m, int variant, int trial, const State& s, std::mt19937& rng) {
        return std::vector<Muscle>{randomWrapMuscle(m, variant, rng, s, trial % 2 == 1), randomMuscle(m, 1, rng, s)};
      },
      worst_same, worst_core);
  EXPECT_GE(checked, 30);
  std::printf("  Type III: %d states; vs MuscleInertia %.2e, vs core MuscleTerm %.2e (of the peak)\n", checked,
              worst_same, worst_core);
}

TEST(MatterMuscleInertia, EqualsMuscleInertiaOnSetFWithTibiaTransfer) {
  const std::string file = std::string(REDMAX_SHARED_DIR) +
                           "/opensim/opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim";
  if (!std::filesystem::exists(file))
    GTEST_SKIP() << "shared OpenSim data not found at " << file << "; this test needs set F's model";
  const osim::ModelDescription d = osim::readOsimModel(file);
  osim::BuildOptions bo;
  bo.simbody_compat = true;
  bo.constraints = false;
  osim::MuscleMassOptions mo;
  mo.source = osim::MuscleMassOptions::Source::Transfer;
  mo.transfer_body = "tibia_r";
  mo.transfer_fraction = 0.8;
  const osim::MuscleMassModel mm = osim::applyMuscleMass(d, bo, mo);
  ASSERT_GT(mm.plan.total_muscle_mass, 0.0);
  const Model& m = mm.build.model;
  const auto sm = simbody::makeSimbodyModel(m);
  std::mt19937 rng(7);
  int checked = 0;
  double worst_same = 0.0, worst_core = 0.0;
  for (int k = 0; k < 8; ++k) {
    State s = randomState(m.nr(), rng);
    s.q *= 0.5;  // stay near walking poses
    const VecX qddot = VecX::NullaryExpr(m.nr(), [&] { return randomVec(rng, 10.0)[0]; });
    // against the core too: MuscleInertia is this same component behind another map, so only
    // the core's MuscleTerm is an independent reference here
    checked += compareAt(*sm, m, mm.build.model.muscles(), s, qddot, true, worst_same, worst_core);
  }
  EXPECT_EQ(checked, 8);
  std::printf("  set F, 80%% tibia_r: %d states; vs MuscleInertia %.2e, vs core MuscleTerm %.2e (of the peak)\n",
              checked, worst_same, worst_core);
}

TEST(MatterMuscleInertia, RejectsMapsThatDoNotFit) {
  const Model m = scenes::doublePendulum();
  const auto sm = simbody::makeSimbodyModel(m);
  Muscle mu;
  mu.name = "m";
  mu.path.points = {makeFixedPoint(-1, Vec3(0.1, 0, 0)), makeFixedPoint(1, Vec3(0, -0.5, 0))};
  MassPointOptions opt;
  opt.count = 3;
  mu.mass_points = makeMassPoints(0.5, 0.5, 0.2, opt);
  const opensim::MatterMap good = simbody::makeMatterMap(*sm, m);
  EXPECT_NO_THROW(opensim::MatterMuscleInertia(sm->matter, good, m, {mu}, m.gravity()));
  opensim::MatterMap short_map = good;
  short_map.mobod_of_body.pop_back();
  EXPECT_THROW(opensim::MatterMuscleInertia(sm->matter, short_map, m, {mu}, m.gravity()), std::invalid_argument);
  opensim::MatterMap no_body = good;
  no_body.mobod_of_body[1] = SimTK::MobilizedBodyIndex();  // the insertion's body is not in the system
  EXPECT_THROW(opensim::MatterMuscleInertia(sm->matter, no_body, m, {mu}, m.gravity()), std::invalid_argument);
  // a massless muscle may sit anywhere: it is skipped
  Muscle lumped = mu;
  lumped.mass_points = MassPoints();
  EXPECT_NO_THROW(opensim::MatterMuscleInertia(sm->matter, no_body, m, {lumped}, m.gravity()));
  // a wrap surface on a body the system lacks (its points elsewhere): refused, naming the wrap
  Muscle wrapped = mu;
  wrapped.path.points = {makeFixedPoint(-1, Vec3(0.1, 0, 0)), makeFixedPoint(0, Vec3(0, -0.5, 0))};
  PathWrap w;
  w.name = "drum_on_link2";
  w.surface = WrapSurface::makeCylinder(0.03, 1.0);
  w.body = 1;
  wrapped.path.wraps = {w};
  wrapped.path.num_wraps = 1;
  EXPECT_NO_THROW(opensim::MatterMuscleInertia(sm->matter, good, m, {wrapped}, m.gravity()));
  try {
    opensim::MatterMuscleInertia(sm->matter, no_body, m, {wrapped}, m.gravity());
    ADD_FAILURE() << "a wrap body outside the system was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("drum_on_link2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace redmax
