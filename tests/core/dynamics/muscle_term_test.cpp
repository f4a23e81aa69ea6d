// MuscleTerm: muscle mass points in the equations of motion [D Eq. 5.6-5.7].
//   - zero muscle mass gives M, f and inverse-dynamics torques identical to the skeleton alone;
//   - analytic hinge cases (Type I, and Type II over a world-fixed via point): effective inertia,
//     quadratic velocity term and gravity torque in closed form, inverse dynamics to 1e-12;
//   - the muscle force is Lagrangian: f_a = -dV/dq - (Mdot qdot - dT/dq), every derivative by
//     central differences (h = 1e-6, relative 1e-6), on random trees with via and moving points;
//   - T = 1/2 qdot^T M qdot; dropping the QVV changes f by exactly -J^T M_a Jdot qdot.
#include "core/dynamics/muscle_term.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/dynamics/system.hpp"
#include "tests/core/dynamics/random_muscle.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {


TEST(MuscleTerm, ZeroMassIsIdenticalToTheSkeleton) {
  const Model m = scenes::randomTree(8, 31, scenes::TreeJoints::SimbodyComparable);
  std::mt19937 rng(5);
  std::vector<Muscle> muscles;
  for (int k = 0; k < 4; ++k) muscles.push_back(test::randomViaMuscle(m, rng, 0.0, "zero" + std::to_string(k)));
  System bare(m), with(m);
  with.addTerm(std::make_shared<MuscleTerm>(m, muscles));
  DynamicsWorkspace wa(m), wb(m);
  for (int trial = 0; trial < 5; ++trial) {
    const State s = test::randomState(m.nr(), rng);
    const VecX qddot = test::randomState(m.nr(), rng).qdot;
    const VecX ta = bare.inverseDynamics(s, qddot, wa);
    const VecX tb = with.inverseDynamics(s, qddot, wb);
    EXPECT_TRUE(wa.M == wb.M);
    EXPECT_TRUE(wa.f == wb.f);
    EXPECT_TRUE(ta == tb);
    EXPECT_EQ(bare.kineticEnergy(s, wa), with.kineticEnergy(s, wb));
    EXPECT_EQ(bare.potentialEnergy(s, wa), with.potentialEnergy(s, wb));
  }
}

// one body on a revolute joint about z through the world origin
Model hinge() {
  ModelBuilder b("hinge");
  b.setGravity(Vec3(0.4, -9.81, 0.3));
  Mat3 I = Vec3(0.02, 0.03, 0.04).asDiagonal();
  b.addBody("arm", 1.2, Vec3(0.3, 0.05, 0.0), I, -1, "pin", Revolute{Vec3::UnitZ()});
  return b.finalize();
}

// tau_muscle = sum_a m_a (|J_a|^2 thddot + (J_a . J_a') thdot^2 - J_a . g), J_a = d x_a / d theta
// (1-DOF Euler-Lagrange of T = 1/2 sum m_a |J_a|^2 thdot^2, V = -sum m_a g . x_a)
struct HingeCase {
  double theta, thdot, thddot;
};

double idDifference(const Model& m, const std::vector<Muscle>& muscles, const HingeCase& c, double* M_eff) {
  System bare(m), with(m);
  with.addTerm(std::make_shared<MuscleTerm>(m, muscles));
  DynamicsWorkspace wa(m), wb(m);
  State s;
  s.q = VecX::Constant(1, c.theta);
  s.qdot = VecX::Constant(1, c.thdot);
  const VecX qddot = VecX::Constant(1, c.thddot);
  const double d = (with.inverseDynamics(s, qddot, wb) - bare.inverseDynamics(s, qddot, wa))[0];
  if (M_eff) *M_eff = wb.M(0, 0) - wa.M(0, 0);
  return d;
}

TEST(MuscleTerm, HingeTypeIMatchesClosedForm) {
  // Straight muscle from world point o to body point x_b. With p(th) = R_z(th) x_b:
  //   x_a = (1 - alpha) o + alpha p,   J_a = alpha p',   p' = z x p = (-p_y, p_x, 0),
  //   p'' = -(p_x, p_y, 0), so |J_a|^2 = alpha^2 r^2 with r^2 = p_x^2 + p_y^2 (distance to the
  //   axis, constant) and J_a . J_a' = alpha^2 p' . p'' = 0:
  //   effective inertia  I_a = r^2 sum m_a alpha_a^2,  no quadratic velocity term,
  //   tau = I_a thddot - sum m_a alpha_a g . p'.
  const Model m = hinge();
  const Vec3 o(0.2, 0.4, 0.1), x_b(0.6, 0.1, 0.05);
  Muscle mu;
  mu.name = "straight";
  mu.path.points = {makeFixedPoint(-1, o), makeFixedPoint(0, x_b)};
  mu.mass_points = makeMassPoints(0.7, 0.3, 0.1, {});
  for (const HingeCase& c : {HingeCase{0.3, 2.0, -1.0}, HingeCase{-1.2, -4.0, 3.0}, HingeCase{2.5, 7.0, 0.5}}) {
    const Vec3 p = rotationAxisAngle(Vec3::UnitZ(), c.theta) * x_b;
    const Vec3 dp(-p.y(), p.x(), 0.0);
    double I_a = 0.0, grav = 0.0;
    for (int a = 0; a < mu.mass_points.size(); ++a) {
      const double al = mu.mass_points.alpha[a], ma = mu.mass_points.mass[a];
      I_a += ma * al * al * (p.x() * p.x() + p.y() * p.y());
      grav += ma * al * m.gravity().dot(dp);
    }
    double M_eff = 0.0;
    const double tau = idDifference(m, {mu}, c, &M_eff);
    const double expected = I_a * c.thddot - grav;
    EXPECT_NEAR(M_eff, I_a, 1e-12 * (1 + I_a));
    EXPECT_NEAR(tau, expected, 1e-12 * (1 + std::abs(expected)));
  }
}

TEST(MuscleTerm, HingeTypeIIOverWorldViaMatchesClosedForm) {
  // Origin o and via point v fixed in the world, insertion p(th) = R_z(th) x_b on the body.
  // l0 = |v - o| is constant, l1 = |p - v|, length = l0 + l1, and equal strain puts mass point
  // alpha at arc length alpha (l0 + l1):
  //   on segment 0 (alpha length < l0): x_a = o + alpha (l0 + l1) u0, u0 = (v - o) / l0
  //       J_a = alpha l1' u0,  J_a' = alpha l1'' u0
  //   on segment 1: x_a = v + beta (p - v), beta = (alpha (l0 + l1) - l0) / l1 = alpha + (alpha - 1) l0 / l1
  //       beta' = (1 - alpha) l0 l1' / l1^2,  beta'' = (1 - alpha) l0 (l1'' / l1^2 - 2 l1'^2 / l1^3)
  //       J_a = beta' (p - v) + beta p',  J_a' = beta'' (p - v) + 2 beta' p' + beta p''
  //   with l1' = (p - v) . p' / l1,  l1'' = (p' . p' + (p - v) . p'') / l1 - l1'^2 / l1,
  //   p' = z x p, p'' = z x p'. Then tau = sum m_a (|J_a|^2 thddot + J_a . J_a' thdot^2 - J_a . g).
  const Model m = hinge();
  const Vec3 o(-0.5, 0.6, 0.0), v(0.1, 0.7, 0.05), x_b(0.7, 0.0, 0.1);
  Muscle mu;
  mu.name = "via";
  mu.path.points = {makeFixedPoint(-1, o), makeFixedPoint(-1, v), makeFixedPoint(0, x_b)};
  mu.mass_points = makeMassPoints(0.9, 0.3, 0.1, {});
  const double l0 = (v - o).norm();
  const Vec3 u0 = (v - o) / l0;
  for (const HingeCase& c : {HingeCase{0.3, 2.0, -1.0}, HingeCase{-0.8, -4.0, 3.0}, HingeCase{1.4, 6.0, 0.5}}) {
    const Vec3 z = Vec3::UnitZ();
    const Vec3 p = rotationAxisAngle(z, c.theta) * x_b;
    const Vec3 dp = z.cross(p), ddp = z.cross(dp);
    const Vec3 d = p - v;
    const double l1 = d.norm();
    const double dl1 = d.dot(dp) / l1;
    const double ddl1 = (dp.dot(dp) + d.dot(ddp)) / l1 - dl1 * dl1 / l1;
    double I_a = 0.0, tau_expected = 0.0;
    for (int a = 0; a < mu.mass_points.size(); ++a) {
      const double al = mu.mass_points.alpha[a], ma = mu.mass_points.mass[a];
      Vec3 J, dJ;
      if (al * (l0 + l1) < l0) {
        J = al * dl1 * u0;
        dJ = al * ddl1 * u0;
      } else {
        const double beta = al + (al - 1.0) * l0 / l1;
        const double db = (1.0 - al) * l0 * dl1 / (l1 * l1);
        const double ddb = (1.0 - al) * l0 * (ddl1 / (l1 * l1) - 2.0 * dl1 * dl1 / (l1 * l1 * l1));
        J = db * d + beta * dp;
        dJ = ddb * d + 2.0 * db * dp + beta * ddp;
      }
      I_a += ma * J.squaredNorm();
      tau_expected += ma * (J.squaredNorm() * c.thddot + J.dot(dJ) * c.thdot * c.thdot - J.dot(m.gravity()));
    }
    double M_eff = 0.0;
    const double tau = idDifference(m, {mu}, c, &M_eff);
    EXPECT_NEAR(M_eff, I_a, 1e-12 * (1 + I_a));
    EXPECT_NEAR(tau, tau_expected, 1e-12 * (1 + std::abs(tau_expected)));
  }
}

class MuscleTermSeeds : public ::testing::TestWithParam<int> {};

TEST_P(MuscleTermSeeds, ForceIsLagrangianAndMassIsKineticEnergyHessian) {
  const Model m = scenes::randomTree(6, 200 + GetParam(), scenes::TreeJoints::SimbodyComparable);
  std::mt19937 rng(GetParam());
  std::vector<Muscle> muscles;
  for (int k = 0; k < 3; ++k) muscles.push_back(test::randomViaMuscle(m, rng, 0.5 + k, "m" + std::to_string(k)));
  const auto term = std::make_shared<MuscleTerm>(m, muscles);
  const State s = test::randomState(m.nr(), rng);
  SkeletonWorkspace sk(m);
  const int n = m.nr();
  // muscle-only M, f, T, V at a state
  auto eval = [&](const State& x, MatX* M, VecX* f, double* T, double* V) {
    calcKinematics(m, x, sk);
    if (M) {
      M->setZero(n, n);
      term->addMass(m, x, sk, *M);
    }
    if (f) {
      f->setZero(n);
      term->addForce(m, x, sk, *f);
    }
    if (T) *T = term->kineticEnergy(m, x, sk);
    if (V) *V = term->potentialEnergy(m, x, sk);
  };
  MatX M;
  VecX f;
  double T = 0.0;
  eval(s, &M, &f, &T, nullptr);
  EXPECT_NEAR(T, 0.5 * s.qdot.dot(M * s.qdot), 1e-12 * (1 + T));
  EXPECT_TRUE(nearRel(M, MatX(M.transpose()), 1e-14));
  // Euler-Lagrange: f = -dV/dq + dT/dq - Mdot qdot (qdot held fixed in the q-differences)
  const double h = 1e-6;
  VecX dV(n), dT(n);
  for (int k = 0; k < n; ++k) {
    State sp = s, sm = s;
    sp.q[k] += h;
    sm.q[k] -= h;
    double Tp, Tm, Vp, Vm;
    eval(sp, nullptr, nullptr, &Tp, &Vp);
    eval(sm, nullptr, nullptr, &Tm, &Vm);
    dV[k] = (Vp - Vm) / (2 * h);
    dT[k] = (Tp - Tm) / (2 * h);
  }
  MatX Mp, Mm;
  eval(test::along(s, h), &Mp, nullptr, nullptr, nullptr);
  eval(test::along(s, -h), &Mm, nullptr, nullptr, nullptr);
  const VecX f_lagrange = -dV + dT - (Mp - Mm) / (2 * h) * s.qdot;
  EXPECT_TRUE(nearRel(f, f_lagrange, 1e-6)) << (f - f_lagrange).norm() << " vs " << f_lagrange.norm();
}

INSTANTIATE_TEST_SUITE_P(Seeds, MuscleTermSeeds, ::testing::Range(0, 4),
                         [](const ::testing::TestParamInfo<int>& i) { return "seed" + std::to_string(i.param); });

TEST(MuscleTerm, DroppingTheQuadraticVelocityVector) {
  const Model m = scenes::randomTree(5, 9, scenes::TreeJoints::SimbodyComparable);
  std::mt19937 rng(2);
  std::vector<Muscle> muscles = {test::randomViaMuscle(m, rng, 1.0, "a"), test::randomViaMuscle(m, rng, 0.5, "b")};
  MuscleTermOptions no_qvv;
  no_qvv.quadratic_velocity = false;
  const MuscleTerm full(m, muscles), dropped(m, muscles, no_qvv);
  State s = test::randomState(m.nr(), rng);
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  VecX f_full = VecX::Zero(m.nr()), f_drop = VecX::Zero(m.nr());
  full.addForce(m, s, sk, f_full);
  dropped.addForce(m, s, sk, f_drop);
  // the difference is -sum J_a^T m_a Jdot_a qdot, computed here from the muscle workspace
  MuscleWorkspace ws(m, muscles);
  calcMuscleKinematics(m, s, sk, muscles, ws);
  VecX qvv = VecX::Zero(m.nr());
  for (size_t k = 0; k < muscles.size(); ++k)
    for (int a = 0; a < muscles[k].mass_points.size(); ++a)
      qvv -= muscles[k].mass_points.mass[a] *
             expandColumns(ws.muscles[k].J_ar, ws.muscles[k], m.nr()).middleRows<3>(3 * a).transpose() *
             (expandColumns(ws.muscles[k].Jdot_ar, ws.muscles[k], m.nr()).middleRows<3>(3 * a) * s.qdot);
  EXPECT_GT(qvv.norm(), 1e-3);
  EXPECT_TRUE(nearRel(VecX(f_full - f_drop), qvv, 1e-13));
  // at rest the two agree exactly
  s.qdot.setZero();
  calcKinematics(m, s, sk);
  f_full.setZero();
  f_drop.setZero();
  full.addForce(m, s, sk, f_full);
  dropped.addForce(m, s, sk, f_drop);
  EXPECT_TRUE(f_full == f_drop);
}

TEST(MuscleTerm, ConstructionValidatesMuscles) {
  const Model m = scenes::doublePendulum();
  Muscle mu;
  mu.name = "bad";
  mu.path.points = {makeFixedPoint(-1, Vec3::Zero()), makeFixedPoint(7, Vec3::UnitX())};
  try {
    MuscleTerm t(m, {mu});
    ADD_FAILURE() << "expected ModelError";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("muscle 'bad'"), std::string::npos) << e.what();
  }
  mu.path.points[1].body = 1;
  mu.mass_points = makeMassPoints(0.4, 0.2, 0.1, {});
  const MuscleTerm t(m, {mu});
  EXPECT_NEAR(t.totalMass(), 0.4, 1e-15);
  EXPECT_EQ(t.muscles().size(), 1u);
}

}  // namespace
}  // namespace redmax
