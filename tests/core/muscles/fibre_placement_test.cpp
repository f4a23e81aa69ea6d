// Fibre-following mass points (core/muscles/fibre_placement.hpp), checked by central differences
// on random trees (Type I and Type II paths with a moving point), with OpenSim's
// Thelen2003Muscle (elastic tendon, fibre-length state, pennation 0.3 rad at l_opt) and
// Millard2012EquilibriumMuscle with a rigid tendon:
//   x_a(q, z) vs J_ar (per coordinate, states held)    x_a vs J_aT (fibre length, q held)
//   x_a along the motion (q + h qdot, z + h zdot) vs J_ar qdot + v_z
//   J_ar along the motion vs Jdot_ar                   xdot_a along the motion vs Jdot_ar qdot + a_z
// (h = 1e-6), plus the two facts the derivation takes from the models (the tendon length's
// slope in the fibre length is -1 / cos(pennation); the fibre's rate does not depend on the path's
// speed) and the closed form: a rigid tendon at l_MT = l_opt + l_ts puts the points exactly where
// the uniform (equal-strain) placement does.
#include "core/muscles/fibre_placement.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/muscles/hill/factory.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "tests/core/dynamics/random_muscle.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

constexpr double kH = 1e-6;

std::shared_ptr<const hill::MuscleModel> makeModel(const std::string& cls, double l_opt, double l_ts, bool rigid) {
  hill::MuscleParameters p;
  p.name = "m";
  p.set("max_isometric_force", 1500.0);
  p.set("optimal_fiber_length", l_opt);
  p.set("tendon_slack_length", l_ts);
  p.set("pennation_angle_at_optimal", 0.3);
  p.set("ignore_tendon_compliance", rigid ? 1 : 0);
  return hill::makeMuscleModel(cls, p);
}

struct Case {
  Model m;
  Muscle mu;
  State s;
  std::vector<double> z, zdot;  // the muscle's states and their rates at s
  double u = 0.7;               // excitation
};

double lengthAt(const Model& m, const Muscle& mu, const VecX& q) {
  std::vector<Mat4> E;
  calcBodyPoses(m, q, E);
  return calcPathLength(m, mu.path, q, E);
}

// a random tree and a fibre-following muscle whose l_opt + l_ts is near its length at s; the
// fibre 2% off its equilibrium at activation 0.4 (so that it moves)
Case makeCase(unsigned seed, bool type1, const std::string& cls, bool rigid) {
  Case c;
  c.m = scenes::randomTree(5, seed, scenes::TreeJoints::SimbodyComparable);
  std::mt19937 rng(seed);
  c.s = test::randomState(c.m.nr(), rng, 0.6, 1.5);
  c.mu = test::randomViaMuscle(c.m, rng, 1.2, "m");
  if (type1) c.mu.path.points = {c.mu.path.points.front(), c.mu.path.points.back()};
  const double L = lengthAt(c.m, c.mu, c.s.q);
  c.mu.optimal_fiber_length = 0.45 * L;
  c.mu.tendon_slack_length = 0.5 * L;
  auto model = makeModel(cls, c.mu.optimal_fiber_length, c.mu.tendon_slack_length, rigid);
  std::vector<Mat4> E;
  calcBodyPoses(c.m, c.s.q, E);
  setFibrePlacement(c.m, c.s.q, E, model, c.mu);
  validateMuscle(c.m, c.mu);
  const int n = model->numStates();
  c.z.assign(n, 0.0);
  c.zdot.assign(n, 0.0);
  model->defaultState(c.z.data());
  const auto& names = model->stateNames();
  for (int j = 0; j < n; ++j)
    if (names[j] == "activation") c.z[j] = 0.4;
  hill::MusculotendonInput in;
  in.length = L;
  in.excitation = 0.4;
  model->equilibrate(in, c.z.data());
  if (c.mu.fibre.fiber_state >= 0) c.z[c.mu.fibre.fiber_state] *= 1.02;
  // rates at s
  SkeletonWorkspace sk(c.m);
  calcKinematics(c.m, c.s, sk);
  MuscleKinematics mk;
  calcPathPoints(c.m, c.s, sk, c.mu.path, mk, true);
  in.length = mk.length;
  in.speed = mk.lengthening_speed;
  in.excitation = c.u;
  hill::MuscleOutput out;
  model->calc(c.z.data(), in, out, c.zdot.data());
  return c;
}

MuscleKinematics eval(const Case& c, const State& s, const std::vector<double>& z, bool velocity = true) {
  SkeletonWorkspace sk(c.m);
  calcKinematics(c.m, s, sk);
  MuscleWorkspace ws(c.m, {c.mu});
  calcMuscleKinematics(c.m, s, sk, c.mu, ws.muscles[0], velocity, FibreStates{z.data(), c.u});
  MuscleKinematics mk = ws.muscles[0];
  test::expandAll(mk, c.m.nr());
  return mk;
}

VecX stack(const std::vector<Vec3>& v) {
  VecX x(3 * v.size());
  for (size_t i = 0; i < v.size(); ++i) x.segment<3>(3 * i) = v[i];
  return x;
}

double relErr(const MatX& a, const MatX& b) { return (a - b).norm() / (1.0 + b.norm()); }

// the state moved by t along the motion (q + t qdot, z + t zdot)
State moved(const Case& c, double t, std::vector<double>& z) {
  z = c.z;
  for (size_t j = 0; j < z.size(); ++j) z[j] += t * c.zdot[j];
  return test::along(c.s, t);
}

struct Worst {
  double J = 0, JT = 0, v = 0, Jdot = 0, acc = 0;
  int checked = 0, skipped = 0;
};

void checkCase(const Case& c, Worst& w) {
  const MuscleKinematics k = eval(c, c.s, c.z);
  std::vector<double> zp, zm;
  const State sp = moved(c, kH, zp), sm = moved(c, -kH, zm);
  const MuscleKinematics kp = eval(c, sp, zp), km = eval(c, sm, zm);
  // a point changed segment inside the stencil, or no coordinate moves the path (no columns)
  if (kp.segment != k.segment || km.segment != k.segment || kp.active != k.active || k.J_ar.cols() != c.m.nr()) {
    ++w.skipped;
    return;
  }
  ++w.checked;
  const int N = c.mu.mass_points.size(), nr = c.m.nr();
  // J_ar: each coordinate, states held
  MatX J(3 * N, nr);
  for (int j = 0; j < nr; ++j) {
    State a = c.s, b = c.s;
    a.q[j] += kH;
    b.q[j] -= kH;
    J.col(j) = (stack(eval(c, a, c.z, false).x_a) - stack(eval(c, b, c.z, false).x_a)) / (2 * kH);
  }
  w.J = std::max(w.J, relErr(k.J_ar, J));
  // J_aT through the fibre length: dx_a/dl_M = -J_aT / cos(pennation)
  if (c.mu.fibre.fiber_state >= 0) {
    const int f = c.mu.fibre.fiber_state;
    std::vector<double> za = c.z, zb = c.z;
    za[f] += kH;
    zb[f] -= kH;
    const VecX dx = (stack(eval(c, c.s, za, false).x_a) - stack(eval(c, c.s, zb, false).x_a)) / (2 * kH);
    hill::MusculotendonInput in;
    in.length = k.length;
    in.speed = k.lengthening_speed;
    in.excitation = c.u;
    hill::MuscleOutput out;
    std::vector<double> r(c.z.size());
    c.mu.fibre.model->calc(c.z.data(), in, out, r.data());
    w.JT = std::max(w.JT, relErr(-k.J_aT / std::cos(out.pennation_angle), dx));
  } else {
    EXPECT_EQ(k.v_z.norm(), 0.0);
    EXPECT_EQ(k.a_z.norm(), 0.0);
  }
  // velocity, Jdot and the bias acceleration along the motion
  const VecX xdot = (stack(kp.x_a) - stack(km.x_a)) / (2 * kH);
  w.v = std::max(w.v, relErr(k.J_ar * c.s.qdot + k.v_z, xdot));
  w.Jdot = std::max(w.Jdot, relErr(k.Jdot_ar, (kp.J_ar - km.J_ar) / (2 * kH)));
  const VecX xddot = ((kp.J_ar * c.s.qdot + kp.v_z) - (km.J_ar * c.s.qdot + km.v_z)) / (2 * kH);
  w.acc = std::max(w.acc, relErr(k.Jdot_ar * c.s.qdot + k.a_z, xddot));
}

TEST(FibrePlacement, JacobiansMatchCentralDifferences) {
  for (const auto& [cls, rigid] : {std::pair{"Thelen2003Muscle", false}, std::pair{"Millard2012EquilibriumMuscle", true},
                                   std::pair{"Millard2012EquilibriumMuscle", false}}) {
    Worst w;
    for (unsigned seed = 1; seed <= 12; ++seed)
      for (bool type1 : {true, false}) {
        SCOPED_TRACE(std::string(cls) + (rigid ? " rigid" : " elastic") + " seed " + std::to_string(seed) +
                     (type1 ? " Type I" : " Type II"));
        checkCase(makeCase(seed, type1, cls, rigid), w);
      }
    std::printf("%s %s: %d checked, %d skipped; worst J %.2e, J_aT %.2e, velocity %.2e, Jdot %.2e, acceleration %.2e\n",
                cls, rigid ? "rigid" : "elastic", w.checked, w.skipped, w.J, w.JT, w.v, w.Jdot, w.acc);
    EXPECT_GE(w.checked, 20);  // measured 22 of 24 (a point crossing a via point, or a path no coordinate moves)
    // measured (relative, 3 models): J <= 3.2e-10, J_aT <= 1.9e-10, velocity <= 2.0e-10, Jdot <= 2.8e-10,
    // acceleration <= 1.0e-7 (elastic: the central difference of the fibre's rate), 1.9e-10 (rigid)
    EXPECT_LT(w.J, 2e-9);
    EXPECT_LT(w.JT, 2e-9);
    EXPECT_LT(w.v, 2e-9);
    EXPECT_LT(w.Jdot, 2e-9);
    EXPECT_LT(w.acc, rigid ? 2e-9 : 5e-7);
  }
}

// what the derivation takes from the models: d l_T / d l_M = -1 / cos(pennation) (fixed-width
// pennation) and a fibre rate that does not depend on the path's lengthening speed
TEST(FibrePlacement, ModelsHaveFixedWidthPennationAndSpeedFreeFibreRate) {
  for (const char* cls : {"Thelen2003Muscle", "Millard2012EquilibriumMuscle"}) {
    SCOPED_TRACE(cls);
    auto model = makeModel(cls, 0.1, 0.25, false);
    const int f = fiberStateIndex(*model);
    ASSERT_GE(f, 0);
    std::vector<double> z(model->numStates()), zd(z.size()), zp, zm, rp(z.size()), rm(z.size());
    model->defaultState(z.data());
    z[0] = 0.5;
    hill::MusculotendonInput in;
    in.length = 0.36;
    in.speed = 0.2;
    in.excitation = 0.8;
    for (double lM : {0.08, 0.1, 0.12}) {
      z[f] = lM;
      hill::MuscleOutput out, op, om;
      model->calc(z.data(), in, out, zd.data());
      zp = z, zm = z;
      zp[f] += 1e-7;
      zm[f] -= 1e-7;
      model->calc(zp.data(), in, op, rp.data());
      model->calc(zm.data(), in, om, rm.data());
      const double slope = (op.tendon_length - om.tendon_length) / 2e-7;
      EXPECT_NEAR(slope, -1.0 / std::cos(out.pennation_angle), 1e-7);
      hill::MusculotendonInput fast = in;
      fast.speed = -1.5;
      model->calc(z.data(), fast, op, rp.data());
      EXPECT_EQ(rp[f], zd[f]);
    }
  }
}

// closed form: with a rigid tendon and l_MT = l_opt + l_ts the fibre takes l_opt of the path, as
// the uniform placement's fibre share phi = l_opt / (l_opt + l_ts) does: same points
TEST(FibrePlacement, RigidTendonAtRestLengthEqualsUniform) {
  Case c = makeCase(7, true, "Millard2012EquilibriumMuscle", true);
  const double L = lengthAt(c.m, c.mu, c.s.q);
  const double l_opt = 0.4 * L, l_ts = L - l_opt;
  Muscle uniform = c.mu;
  uniform.fibre = FibreFollowing{};
  uniform.mass_points = makeMassPoints(1.2, l_opt, l_ts, MassPointOptions{8});
  c.mu.optimal_fiber_length = l_opt;
  c.mu.tendon_slack_length = l_ts;
  std::vector<Mat4> E;
  calcBodyPoses(c.m, c.s.q, E);
  c.mu.mass_points = uniform.mass_points;
  setFibrePlacement(c.m, c.s.q, E, makeModel("Millard2012EquilibriumMuscle", l_opt, l_ts, true), c.mu);
  c.z.assign(c.mu.fibre.model->numStates(), 0.3);
  const MuscleKinematics kf = eval(c, c.s, c.z);
  const MuscleKinematics ku = test::evalMuscle(c.m, uniform, c.s);
  EXPECT_LT((stack(kf.x_a) - stack(ku.x_a)).norm(), 1e-14);  // measured 1e-16
  for (int a = 0; a < 8; ++a) EXPECT_NEAR(c.mu.mass_points.alpha[a], uniform.mass_points.alpha[a], 1e-14);
}

// without states the fibre is at equilibrium (default activation) and the tendon held there
TEST(FibrePlacement, WithoutStatesTheTendonIsAtEquilibrium) {
  const Case c = makeCase(3, false, "Thelen2003Muscle", false);
  const MuscleKinematics k = eval(c, c.s, c.z);
  const TendonKinematics tk = calcTendonKinematics(c.mu, k.length, k.lengthening_speed, FibreStates{});
  std::vector<double> z(c.mu.fibre.model->numStates()), zd(z.size());
  c.mu.fibre.model->defaultState(z.data());
  hill::MusculotendonInput in;
  in.length = k.length;
  in.speed = k.lengthening_speed;
  in.excitation = z[0];
  c.mu.fibre.model->equilibrate(in, z.data());
  hill::MuscleOutput out;
  c.mu.fibre.model->calc(z.data(), in, out, zd.data());
  EXPECT_EQ(tk.length, out.tendon_length);
  EXPECT_EQ(tk.dT_dL, 0.0);
  EXPECT_EQ(tk.rate, 0.0);
  EXPECT_GT(tk.length, c.mu.tendon_slack_length);  // a stretched tendon, not the slack length
}

}  // namespace
}  // namespace redmax
