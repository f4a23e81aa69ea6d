// OpenSim's actuators and passive force elements as ForceTerms (core/dynamics/actuator_terms.hpp,
// passive_force_terms.hpp, sampled_loads.hpp): each generalized force against a closed form, the
// central differences of its potential, or the power of the force along the motion, and energy
// conserved by the springs in a simulation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>

#include "core/dynamics/actuator_terms.hpp"
#include "core/dynamics/body_loads.hpp"
#include "core/dynamics/passive_force_terms.hpp"
#include "core/dynamics/sampled_loads.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "tests/core/dynamics/term_eval.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using test::potentialGradient;
using test::termForce;

State randomState(const Model& m, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  State s;
  s.q = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  s.qdot = VecX::NullaryExpr(m.nr(), [&] { return u(rng); });
  return s;
}

// a body's pose at q + h qdot and at q - h qdot (h = 1e-6), for central differences along the motion
std::pair<Mat4, Mat4> posesAlongMotion(const Model& m, const State& s, int body) {
  const double h = 1e-6;
  SkeletonWorkspace ws(m);
  State sp = s, sm = s;
  sp.q += h * s.qdot;
  sm.q -= h * s.qdot;
  calcKinematics(m, sp, ws);
  const Mat4 Ep = ws.E_wi[body];
  calcKinematics(m, sm, ws);
  return {Ep, ws.E_wi[body]};
}

// a body point's world velocity by central differences of its position along qdot
Vec3 pointVelocityByDifferences(const Model& m, const State& s, int body, const Vec3& x_i) {
  const auto [Ep, Em] = posesAlongMotion(m, s, body);
  return (transformPoint(Ep, x_i) - transformPoint(Em, x_i)) / 2e-6;
}

// a body's world angular velocity by central differences of its rotation along qdot
Vec3 angularVelocityByDifferences(const Model& m, const State& s, int body) {
  if (body < 0) return Vec3::Zero();
  const auto [Ep, Em] = posesAlongMotion(m, s, body);
  const Mat3 A = Ep.topLeftCorner<3, 3>() * Em.topLeftCorner<3, 3>().transpose();  // I + [w] 2h + O(h^2)
  return Vec3(A(2, 1) - A(1, 2), A(0, 2) - A(2, 0), A(1, 0) - A(0, 1)) / 4e-6;
}

TEST(PointActuatorTerm, ForceIsJacobianTransposeAndItsPowerIsForceTimesPointVelocity) {
  const Model m = scenes::randomTree(6, 31);
  const State s = randomState(m, 4);
  std::vector<PointActuatorTerm::Actuator> acts = {
      {"local", 4, Vec3(0.1, -0.2, 0.05), false, Vec3(0, 3, 4), false, 250.0},
      {"global", 5, Vec3(0.3, 0.2, -0.1), true, Vec3(-1, 0, 0), true, 1000.0}};
  const PointActuatorTerm term(m, acts);
  EXPECT_EQ(term.numControls(), 2);
  EXPECT_EQ(term.controlNames(), (std::vector<std::string>{"local", "global"}));
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  for (int k = 0; k < 2; ++k) {
    VecX u = VecX::Zero(2);
    u[k] = 0.7;
    const VecX f = termForce(m, term, s, u);
    // closed form: J_p^T F with the direction made unit and rotated as OpenSim does
    const auto& a = acts[k];
    const Mat4& E = sk.E_wi[a.body];
    const Vec3 d = a.direction.normalized();
    const Vec3 F = 0.7 * a.optimal_force * (a.force_is_global ? d : Vec3(E.topLeftCorner<3, 3>() * d));
    const Vec3 x_i = a.point_is_global ? transformPoint(inverseE(E), a.point) : a.point;
    MatX J(3, m.nr());
    pointJacobian(m, sk, a.body, x_i, J);
    EXPECT_TRUE(nearRel(f, VecX(J.transpose() * F), 1e-13)) << a.name;
    // power: f . qdot = F . v with v by central differences of the point
    const double P = f.dot(s.qdot), Pv = F.dot(pointVelocityByDifferences(m, s, a.body, x_i));
    EXPECT_NEAR(P, Pv, 2e-8 * std::max(1.0, std::abs(P))) << a.name;  // measured 3.1e-9, 1.8e-10
    std::printf("PointActuator %s: power %.6g, |P - F.v| / |P| = %.2g\n", a.name.c_str(), P, std::abs(P - Pv) / std::abs(P));
    EXPECT_GT(std::abs(P), 1.0);
  }
}

TEST(TorqueActuatorTerm, PowerIsTorqueTimesRelativeAngularVelocity) {
  const Model m = scenes::randomTree(6, 32);
  const State s = randomState(m, 5);
  const std::vector<TorqueActuatorTerm::Actuator> acts = {{"global_vs_ground", 3, -1, Vec3(0, 0, 2), true, 300.0},
                                                          {"local_pair", 5, 2, Vec3(1, 1, 0), false, 40.0}};
  const TorqueActuatorTerm term(m, acts);
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  for (int k = 0; k < 2; ++k) {
    VecX u = VecX::Zero(2);
    u[k] = -0.6;
    const VecX f = termForce(m, term, s, u);
    const auto& a = acts[k];
    const Vec3 n = a.axis.normalized();
    const Vec3 T = -0.6 * a.optimal_force * (a.torque_is_global ? n : Vec3(sk.E_wi[a.body_a].topLeftCorner<3, 3>() * n));
    const Vec3 w = angularVelocityByDifferences(m, s, a.body_a) - angularVelocityByDifferences(m, s, a.body_b);
    const double P = f.dot(s.qdot);
    EXPECT_NEAR(P, T.dot(w), 5e-10 * std::max(1.0, std::abs(P))) << a.name;  // measured 7.2e-11, 5e-11
    std::printf("TorqueActuator %s: power %.6g, |P - T.w| / |P| = %.2g\n", a.name.c_str(), P, std::abs(P - T.dot(w)) / std::abs(P));
    EXPECT_GT(std::abs(P), 1.0);
    EXPECT_TRUE(nearRel(term.axisInWorld(sk, k), Vec3(T / (-0.6 * a.optimal_force)), 1e-14));
  }
}

TEST(ActuatorTerms, ZeroDirectionAndBadBodiesAreRefused) {
  const Model m = scenes::randomTree(3, 33);
  EXPECT_THROW(PointActuatorTerm(m, {{"a", 1, Vec3::Zero(), false, Vec3::Zero(), false, 1.0}}), ModelError);
  EXPECT_THROW(PointActuatorTerm(m, {{"a", -1, Vec3::Zero(), false, Vec3::UnitX(), false, 1.0}}), ModelError);
  EXPECT_THROW(TorqueActuatorTerm(m, {{"t", 7, -1, Vec3::UnitZ(), true, 1.0}}), ModelError);
  EXPECT_THROW(TorqueActuatorTerm(m, {{"t", 1, -1, Vec3(0, 0, NAN), true, 1.0}}), ModelError);
}

// OpenSim's example values in SI: limits 10 deg / -20 deg, 50 and 80 N m/deg, 5 deg transition
CoordinateLimitForceTerm::Limit exampleLimit(int coordinate) {
  const double w = M_PI / 180.0;
  CoordinateLimitForceTerm::Limit l;
  l.name = "limit";
  l.coordinate = coordinate;
  l.upper_limit = 10 * w;
  l.lower_limit = -20 * w;
  l.upper_stiffness = 50 / w;
  l.lower_stiffness = 80 / w;
  l.damping = 0.3 / w;
  l.transition = 5 * w;
  return l;
}

TEST(CoordinateLimitForceTerm, ElasticForceIsMinusTheDerivativeOfOpenSimsPotential) {
  const auto l = exampleLimit(0);
  const double w = M_PI / 180.0, h = 1e-7;
  double worst = 0.0;
  // below the lower limit, its transition, free, the upper transition, beyond it
  for (double deg = -40.0; deg <= 30.0; deg += 0.37) {
    const double q = deg * w;
    const double fd = -(CoordinateLimitForceTerm::potential(l, q + h) - CoordinateLimitForceTerm::potential(l, q - h)) / (2 * h);
    const double f = CoordinateLimitForceTerm::force(l, q, 0.0);
    worst = std::max(worst, std::abs(f - fd) / std::max(1.0, std::abs(f)));
  }
  std::printf("CoordinateLimitForce: worst |f + dV/dq| / max(1, |f|) = %.2g\n", worst);
  EXPECT_LT(worst, 5e-9);  // measured 7.1e-10
  // closed forms: free between the limits; beyond a full transition a plain linear spring
  EXPECT_EQ(CoordinateLimitForceTerm::force(l, 0.0, 1.0), 0.0);
  EXPECT_EQ(CoordinateLimitForceTerm::potential(l, -5 * w), 0.0);
  const double q = 20 * w;  // 10 deg beyond the upper limit, past its 5 deg transition
  EXPECT_NEAR(CoordinateLimitForceTerm::force(l, q, 0.0), -l.upper_stiffness * (q - l.upper_limit), 1e-12);
  EXPECT_NEAR(CoordinateLimitForceTerm::force(l, q, 2.0) - CoordinateLimitForceTerm::force(l, q, 0.0),
              -l.damping * 2.0, 1e-12);
  // OpenSim's potential beyond the transition: K (0.5 delta^2 - trans^2 / 7)
  const double delta = q - l.upper_limit, tr = l.transition;
  EXPECT_NEAR(CoordinateLimitForceTerm::potential(l, q), l.upper_stiffness * (0.5 * delta * delta - tr * tr / 7.0), 1e-12);
  // the potential is continuous where its formula changes (end of the transition)
  const double qe = l.upper_limit + tr;
  EXPECT_NEAR(CoordinateLimitForceTerm::potential(l, qe - 1e-12), CoordinateLimitForceTerm::potential(l, qe + 1e-12), 1e-9);
  // half way in the lower transition the stiffness is half: step(1/2) = 1/2
  const double ql = l.lower_limit - tr / 2;
  EXPECT_NEAR(CoordinateLimitForceTerm::force(l, ql, 0.0), 0.5 * l.lower_stiffness * (l.lower_limit - ql), 1e-12);
}

TEST(CoordinateLimitForceTerm, BadParametersAreRefused) {
  const Model m = scenes::randomTree(2, 34);
  auto l = exampleLimit(0);
  l.upper_stiffness = -1.0;
  EXPECT_THROW(CoordinateLimitForceTerm(m, {l}), ModelError);
  l = exampleLimit(0);
  l.transition = 0.0;
  EXPECT_THROW(CoordinateLimitForceTerm(m, {l}), ModelError);
  EXPECT_THROW(CoordinateLimitForceTerm(m, {exampleLimit(m.nr())}), ModelError);
}

TEST(PassiveForceTerms, SpringsAreMinusTheGradientOfTheirPotential) {
  ModelBuilder mb(scenes::randomTree(5, 35));
  const Model m = mb.finalize();
  State s = randomState(m, 6);
  s.qdot.setZero();
  const SpringGeneralizedForceTerm gs(m, {{"gs", 1, 30.0, 0.2, 0.0}});
  const PointToPointSpringTerm ps(m, {{"p2p", 2, -1, Vec3(0.1, 0.2, 0.0), Vec3(0.5, 1.0, -0.2), 200.0, 0.3},
                                      {"p2p_bodies", 4, 1, Vec3(0.0, -0.1, 0.2), Vec3(0.2, 0.0, 0.0), 80.0, 0.05}});
  const CoordinateLimitForceTerm cl(m, {exampleLimit(0)});
  BushingForceTerm::Bushing bb;
  bb.name = "bush";
  bb.body1 = 1;
  bb.body2 = 3;
  bb.X_1F.topRightCorner<3, 1>() = Vec3(0.1, -0.2, 0.05);
  bb.X_2M.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  bb.stiffness << 20, 30, 40, 500, 600, 700;
  const BushingForceTerm bu(m, {bb});
  s.q[0] = 0.25;  // inside the upper transition (10-15 deg)
  for (const ForceTerm* t : std::vector<const ForceTerm*>{&gs, &ps, &cl, &bu}) {
    const VecX f = termForce(m, *t, s, VecX());
    const VecX fd = -potentialGradient(m, *t, s);
    // measured 3.9e-12 (generalized spring) .. 3.3e-10 (point-to-point spring)
    EXPECT_TRUE(nearRel(f, fd, 2e-9)) << t->name() << "\n" << f.transpose() << "\n" << fd.transpose();
    std::printf("%s: |f + grad V| / |f| = %.2g\n", t->name().c_str(), (f - fd).norm() / f.norm());
    EXPECT_GT(f.norm(), 0.1) << t->name();
  }
  // SpringGeneralizedForce closed form with viscosity
  const SpringGeneralizedForceTerm gv(m, {{"gv", 3, 12.0, -0.1, 0.5}});
  State sv = randomState(m, 7);
  const VecX f = termForce(m, gv, sv, VecX());
  EXPECT_DOUBLE_EQ(f[3], -12.0 * (sv.q[3] + 0.1) - 0.5 * sv.qdot[3]);
  EXPECT_EQ(f.norm(), std::abs(f[3]));
}

// the bushing's damping: its generalized force has the power g . qdot of its deflection rate,
// qdot by central differences of the deflection along the motion
TEST(BushingForceTerm, DampingPowerIsGeneralizedForceTimesDeflectionRate) {
  const Model m = scenes::randomTree(5, 37);
  const State s = randomState(m, 9);
  BushingForceTerm::Bushing bb;
  bb.name = "bush";
  bb.body1 = -1;
  bb.body2 = 4;
  bb.X_1F.topRightCorner<3, 1>() = Vec3(0.3, 0.1, 0.0);
  bb.X_2M.topRightCorner<3, 1>() = Vec3(0.0, 0.2, -0.1);
  bb.damping << 2, 3, 4, 50, 60, 70;
  const BushingForceTerm bu(m, {bb});
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  Vec6 q, qdot;
  bu.calcDeflection(sk, 0, q, &qdot);
  const double h = 1e-6;
  State sp = s, sm = s;
  sp.q += h * s.qdot;
  sm.q -= h * s.qdot;
  Vec6 qp, qm;
  calcKinematics(m, sp, sk);
  bu.calcDeflection(sk, 0, qp, nullptr);
  calcKinematics(m, sm, sk);
  bu.calcDeflection(sk, 0, qm, nullptr);
  EXPECT_TRUE(nearRel(qdot, Vec6((qp - qm) / (2 * h)), 5e-10)) << qdot.transpose();  // measured 6.4e-11
  std::printf("Bushing: |qdot - FD| / |qdot| = %.2g\n", (qdot - (qp - qm) / (2 * h)).norm() / qdot.norm());
  const VecX f = termForce(m, bu, s, VecX());
  const double P = f.dot(s.qdot), Pg = -bb.damping.dot(qdot.cwiseProduct(qdot));
  EXPECT_NEAR(P, Pg, 1e-12 * std::abs(Pg));  // measured 0
  std::printf("Bushing: damping power %.6g, |P - g.qdot| / |P| = %.2g\n", Pg, std::abs(P - Pg) / std::abs(Pg));
  EXPECT_LT(Pg, -0.1);  // it dissipates
}

// springs, a bushing and an undamped limit conserve energy in a simulation (kinetic + gravity +
// their potentials)
TEST(PassiveForceTerms, UndampedSpringsAndLimitsConserveEnergyInSimulation) {
  const Model m = scenes::doublePendulum(1.0, 1.0);
  System sys(m);
  auto l = exampleLimit(1);
  l.damping = 0.0;
  l.upper_stiffness = 20.0;  // soft, so that the run crosses the transitions many times
  l.lower_stiffness = 30.0;
  sys.addTerm(std::make_shared<CoordinateLimitForceTerm>(m, std::vector<CoordinateLimitForceTerm::Limit>{l}));
  sys.addTerm(std::make_shared<PointToPointSpringTerm>(
      m, std::vector<PointToPointSpringTerm::Spring>{{"p2p", 1, -1, Vec3(0.0, -0.5, 0.0), Vec3(0.8, -1.0, 0.3), 40.0, 0.4}}));
  sys.addTerm(std::make_shared<SpringGeneralizedForceTerm>(
      m, std::vector<SpringGeneralizedForceTerm::Spring>{{"gs", 0, 5.0, 0.3, 0.0}}));
  BushingForceTerm::Bushing bb;
  bb.name = "bush";
  bb.body1 = -1;
  bb.body2 = 0;
  bb.X_2M.topRightCorner<3, 1>() = Vec3(0.0, -0.3, 0.0);
  bb.stiffness << 1, 2, 3, 10, 20, 30;
  sys.addTerm(std::make_shared<BushingForceTerm>(m, std::vector<BushingForceTerm::Bushing>{bb}));
  State s = sys.defaultState();
  s.q << 1.2, 0.4;
  DynamicsWorkspace ws(sys);
  const double E0 = sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
  IntegratorOptions opt;
  opt.rtol = 1e-10;
  opt.atol = 1e-12;
  auto integ = makeIntegrator("rk45", opt);
  double qmin = 1e9, qmax = -1e9;
  for (int k = 1; k <= 300; ++k) {
    integ->advance(sys, s, 0.01 * k);
    qmin = std::min(qmin, s.q[1]);
    qmax = std::max(qmax, s.q[1]);
  }
  const double E1 = sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
  std::printf("springs, bushing, limit: energy %.10g -> %.10g J, drift %.2g relative; q2 in [%.3f, %.3f]\n", E0, E1,
              std::abs(E1 - E0) / std::abs(E0), qmin, qmax);
  EXPECT_LT(std::abs(E1 - E0), 2e-9 * std::abs(E0)) << E0 << " -> " << E1;  // measured 3.7e-10
  // the elbow went into both limits' transitions
  EXPECT_GT(qmax, l.upper_limit);
  EXPECT_LT(qmin, l.lower_limit);
}

TEST(SampledLoadsTerm, EqualsBodyLoadsForTheSameLoadAtTheSampledTime) {
  const Model m = scenes::randomTree(5, 36);
  State s = randomState(m, 8);
  s.t = 0.3;
  // a force at t: F(t) = (t, 2, -1) at a ground point, expressed in body 2; a world torque
  const SampledLoadsTerm term([](double t, std::vector<IdLoadSample>& loads) {
    loads.clear();
    IdLoadSample l;
    l.body = 3;
    l.force_frame = 2;
    l.point_frame = -1;
    l.has_force = l.has_point = l.has_torque = true;
    l.force = Vec3(t, 2.0, -1.0);
    l.point = Vec3(0.2, 0.5, 0.1);
    l.torque = Vec3(0.0, 0.0, 3.0 * t);
    loads.push_back(l);
  });
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  const Mat3 R2 = sk.E_wi[2].topLeftCorner<3, 3>();
  BodyLoads ref;
  ref.point_forces.push_back({3, transformPoint(inverseE(sk.E_wi[3]), Vec3(0.2, 0.5, 0.1)), R2 * Vec3(0.3, 2.0, -1.0)});
  ref.wrenches.push_back({3, R2 * Vec3(0.0, 0.0, 0.9), Vec3::Zero()});
  VecX f_ref = VecX::Zero(m.nr());
  ref.addForce(m, s, sk, f_ref);
  EXPECT_TRUE(nearRel(termForce(m, term, s, VecX()), f_ref, 1e-13));
  EXPECT_GT(f_ref.norm(), 0.1);
}

}  // namespace
}  // namespace redmax
