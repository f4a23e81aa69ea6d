// redmax's hard contact against MuJoCo's soft contact on the same scenes (docs/contact.md §6.4a,
// validation/peers/mujoco_scenes.hpp). Bounds sit near the values measured with MuJoCo 2.2.2
// (Debian's libmujoco-dev), quoted beside each. Without libmujoco-dev the suite is one visible skip.
#include <gtest/gtest.h>

#ifdef REDMAX_HAVE_MUJOCO

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "validation/peers/mujoco_scenes.hpp"
#include "validation/scenes/contact_scenes.hpp"

namespace redmax {
namespace {

constexpr double kG = 9.81;

TEST(MujocoContact, BallFirstImpactAndFreeFallAgree) {
  const scenes::BallDropOptions o;
  const scenes::BallDropResult r = scenes::runBallDrop(o);
  peers::MujocoModel m(peers::ballDropMjcf(o, {}));
  const peers::MjBallDropResult j = peers::runBallDrop(m, o);
  std::vector<double> t, h, v;
  for (const VecX& row : r.run.rows) t.push_back(row[0]), h.push_back(row[2] - o.radius), v.push_back(row[8]);
  const double closed = std::sqrt(2 * o.drop_height / kG);  // 0.31928 s
  const double tr = peers::firstImpactTime(t, v, kG);
  // measured: redmax 0.319 s (it takes the impact at the start of the closing step), MuJoCo
  // 0.320 s (its contact acts once the sphere is below the plane)
  EXPECT_NEAR(tr, closed, o.dt);
  EXPECT_NEAR(j.first_impact, closed, o.dt);
  EXPECT_LE(std::abs(tr - j.first_impact), o.dt + 1e-12);
  // both integrate free fall as semi-implicit Euler: the same heights up to rounding (3.6e-16 m)
  ASSERT_GT(tr, 0.3);
  for (size_t k = 0; k + 1 < static_cast<size_t>(std::lround(tr / o.dt)); ++k)
    ASSERT_NEAR(h[k], j.height.y[k], 1e-12) << "step " << k;
}

TEST(MujocoContact, BallRestsWithMujocosPenetration) {
  const scenes::BallDropOptions o;
  const scenes::BallDropResult r = scenes::runBallDrop(o);
  peers::MujocoModel m(peers::ballDropMjcf(o, {}));
  const peers::MjBallDropResult j = peers::runBallDrop(m, o);
  // redmax: hard, on the radius (2e-11 m); MuJoCo's defaults (solref 0.02 1, critically damped):
  // no bounce, rests 3.67e-4 m deep, 2.15e-2 m deep at the impact
  EXPECT_NEAR(r.rest_height, o.radius, 1e-8);
  EXPECT_TRUE(j.apexes.empty());
  EXPECT_GT(o.radius - j.rest_height, 2e-4);
  EXPECT_LT(o.radius - j.rest_height, 6e-4);
  EXPECT_GT(j.max_penetration, 1e-2);
  EXPECT_LT(j.max_penetration, 3e-2);
}

TEST(MujocoContact, BouncySolrefBouncesNearTheRestitution) {
  const scenes::BallDropOptions o;  // e 0.5: apexes e^(2k) h0 = 0.125, 0.03125, 0.0078 m
  peers::MujocoModel m(peers::ballDropMjcf(o, peers::bouncyContact(o.restitution)));
  const peers::MjBallDropResult j = peers::runBallDrop(m, o);
  // measured 0.1331, 0.0450, 0.0126 m: MuJoCo's impedance makes it livelier than the linear
  // spring-damper the damping was chosen from, more so on slower impacts
  ASSERT_GE(j.apexes.size(), 3u);
  EXPECT_NEAR(j.apexes[0], 0.125, 0.0125);
  EXPECT_GT(j.apexes[1], 0.03125);
  EXPECT_LT(j.apexes[1], 0.055);
  EXPECT_LT(j.apexes[2], j.apexes[1]);
  EXPECT_NEAR(j.rest_height, o.radius, 5e-5);  // measured 0.0999891 m: stiffer than the default
}

TEST(MujocoContact, BlockSlideDistanceAgreesWithClosedFormAndRedmax) {
  const scenes::BlockSlideOptions o;
  const double closed = o.v0 * o.v0 / (2 * o.friction * kG);  // 0.407747 m
  const scenes::BlockSlideResult r = scenes::runBlockSlide(o);  // 0.406748 m
  std::vector<double> x;
  for (const VecX& row : r.run.rows) x.push_back(row[1]);
  for (bool elliptic : {false, true}) {
    SCOPED_TRACE(elliptic ? "elliptic cone" : "pyramidal cone");
    peers::MjContactParams p;
    p.elliptic_cone = elliptic;
    peers::MujocoModel m(peers::blockSlideMjcf(o, p));
    const peers::MjBlockSlideResult j = peers::runBlockSlide(m, o);
    // measured 0.406964 m (pyramidal), 0.406955 m (elliptic): -0.19 % of the closed form,
    // +0.05 % of redmax's; the x trajectories differ by 2.8e-4 m at most
    EXPECT_NEAR(j.distance, closed, 0.005 * closed);
    EXPECT_NEAR(j.distance, r.distance, 0.001 * closed);
    double d = 0.0;
    for (size_t k = 0; k < std::min(x.size(), j.x.y.size()); ++k) d = std::max(d, std::abs(x[k] - j.x.y[k]));
    EXPECT_LT(d, 1e-3);
    EXPECT_LT(j.final_speed, 1e-9);            // at rest at 1 s (1.6e-12 m/s)
    EXPECT_GT(j.stop_time, r.stop_time);       // soft friction creeps: 0.434 / 0.442 s against 0.408 s
    EXPECT_LT(j.stop_time, r.stop_time + 0.05);
    EXPECT_LT(j.max_penetration, 5e-4);        // 2.3e-4 m / 2.0e-4 m
  }
}

TEST(MujocoContact, BoxStacksSettle) {
  const scenes::BoxStackOptions o;
  const scenes::BoxStackResult r = scenes::runBoxStack(o);
  // redmax: 9.8e-11 m/s, 9.8e-11 m
  EXPECT_LT(r.drift_per_second, 1e-8);
  EXPECT_LT(r.max_penetration, 1e-8);
  peers::MujocoModel mp(peers::boxStackMjcf(o, {}));
  const peers::MjBoxStackResult jp = peers::runBoxStack(mp, o);
  // pyramidal: drift 6.9e-7 m/s, 6.8e-5 m deep
  EXPECT_LT(jp.drift_per_second, 5e-6);
  EXPECT_GT(jp.max_penetration, 1e-5);
  EXPECT_LT(jp.max_penetration, 5e-4);
  peers::MjContactParams p;
  p.elliptic_cone = true;
  peers::MujocoModel me(peers::boxStackMjcf(o, p));
  const peers::MjBoxStackResult je = peers::runBoxStack(me, o);
  // elliptic: drift 9.3e-11 m/s, 3.7e-4 m deep
  EXPECT_LT(je.drift_per_second, 1e-8);
  EXPECT_GT(je.max_penetration, 1e-4);
  EXPECT_LT(je.max_penetration, 1e-3);
}

TEST(MujocoContact, BadMjcfIsAClearError) {
  try {
    peers::MujocoModel m("<mujoco><worldbody><geom type=\"nosuchshape\"/></worldbody></mujoco>");
    FAIL() << "loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("MuJoCo could not load"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace redmax

#else

TEST(MujocoContact, SkippedWithoutMujoco) {
  GTEST_SKIP() << "MuJoCo not installed (libmujoco-dev): the redmax/MuJoCo contact comparison is not built";
}

#endif
