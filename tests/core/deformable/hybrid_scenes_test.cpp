// The hybrid-dynamics scenes of [D Sec. 6.1.2-6.1.3] (validation/scenes/hybrid_scenes, docs/
// deformable.md §6): what their prescriptions achieve, with the levels explained.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/system.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "mesh_checks.hpp"
#include "validation/scenes/hybrid_scenes.hpp"

namespace redmax {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(Hand, PrescribedPointsAndAngleHoldToRoundOffWithProjection) {
  const scenes::HandOptions opt;  // bdf1, dt 1e-3 s, 2 s, projection every step
  const scenes::HandResult r = scenes::runHand(opt);
  EXPECT_EQ(r.nr, 19);
  EXPECT_EQ(r.nR, 15);   // four DIPs eliminated
  EXPECT_EQ(r.rows, 13);
  // the projection's Newton steps stop at max |C| <= 1e-14 per row (measured 1.7e-16 m); the
  // elbow row is linear in q, so one Newton step meets it exactly
  EXPECT_LE(r.point_error, 2e-14);
  EXPECT_EQ(r.angle_error, 0.0);
  // DIP = 0.5 PIP by the coordinate map, exactly in floating point
  EXPECT_EQ(r.coupling_deviation, 0.0);
  // within a step (before its projection) the velocity-level rows leave the position error of
  // one step: for the elbow q_p(t+h) - q_p(t) - h qdot_p(t+h) = -h^2/2 qddot_p, largest
  // A w^2 h^2 / 2
  const double w = 2 * kPi * opt.elbow_frequency;
  EXPECT_NEAR(r.angle_step_error, opt.elbow_amplitude * w * w * opt.dt * opt.dt / 2, 1e-3 * r.angle_step_error);
  // and the fingertips' is second order too (measured 8.63e-8 m at dt 1e-3, 2.19e-8 m at 5e-4)
  scenes::HandOptions half = opt;
  half.dt = opt.dt / 2;
  const scenes::HandResult rh = scenes::runHand(half);
  EXPECT_NEAR(r.point_step_error / rh.point_step_error, 4.0, 0.1);
  EXPECT_NEAR(r.point_step_error, 8.63e-8, 0.1e-8);
}

TEST(Hand, WithoutProjectionTheElbowDriftsByTheFirstOrderStepError) {
  scenes::HandOptions opt;
  opt.project = false;
  const scenes::HandResult r = scenes::runHand(opt);
  // the per-step errors -h^2/2 qddot_p add up to -h/2 (qdot_p(t) - qdot_p(0)) (the velocity is
  // exact after every step), largest h A w
  const double w = 2 * kPi * opt.elbow_frequency;
  EXPECT_NEAR(r.angle_error, opt.dt * opt.elbow_amplitude * w, 1e-2 * r.angle_error);
  // the fingertips drift at the same first-order rate (measured 2.04e-5 m at dt 1e-3)
  EXPECT_NEAR(r.point_error, 2.04e-5, 0.05e-5);
  EXPECT_EQ(r.coupling_deviation, 0.0);
}

TEST(Hand, AtRestTheMultipliersBalanceGravityAboutTheElbow) {
  // elbow and tips held still: once the passive wrist has settled, the elbow torque and the tip
  // forces (the prescriptions' multipliers) balance the weights: about the elbow axis (z through
  // the origin) lambda_elbow + sum (x_tip x F_tip)_z + sum (x_com x m g)_z = 0
  scenes::HandOptions opt;
  opt.elbow_amplitude = 0.0;
  opt.tip_radius = 0.0;
  opt.duration = 3.0;
  const scenes::HandResult r = scenes::runHand(opt);
  const Model m = scenes::handModel();
  const VecX& row = r.run.rows.back();
  std::vector<Mat4> E;
  calcBodyPoses(m, row.head(m.nr()), E);
  double moment = row[m.nr()], weight_moment = 0.0;
  for (int i = 0; i < m.nb(); ++i) {
    const Vec3 c = transformPoint(E[i], m.bodies()[i].com);
    weight_moment += c.cross(m.bodies()[i].mass * m.gravity())[2];
  }
  moment += weight_moment;
  const auto& pts = r.run.points.back();
  for (int f = 0; f < 4; ++f) moment += pts[2 + 4 * f + 3].cross(Vec3(row.segment<3>(m.nr() + 1 + 3 * f)))[2];
  EXPECT_LE(std::abs(moment), 1e-13 * std::abs(weight_moment)) << moment << " of " << weight_moment;
  std::printf("hand at rest: moment residual %.2e N m of a weight moment %.4f N m\n", moment, weight_moment);
  // (measured 5.6e-17 N m: the wrist has settled, so the residual is round-off)
  // the net vertical force the tips take is less than the hand's weight (the elbow's joint
  // reaction carries the rest); it is upward
  double tips_y = 0;
  for (int f = 0; f < 4; ++f) tips_y += row[m.nr() + 1 + 3 * f + 1];
  EXPECT_GT(tips_y, 0.0);
}

TEST(Hand, PrescribingEveryIndependentJointGivesTheHyperReducedInverseDynamics) {
  // [D Eq. 4.109] with DIP = 0.5 PIP: prescribing all 15 independent coordinates, the multipliers
  // are the torques tau_R = J_rR^T (M_r qddot_r - f_r) that the mapped system's inverse dynamics
  // gives for the same motion (the DIP's torque shared into its PIP through J_rR)
  // (measured 1e-15 to 1e-14 relative: round-off of the KKT solve)
  const Model m = scenes::handModel();
  auto map = std::make_shared<CoordinateMap>(m);
  for (int f = 0; f < 4; ++f) map->addDependent(3 + 4 * f + 3, {3 + 4 * f + 2}, makeLinearFunction({0.5}));
  System plain(m);
  plain.setCoordinateMap(map);
  System sys = plain;
  const int n = plain.ndof();
  std::vector<double> amp(n), w(n), ph(n);
  for (int i = 0; i < n; ++i) {
    amp[i] = 0.2 + 0.03 * i;
    w[i] = 1.0 + 0.25 * i;
    ph[i] = 0.7 * i;
  }
  for (int i = 0; i < n; ++i) {
    const int k = map->independent()[i];
    const double a = amp[i], wi = w[i], p = ph[i], q0 = m.coordinates()[k].default_value;
    sys.addConstraint(std::make_shared<PrescribedCoordinate>(
        m, k,
        makeConstraintFunction1([=](double t) { return q0 + a * std::sin(wi * t + p); },
                                [=](double t) { return a * wi * std::cos(wi * t + p); },
                                [=](double t) { return -a * wi * wi * std::sin(wi * t + p); })));
  }
  DynamicsWorkspace ws(sys), ws_id(plain);
  for (double t : {0.2, 1.3}) {
    State s = sys.defaultState();
    s.t = t;
    VecX qdd(n);
    for (int i = 0; i < n; ++i) {
      const int k = map->independent()[i];
      s.q[i] = m.coordinates()[k].default_value + amp[i] * std::sin(w[i] * t + ph[i]);
      s.qdot[i] = amp[i] * w[i] * std::cos(w[i] * t + ph[i]);
      qdd[i] = -amp[i] * w[i] * w[i] * std::sin(w[i] * t + ph[i]);
    }
    EXPECT_LE((sys.forwardDynamics(s, ws) - qdd).norm(), 1e-12 * qdd.norm());
    const VecX tau = plain.inverseDynamics(s, qdd, ws_id);
    EXPECT_LE((ws.lambda - tau).norm(), 1e-12 * tau.norm()) << (ws.lambda - tau).norm() / tau.norm();
    EXPECT_LE((sys.prescribedForces(ws) - tau).norm(), 1e-12 * tau.norm());
    std::printf("hand, every joint prescribed at t = %.1f: |lambda - tau_ID| / |tau_ID| = %.1e\n", t,
                (ws.lambda - tau).norm() / tau.norm());
  }
}

TEST(StarMesh, TetsArePositiveAndFacesConform) {
  const TetMesh mesh = scenes::makeStarTetMesh();  // 5 arms, 20 angles, 4 rings, 3 node layers
  EXPECT_EQ(mesh.numNodes(), 3 * (1 + 4 * 20));
  EXPECT_EQ(mesh.numTets(), 2 * 3 * (20 + 3 * 20 * 2));
  double volume = 0;
  for (const auto& t : mesh.tets) {
    const double v = tetVolume(mesh.nodes, t);
    EXPECT_GT(v, 0.0);
    volume += v;
  }
  // conforming: every face is shared by two tets or lies on the boundary, which is the top and
  // bottom (140 triangles each) and the rim (20 quads per layer, 2 triangles each)
  EXPECT_EQ(testing::boundaryFaces(mesh), 2 * 140 + 2 * 20 * 2);
  // the slab's volume is its top area times the thickness: the polygon's area by the shoelace
  double area = 0;
  for (int j = 0; j < 20; ++j) {
    const Vec3 &a = mesh.nodes[1 + 3 * 20 + j], &b = mesh.nodes[1 + 3 * 20 + (j + 1) % 20];
    area += (b.x() * a.z() - a.x() * b.z()) / 2;  // x-z plane seen from +y
  }
  EXPECT_NEAR(volume, std::abs(area) * 0.06, 1e-14);
}

TEST(Starfish, RunsStablyTheJointsFollowAndNoTetInverts) {
  scenes::StarfishOptions opt;
  opt.duration = 0.3;  // 150 steps of 2 ms
  const scenes::StarfishResult r = scenes::runStarfish(opt);
  EXPECT_EQ(r.joints, 20);
  EXPECT_EQ(r.prescribed, 5);
  EXPECT_EQ(r.nodes, 243);
  EXPECT_EQ(r.tets, 840);
  EXPECT_EQ(r.ndof, 6 + 20 + 3 * (r.nodes - r.attached));  // the disc's free joint, hinges, free nodes
  EXPECT_EQ(r.steps, 150);
  for (const VecX& row : r.run.rows) EXPECT_TRUE(row.allFinite());
  // bdf1 meets a prescribed row at the velocity level [D Eq. 4.110]: whatever the dynamics, the
  // step from t_k sets qdot = qdot_p(t_k) + h qddot_p(t_k) and q += h qdot, so the error
  // q_p(t_n) - q_n follows from the trajectory alone (first order in h). Both kinds of rows here are
  // linear in q (the joints; the disc centre is its free joint's translation), so the prediction
  // holds to round-off.
  auto drift = [&](double A, double w, double ph) {
    double q = 0, worst = 0;  // q_n - q_p(0)
    for (int k = 0; k < r.steps; ++k) {
      const double t = k * opt.dt;
      q += opt.dt * (A * w * std::cos(w * t + ph) - opt.dt * A * w * w * std::sin(w * t + ph));
      const double tn = (k + 1) * opt.dt;
      worst = std::max(worst, std::abs(A * std::sin(w * tn + ph) - A * std::sin(ph) - q));
    }
    return worst;
  };
  double predicted = 0;
  for (int a = 0; a < 5; ++a) predicted = std::max(predicted, drift(opt.amplitude, 2 * kPi * opt.frequency, 2 * kPi * a / 5));
  const double predicted_point = drift(opt.disc_amplitude, 2 * kPi * opt.disc_frequency, 0.0);
  EXPECT_NEAR(r.prescribed_error, predicted, 1e-9 * predicted);
  EXPECT_NEAR(r.point_error, predicted_point, 1e-9 * predicted_point);
  // no tet inverts: the smallest volume / rest volume is measured (0.7633 over these 0.3 s, 0.63
  // over the scene's 2 s) and asserted near it; the motion is bounded (largest kinetic energy
  // measured 0.0243 J here, 0.039 J over 2 s)
  EXPECT_GT(r.min_volume_ratio, 0.0);
  EXPECT_NEAR(r.min_volume_ratio, 0.7633, 0.005);
  EXPECT_NEAR(r.max_kinetic, 0.0243, 0.0005);
  std::printf("starfish 0.3 s: prescribed error %.3e rad (predicted %.3e), point %.3e m (predicted %.3e), "
              "smallest volume ratio %.4f, largest kinetic %.4f J\n",
              r.prescribed_error, predicted, r.point_error, predicted_point, r.min_volume_ratio, r.max_kinetic);
}

}  // namespace
}  // namespace redmax
