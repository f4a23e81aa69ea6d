// Contact pairs under the adaptive integrators by event location (core/integrators/event_driven.hpp,
// core/dynamics/unilateral/held_contacts.hpp). With the events located in time, Coulomb friction
// and impacts follow their closed forms to the integrator's tolerance (bdf1's contact step is first
// order in h there, docs/contact.md §6.3): a ball bouncing keeps e^2 of its energy per impact and
// comes to rest on its radius; a block slides v0^2 / (2 mu g) and stops at v0 / (mu g); a ball
// thrown without spin slides until it rolls at 5/7 of its speed and then rolls without slipping;
// a block on a slope sticks below atan(mu) and slides with g (sin - mu cos) above it; a box stack
// stays at rest.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "core/dynamics/system.hpp"
#include "core/dynamics/unilateral/held_contacts.hpp"
#include "core/dynamics/unilateral/unilateral.hpp"
#include "core/integrators/event_driven.hpp"
#include "core/integrators/integrator.hpp"
#include "core/joints/free_joints.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "validation/scenes/contact_scenes.hpp"
#include "validation/scenes/deformable_scenes.hpp"

namespace redmax {
namespace {

constexpr double kG = 9.81;

IntegratorOptions tight() {
  IntegratorOptions io;
  io.rtol = 1e-11;
  io.atol = 1e-12;
  return io;
}

double energy(const System& sys, const State& s) {
  DynamicsWorkspace ws(sys);
  return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
}

// run to t_end; the largest coordinate change over its last second
double driftOverTheLastSecond(const System& sys, State& s, Integrator& integ, double t_end) {
  integ.advance(sys, s, t_end - 1.0);
  const VecX q = s.q;
  integ.advance(sys, s, t_end);
  return (s.q - q).cwiseAbs().maxCoeff();
}

// the relative tangential velocity at every contact point of the system's pairs (world, m/s)
double largestTangentialSpeed(const System& sys, const State& s) {
  SkeletonWorkspace sk(sys.model());
  calcKinematics(sys.model(), s, sk);
  UnilateralRows rows;
  sys.unilateral()->detect(sys.model(), s, sk, sys.ndof(), 1.0, rows);
  double w = 0.0;
  for (const auto& c : rows.c)
    if (c.gap < 1e-9 && c.tangent_row >= 0)
      w = std::max({w, std::abs(rows.Jt.row(c.tangent_row).dot(s.qdot)),
                    std::abs(rows.Jt.row(c.tangent_row + 1).dot(s.qdot))});
  return w;
}

TEST(ContactEvents, ABallKeepsESquaredOfItsEnergyPerBounceAndComesToRestOnItsRadius) {
  for (const char* method : {"rk45", "cvode"}) {
    scenes::BallDropOptions o;
    o.restitution = 0.5;
    State s;
    auto sys = scenes::makeBallDrop(o, s);
    auto integ = makeIntegrator(method, tight());
    // energy above the resting height, sampled just after each impact
    const double E_rest = o.mass * kG * o.radius;
    std::vector<double> after;
    long seen = 0;
    for (int k = 1; k <= 3000; ++k) {
      integ->advance(*sys, s, 0.001 * k);
      if (integ->stats().event_impacts > seen) {
        seen = integ->stats().event_impacts;
        after.push_back(energy(*sys, s) - E_rest);
      }
    }
    const double E0 = o.mass * kG * o.drop_height;
    ASSERT_GE(after.size(), 4u) << method;
    double worst = std::abs(after[0] / E0 - 0.25);
    for (size_t k = 1; k + 1 < after.size() && after[k] > 1e-3 * E0; ++k)
      worst = std::max(worst, std::abs(after[k] / after[k - 1] - 0.25));
    std::printf("[ measured ] %s: %zu impacts, energy ratio per bounce within %.2e of e^2; at 3 s height - r = "
                "%.2e m, speed %.2e m/s; %ld steps, %ld right-hand sides\n",
                method, after.size(), worst, s.q[1] - o.radius, s.qdot.norm(), integ->stats().steps,
                integ->stats().rhs_evals);
    EXPECT_LT(worst, 1e-7);  // the located impact time's and the tolerances' error
    // bounces slower than the restitution threshold (0.05 m/s) stop it: held on the ground
    EXPECT_NEAR(s.q[1], o.radius, 1e-10);
    EXPECT_LT(s.qdot.norm(), 1e-10);
  }
}

TEST(ContactEvents, ABlockSlidesTheClosedFormDistanceAndStaysWhereItStops) {
  scenes::BlockSlideOptions o;  // 2 m/s, mu 0.5
  State s;
  auto sys = scenes::makeBlockSlide(o, s);
  auto integ = makeIntegrator("rk45", tight());
  const double d = o.v0 * o.v0 / (2 * o.friction * kG), t_stop = o.v0 / (o.friction * kG);
  integ->advance(*sys, s, t_stop - 0.01);
  EXPECT_GT(s.qdot[0], 0.0);
  const double slide_x = s.q[0];
  integ->advance(*sys, s, 1.0);
  const double dist = s.q[0];
  std::printf("[ measured ] block: distance %.12f m (closed form %.12f), before the stop %.12f (closed form %.12f); "
              "%ld sticks, %ld slips, tilt %.2e, speed at 1 s %.2e\n",
              dist, d, slide_x, o.v0 * (t_stop - 0.01) - 0.5 * o.friction * kG * std::pow(t_stop - 0.01, 2),
              integ->stats().event_sticks, integ->stats().event_slips, s.q.tail(3).cwiseAbs().maxCoeff(),
              s.qdot.norm());
  EXPECT_NEAR(dist, d, 1e-10 * d);  // measured equal to 12 digits
  EXPECT_NEAR(slide_x, o.v0 * (t_stop - 0.01) - 0.5 * o.friction * kG * std::pow(t_stop - 0.01, 2), 1e-10 * d);
  EXPECT_GE(integ->stats().event_sticks, 1);
  EXPECT_LT(s.qdot.norm(), 1e-10);
  EXPECT_NEAR(s.q[1], o.half_extents.y(), 1e-10);
  EXPECT_LT(s.q.tail(3).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(ContactEvents, ABallThrownWithoutSpinRollsAtFiveSeventhsOfItsSpeed) {
  // a solid sphere sliding on the ground: friction mu m g slows it and spins it up until the
  // contact point stops, at v = 5/7 v0 after t = 2 v0 / (7 mu g); then it rolls without slipping
  scenes::BallDropOptions o;
  o.drop_height = 0.0;
  o.restitution = 0.0;
  o.friction = 0.3;
  State s;
  auto sys = scenes::makeBallDrop(o, s);
  const double v0 = 3.0;
  s.qdot[0] = v0;
  auto integ = makeIntegrator("rk45", tight());
  const double t_roll = 2 * v0 / (7 * o.friction * kG);
  integ->advance(*sys, s, 0.5 * t_roll);
  const double v_half = s.qdot[0];
  integ->advance(*sys, s, 2.0);
  std::printf("[ measured ] ball: speed at t_roll / 2 %.12f (closed form %.12f), at 2 s %.12f (5/7 v0 = %.12f), "
              "slip speed %.2e m/s, height - r %.2e m; %ld sticks\n",
              v_half, v0 - o.friction * kG * 0.5 * t_roll, s.qdot[0], 5.0 / 7.0 * v0, largestTangentialSpeed(*sys, s),
              s.q[1] - o.radius, integ->stats().event_sticks);
  EXPECT_NEAR(v_half, v0 - o.friction * kG * 0.5 * t_roll, 1e-10 * v0);  // measured 7e-13 relative
  EXPECT_NEAR(s.qdot[0], 5.0 / 7.0 * v0, 1e-10 * v0);  // measured 7e-12 relative
  EXPECT_LT(largestTangentialSpeed(*sys, s), 1e-9 * v0);  // rolling: the rows' bias holds it (measured 7e-11 m/s)
  EXPECT_NEAR(s.q[1], o.radius, 1e-10);  // measured 3.8e-12 m
  EXPECT_EQ(integ->stats().event_sticks, 1);
}

// a box on a ground tilted by theta about z (down the slope is -x'), at rest at the start
std::shared_ptr<System> blockOnSlope(double theta, double mu, State& s) {
  ModelBuilder b("slope");
  b.setGravity(Vec3(0, -kG, 0));
  const Vec3 h(0.1, 0.05, 0.1);
  const double m = 1.0;
  b.addBody("block", m,
            Vec3::Zero(),
            Vec3(m / 3 * (h.y() * h.y() + h.z() * h.z()), m / 3 * (h.x() * h.x() + h.z() * h.z()),
                 m / 3 * (h.x() * h.x() + h.y() * h.y()))
                .asDiagonal(),
            -1, "free", Free3D{});
  auto sys = std::make_shared<System>(b.finalize());
  const Mat3 R = rotationAxisAngle(Vec3::UnitZ(), theta);
  CollisionGeometry ground;
  ground.name = "slope";
  ground.shape = CollisionShape::HalfSpace;
  ground.X_body = makeE(R * rotationAxisAngle(Vec3::UnitZ(), -M_PI / 2), Vec3::Zero());
  CollisionGeometry box;
  box.name = "block";
  box.shape = CollisionShape::Box;
  box.body = 0;
  box.half_extents = h;
  sys->setUnilateral(std::make_shared<UnilateralConstraints>(sys->model(), std::vector<CollisionGeometry>{ground, box},
                                                             std::vector<CollisionPair>{{0, 1, mu, 0.0}},
                                                             std::vector<JointLimit>{}));
  s = sys->defaultState();
  // resting on the slope: centre h.y above it along its normal, the box turned with it
  s.q.head(3) = R * Vec3(0, h.y(), 0);
  s.q[5] = theta;
  return sys;
}

TEST(ContactEvents, ABlockOnASlopeSticksBelowTheFrictionAngleAndSlidesAboveIt) {
  const double mu = 0.4;
  for (double theta : {0.3, 0.5}) {  // atan(0.4) = 0.3805
    State s;
    auto sys = blockOnSlope(theta, mu, s);
    const Vec3 x0 = s.q.head(3);
    auto integ = makeIntegrator("rk45", tight());
    const double T = 0.5;
    integ->advance(*sys, s, T);
    const Vec3 down = -Vec3(std::cos(theta), std::sin(theta), 0.0);  // down the slope
    const double travelled = (Vec3(s.q.head(3)) - x0).dot(down);
    const double a = std::max(0.0, kG * (std::sin(theta) - mu * std::cos(theta)));
    std::printf("[ measured ] slope %.2f rad: travelled %.15f m (closed form %.15f), off the slope %.2e m; %ld slips, "
                "%ld sticks\n",
                theta, travelled, 0.5 * a * T * T, (Vec3(s.q.head(3)) - x0).dot(Vec3(-std::sin(theta), std::cos(theta), 0)),
                integ->stats().event_slips, integ->stats().event_sticks);
    EXPECT_NEAR(travelled, 0.5 * a * T * T, 1e-11);
    EXPECT_NEAR((Vec3(s.q.head(3)) - x0).dot(Vec3(-std::sin(theta), std::cos(theta), 0)), 0.0, 1e-12);
    if (a == 0.0) EXPECT_EQ(integ->stats().event_slips, 0);
    else EXPECT_GE(integ->stats().event_slips, 1);
  }
}

TEST(ContactEvents, AStackOfBoxesStaysAtRest) {
  scenes::BoxStackOptions o;  // three boxes, each resting on the one below
  State s;
  auto sys = scenes::makeBoxStack(o, s);
  auto integ = makeIntegrator("rk45", tight());
  const double drift = driftOverTheLastSecond(*sys, s, *integ, 2.0);
  std::printf("[ measured ] box stack under rk45: drift over the second second %.2e m, speed %.2e; %ld steps, %ld "
              "right-hand sides, %ld releases, %ld slips\n",
              drift, s.qdot.cwiseAbs().maxCoeff(), integ->stats().steps, integ->stats().rhs_evals,
              integ->stats().event_releases, integ->stats().event_slips);
  EXPECT_LT(drift, 1e-12);  // measured 7e-15 m
  EXPECT_LT(s.qdot.cwiseAbs().maxCoeff(), 1e-10);  // measured 1.5e-12
}

TEST(ContactEvents, SixBoxesDroppedOntoEachOtherSettle) {
  // 24 corner contacts, four coplanar per box (rank deficient), closing in cascades of impacts
  scenes::BoxStackOptions o;
  o.boxes = 6;
  o.initial_gap = 0.02;
  State s;
  auto sys = scenes::makeBoxStack(o, s);
  auto integ = makeIntegrator("rk45", tight());
  const double drift = driftOverTheLastSecond(*sys, s, *integ, 3.0);
  const auto& st = integ->stats();
  std::printf("[ measured ] six boxes under rk45: %ld impacts, %ld releases, %ld slips, %ld sticks; drift over the "
              "third second %.2e m, largest penetration %.2e m; %ld steps, %ld right-hand sides\n",
              st.event_impacts, st.event_releases, st.event_slips, st.event_sticks, drift, st.max_penetration, st.steps,
              st.rhs_evals);
  // the five boxes above the bottom one land on their four corners each, all 24 corners end held
  EXPECT_GE(st.event_impacts, 20);
  SkeletonWorkspace sk(sys->model());
  calcKinematics(sys->model(), s, sk);
  int touching = 0;
  for (double g : sys->unilateral()->gaps(sys->model(), s, sk)) touching += std::abs(g) < 1e-10;
  EXPECT_EQ(touching, 24);
  EXPECT_LT(drift, 1e-12);  // measured 2.5e-14 m
  EXPECT_LT(st.max_penetration, 1e-10);  // measured 1.8e-12 m
  EXPECT_LT(s.qdot.cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ContactEvents, AnElasticBallKeepsBouncingToItsHeight) {
  // e = 1, 5 mm high: the contact comes and goes every 64 ms; every apex is the drop height
  scenes::BallDropOptions o;
  o.restitution = 1.0;
  o.drop_height = 5e-3;
  State s;
  auto sys = scenes::makeBallDrop(o, s);
  auto integ = makeIntegrator("rk45", tight());
  double apex = 0.0, worst = 0.0, lowest = 1.0;
  double prev_v = 0.0;
  int apexes = 0;
  for (int k = 1; k <= 20000; ++k) {  // 2 s in 0.1 ms samples
    integ->advance(*sys, s, 1e-4 * k);
    lowest = std::min(lowest, s.q[1] - o.radius);
    if (prev_v > 0.0 && s.qdot[1] <= 0.0) {
      // the apex from the sampled state: height + v^2 / (2 g)
      apex = s.q[1] - o.radius + s.qdot[1] * s.qdot[1] / (2 * kG);
      worst = std::max(worst, std::abs(apex - o.drop_height));
      ++apexes;
    }
    prev_v = s.qdot[1];
  }
  std::printf("[ measured ] elastic ball: %d apexes, %ld impacts, apex within %.2e m of the drop height, lowest %.2e "
              "m\n",
              apexes, integ->stats().event_impacts, worst, lowest);
  EXPECT_GE(apexes, 30);
  EXPECT_LT(worst, 5e-9);  // measured 6.2e-10 m
  EXPECT_GT(lowest, -1e-12);
}

TEST(ContactEvents, SlidingFrictionMakesTheKktSystemNonSymmetric) {
  // the held block sliding along +x: its force rows are J_n - mu J_t, so the System solves
  // [M H^T; G 0]; the normal forces carry the weight and the friction is mu times it
  scenes::BlockSlideOptions o;
  State s;
  auto sys = scenes::makeBlockSlide(o, s);
  SkeletonWorkspace sk(sys->model());
  calcKinematics(sys->model(), s, sk);
  UnilateralRows rows;
  sys->unilateral()->detect(sys->model(), s, sk, sys->ndof(), 1.0, rows);
  std::vector<HeldContact> held;
  for (const auto& c : rows.c)
    if (std::abs(c.gap) < 1e-12) {
      HeldContact h;
      h.key = ContactKey::of(c);
      h.mu = o.friction;
      const double w = rows.Jt.row(c.tangent_row).dot(s.qdot);
      h.slide[0] = w > 0 ? 1 : -1;
      held.push_back(h);
    }
  ASSERT_EQ(held.size(), 4u);
  System P(*sys);
  P.setUnilateral(nullptr);
  auto hc = std::make_shared<HeldContacts>(sys->unilateral(), held);
  P.addConstraint(hc);
  DynamicsWorkspace ws(P);
  const VecX qddot = P.forwardDynamics(s, ws);
  double pn = 0.0;
  for (size_t k = 0; k < held.size(); ++k) pn += -ws.lambda[hc->firstRow(static_cast<int>(k))];
  EXPECT_NEAR(pn, o.mass * kG, 1e-9);
  EXPECT_NEAR(qddot[0], -o.friction * kG, 1e-9);
  EXPECT_NEAR(qddot[1], 0.0, 1e-9);
}

TEST(ContactEvents, ContactPairsOnSystemsWithExtraCoordinatesNeedBdf1) {
  auto sys = std::make_shared<System>(scenes::singlePendulum());
  CollisionGeometry ground{"ground", CollisionShape::HalfSpace, -1, Mat4::Identity(), 0.0, 0.0, Vec3::Zero()};
  CollisionGeometry tip{"tip", CollisionShape::Sphere, 0, Mat4::Identity(), 0.05, 0.0, Vec3::Zero()};
  sys->setUnilateral(std::make_shared<UnilateralConstraints>(sys->model(), std::vector<CollisionGeometry>{ground, tip},
                                                             std::vector<CollisionPair>{{0, 1, 0.0, 0.0}},
                                                             std::vector<JointLimit>{}));
  sys->addExtraCoordinates(3);
  State s = sys->defaultState();
  try {
    makeIntegrator("rk45", IntegratorOptions{})->advance(*sys, s, 0.1);
    ADD_FAILURE() << "rk45 accepted contact pairs with extra coordinates";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("use bdf1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace redmax
