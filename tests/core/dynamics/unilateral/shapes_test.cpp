// The collision pairs added for issue 21's list (core/dynamics/unilateral/unilateral.hpp): an
// ellipsoid against a half-space (its support point) and a sphere against a capsule (the nearest
// point of the capsule's axis segment). Gaps in closed form, normal rows against differences of
// the gaps, and two scenes that settle where geometry says.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "core/dynamics/system.hpp"
#include "core/dynamics/unilateral/unilateral.hpp"
#include "core/integrators/integrator.hpp"
#include "core/joints/free_joints.hpp"
#include "core/spatial/se3.hpp"
#include "tests/core/dynamics/unilateral/unilateral_test_util.hpp"

namespace redmax {
namespace {

const Vec3 kSemiAxes(0.3, 0.1, 0.2);

// a free ellipsoid (body 0) on the ground; a free sphere (body 1, r 0.1) on the ground and against
// a capsule fixed in the world (r 0.05, half length 0.4, axis along z at height `bar_height`)
struct Scene {
  std::shared_ptr<System> sys;
  std::shared_ptr<UnilateralConstraints> u;
  explicit Scene(double bar_height = 0.5, double friction = 0.5) {
    ModelBuilder b("shapes");
    const Mat3 Ie = (0.2 * Vec3(kSemiAxes[1] * kSemiAxes[1] + kSemiAxes[2] * kSemiAxes[2],
                                kSemiAxes[0] * kSemiAxes[0] + kSemiAxes[2] * kSemiAxes[2],
                                kSemiAxes[0] * kSemiAxes[0] + kSemiAxes[1] * kSemiAxes[1]))
                         .asDiagonal();  // solid ellipsoid, 1 kg
    b.addBody("ellipsoid", 1.0, Vec3::Zero(), Ie, -1, "f0", Free3D{});
    b.addBody("ball", 1.0, Vec3::Zero(), Mat3(0.004 * Mat3::Identity()), -1, "f1", Free3D{});
    sys = std::make_shared<System>(b.finalize());
    CollisionGeometry ell{"ellipsoid", CollisionShape::Ellipsoid, 0, Mat4::Identity(), 0.0, 0.0, kSemiAxes};
    CollisionGeometry ball{"ball", CollisionShape::Sphere, 1, Mat4::Identity(), 0.1, 0.0, Vec3::Zero()};
    CollisionGeometry bar{"bar", CollisionShape::Capsule, -1,
                          makeE(rotationAxisAngle(Vec3::UnitY(), M_PI / 2), Vec3(0, bar_height, 0)), 0.05, 0.4,
                          Vec3::Zero()};
    // the ball-bar pair names the sphere first: the constructor puts the capsule first
    std::vector<CollisionPair> p{{0, 1, friction, 0.0}, {0, 2, friction, 0.0}, {2, 3, friction, 0.0}};
    u = std::make_shared<UnilateralConstraints>(sys->model(), std::vector<CollisionGeometry>{test::groundPlane(), ell, ball, bar}, p,
                                                std::vector<JointLimit>{});
    sys->setUnilateral(u);
  }
};

TEST(CollisionShapes, GapsInClosedForm) {
  Scene sc;
  State s = sc.sys->defaultState();
  // the ellipsoid tilted by 0.5 rad about z, centre at 0.4: its lowest point is
  // sqrt((a sin 0.5)^2 + (b cos 0.5)^2) below the centre
  s.q.segment<3>(0) = Vec3(0.1, 0.4, -0.2);
  s.q.segment<3>(3) = Vec3(0, 0, 0.5);
  // the ball beside the bar's axis (0.5 high along z at x = 0), 0.3 from it in the xy plane at
  // z = 0.1 (inside the segment), and beyond its end at z = 0.7
  s.q.segment<3>(6) = Vec3(0.3 * std::cos(0.7), 0.5 + 0.3 * std::sin(0.7), 0.1);
  DynamicsWorkspace ws(*sc.sys);
  sc.sys->kineticEnergy(s, ws);
  std::vector<double> g = sc.u->gaps(sc.sys->model(), s, ws.sk);
  ASSERT_EQ(g.size(), 3u);
  const double a = kSemiAxes[0], b = kSemiAxes[1];
  EXPECT_NEAR(g[0], 0.4 - std::hypot(a * std::sin(0.5), b * std::cos(0.5)), 1e-15);
  EXPECT_NEAR(g[2], 0.3 - 0.05 - 0.1, 1e-15);
  s.q[8] = 0.7;  // 0.3 beyond the segment's end at z = 0.4
  sc.sys->kineticEnergy(s, ws);
  g = sc.u->gaps(sc.sys->model(), s, ws.sk);
  EXPECT_NEAR(g[2], std::hypot(0.3, 0.3) - 0.15, 1e-15);
}

TEST(CollisionShapes, NormalRowsAreTheGapRatesByFiniteDifferences) {
  Scene sc;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    State s = sc.sys->defaultState();
    for (int k = 0; k < s.q.size(); ++k) s.q[k] = 0.5 * U(rng), s.qdot[k] = U(rng);
    s.q[1] = 0.35;
    s.q.segment<3>(6) = Vec3(0.2 * U(rng), 0.65, 0.3 * U(rng) + (trial == 2 ? 0.5 : 0.0));  // past the end in trial 2
    test::expectNormalRowsAreGapRates(*sc.sys, *sc.u, s, 3u, 1e-9);
  }
}

// bdf1 with the contact QP (1 ms, restitution 0, friction 0.5) from s for `seconds`; the total
// energy every 5 ms, the deepest penetration
struct SceneRun {
  std::vector<double> energy;
  double deepest = 0.0;
};
SceneRun runScene(const Scene& sc, State& s, double seconds) {
  IntegratorOptions io;
  io.dt = 1e-3;
  auto integ = makeIntegrator("bdf1", io);
  SceneRun r;
  const int n = static_cast<int>(std::lround(seconds / 0.005));
  DynamicsWorkspace ws(*sc.sys);
  for (int k = 0; k <= n; ++k) {
    if (k > 0) integ->advance(*sc.sys, s, 0.005 * k);
    r.energy.push_back(sc.sys->kineticEnergy(s, ws) + sc.sys->potentialEnergy(s, ws));
    for (double g : sc.u->gaps(sc.sys->model(), s, ws.sk)) r.deepest = std::max(r.deepest, -g);
  }
  return r;
}

TEST(CollisionShapes, EllipsoidOnItsShortestAxisStaysAtRest) {
  Scene sc;
  State s = sc.sys->defaultState();
  s.q[1] = kSemiAxes[1];           // touching, upright
  s.q.segment<3>(6) = Vec3(2, 0.1, 0);  // the ball resting on the floor, away from the bar
  const SceneRun r = runScene(sc, s, 2.0);
  DynamicsWorkspace ws(*sc.sys);
  std::printf("[ measured ] upright ellipsoid after 2 s: height error %.2e m, tilt %.2e rad, kinetic energy %.2e J\n",
              s.q[1] - kSemiAxes[1], s.q.segment<3>(3).norm(), sc.sys->kineticEnergy(s, ws));
  EXPECT_NEAR(s.q[1], kSemiAxes[1], 1e-9);
  EXPECT_LT(s.q.segment<3>(3).norm(), 1e-12);
  EXPECT_LT(sc.sys->kineticEnergy(s, ws), 1e-12);
}

TEST(CollisionShapes, TiltedEllipsoidRocksTowardItsShortestAxisLosingEnergy) {
  // released at rest tilted 0.3 rad about z, touching the floor: the support point is not under the
  // centre, so it rocks back. The rows are first order in the contact point, which slides along
  // the curved surface as it rocks, so it sinks in a little; the stabilization pushes that out
  // (beyond the 1e-5 m slop) and adds the only energy the step ever adds
  Scene sc;
  State s = sc.sys->defaultState();
  const double tilt0 = 0.3;
  s.q[1] = std::hypot(kSemiAxes[0] * std::sin(tilt0), kSemiAxes[1] * std::cos(tilt0));
  s.q[5] = tilt0;
  s.q.segment<3>(6) = Vec3(2, 0.1, 0);
  const SceneRun r = runScene(sc, s, 2.0);
  double rise = 0.0;
  for (size_t k = 1; k < r.energy.size(); ++k) rise = std::max(rise, r.energy[k] - r.energy[k - 1]);
  std::printf("[ measured ] tilted ellipsoid, 2 s: energy %.6f -> %.6f J (largest rise over 5 ms %.2e J), tilt %.3f "
              "rad, deepest penetration %.2e m\n",
              r.energy.front(), r.energy.back(), rise, s.q[5], r.deepest);
  EXPECT_LT(rise, 1e-3);       // measured 3.7e-4 J (the stabilization's push)
  EXPECT_LT(r.energy.back(), r.energy.front() - 0.05);  // measured 0.090 J lost
  EXPECT_LT(std::abs(s.q[5]), tilt0);
  EXPECT_LT(r.deepest, 1e-4);  // measured 4.8e-5 m
}

TEST(CollisionShapes, BallSlidingIntoABarStopsAgainstIt) {
  // the bar at the ball's centre height (axis 0.1 high along z); frictionless, the ball slides
  // at it from x = -0.5 at 1 m/s, meets it along the horizontal normal and stops there
  // (restitution 0): centre 0.15 from the axis, x = -0.15
  Scene sc(0.1, 0.0);
  State s = sc.sys->defaultState();
  s.q.segment<3>(0) = Vec3(3, kSemiAxes[1], 0);  // the ellipsoid out of the way, upright
  s.q.segment<3>(6) = Vec3(-0.5, 0.1, 0.1);
  s.qdot[6] = 1.0;
  const SceneRun r = runScene(sc, s, 2.0);
  DynamicsWorkspace ws(*sc.sys);
  const double x_rest = -0.15;
  std::printf("[ measured ] ball against the bar after 2 s: x %.7f m (geometry %.7f), height %.7f m, speed %.2e m/s, "
              "deepest penetration %.2e m\n",
              s.q[6], x_rest, s.q[7], s.qdot.segment<3>(6).norm(), r.deepest);
  EXPECT_NEAR(s.q[6], x_rest, 2e-5);
  EXPECT_NEAR(s.q[7], 0.1, 2e-5);
  EXPECT_LT(s.qdot.segment<3>(6).norm(), 1e-6);
  EXPECT_LT(r.deepest, 5e-4);
}

TEST(CollisionShapes, BadPairsAreRefused) {
  ModelBuilder b("two");
  b.addBody("a", 1.0, Vec3::Zero(), Mat3::Identity(), -1, "fa", Free3D{});
  const Model m = b.finalize();
  CollisionGeometry ell{"e", CollisionShape::Ellipsoid, 0, Mat4::Identity(), 0.0, 0.0, Vec3(0.1, 0.0, 0.1)};
  EXPECT_THROW(UnilateralConstraints(m, {test::groundPlane(), ell}, {{0, 1, 0.0, 0.0}}, {}), ModelError);  // a zero semi-axis
  ell.half_extents = Vec3(0.1, 0.2, 0.1);
  CollisionGeometry cap{"c", CollisionShape::Capsule, -1, Mat4::Identity(), 0.05, 0.2, Vec3::Zero()};
  try {
    UnilateralConstraints(m, {ell, cap}, {{0, 1, 0.0, 0.0}}, {});
    ADD_FAILURE() << "an ellipsoid-capsule pair was accepted";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("ellipsoid against capsule"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace redmax
