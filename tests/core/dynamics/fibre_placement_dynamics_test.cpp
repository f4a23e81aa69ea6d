// Fibre-following mass points in the dynamics (core/muscles/fibre_placement.hpp,
// core/dynamics/muscle_term.hpp): the double pendulum with a long-tendon muscle across the second
// joint (link 1 to link 2, Type I), 20 points.
//   - zero muscle mass: a muscle-driven rk45 run equals the massless one bit for bit;
//   - the power balance of an elastic-tendon (Thelen2003Muscle) run: the mechanical energy of bones
//     and points changes as the muscle's work on the skeleton plus the work the moving fibre
//     does on its points,  dE/dt = -F_t ldot + sum_a m_a v_z,a . (xddot_a - g),  checked by a
//     central difference of E along the motion (q, qdot, z moved by their rates);
//   - rigid tendon (the points depend on q only): the inertia alone conserves energy (rk45,
//     rtol 1e-12); passive (zero excitation, damped Millard2012EquilibriumMuscle): E plus the
//     muscle's elastic potential never increases and does decrease.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/dynamics/controller.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/hill/factory.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using ModelPtr = std::shared_ptr<const hill::MuscleModel>;

ModelPtr makeModel(const std::string& cls, bool rigid, bool passive_damped = false) {
  hill::MuscleParameters p;
  p.name = "mt";
  p.set("max_isometric_force", 400.0);
  p.set("optimal_fiber_length", 0.45);
  p.set("tendon_slack_length", 0.95);
  p.set("pennation_angle_at_optimal", 0.2);
  p.set("ignore_tendon_compliance", rigid ? 1 : 0);
  if (passive_damped) {
    p.set("ignore_activation_dynamics", 1);
    p.set("fiber_damping", 0.1);
    p.set("minimum_activation", 0.0);
    p.set("min_control", 0.0);
  }
  return hill::makeMuscleModel(cls, p);
}

// the muscle, fibre-following with `model`, carrying `mass` kg on 20 points
Muscle makeMuscle(const Model& m, const ModelPtr& model, double mass) {
  Muscle mu;
  mu.name = "mt";
  mu.path.points = {makeFixedPoint(0, Vec3(0.08, -0.1, 0), "origin"), makeFixedPoint(1, Vec3(0.06, -0.6, 0), "insertion")};
  mu.optimal_fiber_length = 0.45;
  mu.tendon_slack_length = 0.95;
  mu.mass_points = makeMassPoints(mass, 0.45, 0.95, {});
  const VecX q = VecX::Zero(m.nr());
  std::vector<Mat4> E;
  calcBodyPoses(m, q, E);
  setFibrePlacement(m, q, E, model, mu);
  return mu;
}

// skeleton + (mass points) + the muscle's force, excitation u(t) = u0 + u1 t
System makeSystem(const Model& m, const Muscle& mu, const ModelPtr& model, bool with_mass, double u0, double u1) {
  System sys(m);
  if (with_mass) sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{mu}));
  sys.addTerm(std::make_shared<MuscleForceTerm>(m, std::vector<Muscle>{mu}, std::vector<ModelPtr>{model}));
  EXPECT_TRUE(bindMuscleStates(sys).empty());
  sys.addController(std::make_shared<PrescribedControls>(
      "u", std::vector<PrescribedControls::Entry>{{0, std::make_shared<LinearFunction>(u1, u0)}}));
  return sys;
}

State startState(const System& sys) {
  State s = sys.defaultState();
  s.q << 0.7, -0.5;
  s.qdot << 1.5, -2.0;
  DynamicsWorkspace ws(sys.model());
  sys.equilibrateStates(s, ws);
  return s;
}

TEST(FibrePlacementDynamics, ZeroMassEqualsMasslessBitForBit) {
  const Model m = scenes::doublePendulum();
  const ModelPtr model = makeModel("Thelen2003Muscle", false);
  const Muscle mu = makeMuscle(m, model, 0.0);
  const System massless = makeSystem(m, mu, model, false, 0.2, 1.0);
  const System zero = makeSystem(m, mu, model, true, 0.2, 1.0);
  State a = startState(massless), b = startState(zero);
  ASSERT_EQ(a.z, b.z);
  IntegratorOptions io;
  io.rtol = io.atol = 1e-9;
  auto ia = makeIntegrator("rk45", io), ib = makeIntegrator("rk45", io);
  ia->advance(massless, a, 0.5);
  ib->advance(zero, b, 0.5);
  EXPECT_EQ(a.q, b.q);
  EXPECT_EQ(a.qdot, b.qdot);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(ia->stats().steps, ib->stats().steps);
  EXPECT_GT(std::abs(a.z[1] - startState(massless).z[1]), 1e-3);  // the fibre moved
}

double energy(const System& sys, const State& s, DynamicsWorkspace& ws) {
  return sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
}

TEST(FibrePlacementDynamics, PowerBalanceOfAnElasticTendonRun) {
  const Model m = scenes::doublePendulum();
  const ModelPtr model = makeModel("Thelen2003Muscle", false);
  const Muscle mu = makeMuscle(m, model, 0.8);
  const System sys = makeSystem(m, mu, model, true, 0.6, 0.0);
  State s = startState(sys);
  s.z[1] *= 0.998;  // off equilibrium: the fibre moves
  DynamicsWorkspace ws(m);
  const VecX qddot = sys.forwardDynamics(s, ws);
  const VecX zdot = ws.zdot;
  ASSERT_GT(std::abs(zdot[1]), 0.05);
  // the muscle's power on the skeleton, f . qdot = -F_t ldot
  TermContext ctx(ws.sk);
  ctx.z_offset = sys.stateOffset(1);
  ctx.u_offset = sys.controlOffset(1);
  ctx.controls = &ws.controls;
  VecX f = VecX::Zero(m.nr());
  sys.terms()[1]->addForce(m, s, ctx, f);
  const double P_muscle = f.dot(s.qdot);
  // the fibre's power on its points
  const auto& bound = static_cast<const MuscleTerm&>(*sys.terms()[0]).muscles()[0];
  SkeletonWorkspace sk(m);
  calcKinematics(m, s, sk);
  MuscleWorkspace mw(m, {bound});
  MuscleKinematics& mk = mw.muscles[0];
  calcMuscleKinematics(m, s, sk, bound, mk, true, FibreStates{s.z.data(), ws.controls[0]});
  const VecX qc = gatherColumns(s.qdot, mk), qddc = gatherColumns(qddot, mk);
  double P_z = 0.0;
  for (int a = 0; a < bound.mass_points.size(); ++a) {
    const Vec3 acc = mk.J_ar.middleRows<3>(3 * a) * qddc + mk.Jdot_ar.middleRows<3>(3 * a) * qc + mk.a_z.segment<3>(3 * a);
    P_z += bound.mass_points.mass[a] * mk.v_z.segment<3>(3 * a).dot(acc - m.gravity());
  }
  // dE/dt along the motion
  const double h = 1e-6;
  auto moved = [&](double t) {
    State r = s;
    r.t += t;
    r.q += t * s.qdot;
    r.qdot += t * qddot;
    r.z += t * zdot;
    return r;
  };
  DynamicsWorkspace w2(m);
  const double dEdt = (energy(sys, moved(h), w2) - energy(sys, moved(-h), w2)) / (2 * h);
  std::printf("dE/dt %.9g, -F_t ldot %.9g, fibre on points %.9g, residual %.3g\n", dEdt, P_muscle, P_z,
              dEdt - P_muscle - P_z);
  EXPECT_GT(std::abs(P_z), 1e-2 * std::abs(P_muscle));  // the fibre term matters here
  const double scale = std::abs(P_muscle) + std::abs(P_z);
  std::printf("relative residual %.3g\n", std::abs(dEdt - P_muscle - P_z) / scale);
  EXPECT_NEAR(dEdt, P_muscle + P_z, 1e-6 * scale);
}

TEST(FibrePlacementDynamics, RigidTendonInertiaConservesEnergy) {
  const Model m = scenes::doublePendulum();
  const ModelPtr model = makeModel("Millard2012EquilibriumMuscle", true);
  const Muscle mu = makeMuscle(m, model, 0.8);
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, std::vector<Muscle>{mu}));
  DynamicsWorkspace ws(m);
  State s = sys.defaultState();
  s.q << 0.7, -0.5;
  s.qdot << 1.5, -2.0;
  IntegratorOptions io;
  io.rtol = io.atol = 1e-12;
  auto integ = makeIntegrator("rk45", io);
  const double E0 = energy(sys, s, ws);
  double drift = 0.0;
  for (int k = 1; k <= 300; ++k) {
    integ->advance(sys, s, 0.01 * k);
    drift = std::max(drift, std::abs(energy(sys, s, ws) - E0));
  }
  std::printf("rigid-tendon fibre placement, 3 s: max |E - E0| = %.3g J of %.3g J\n", drift, E0);
  EXPECT_LT(drift, 5e-10);  // measured 4.8e-11 J of |E| = 20 J
}

TEST(FibrePlacementDynamics, PassiveMuscleDissipates) {
  const Model m = scenes::doublePendulum();
  const ModelPtr model = makeModel("Millard2012EquilibriumMuscle", true, true);
  const Muscle mu = makeMuscle(m, model, 0.8);
  const System sys = makeSystem(m, mu, model, true, 0.0, 0.0);
  State s = startState(sys);
  s.qdot << 4.0, -5.0;
  DynamicsWorkspace ws(m);
  // the muscle's elastic potential: the integral of its tension at rest over the path length
  auto tension = [&](double L) {
    hill::MusculotendonInput in;
    in.length = L;
    hill::MuscleOutput out;
    model->calc(nullptr, in, out, nullptr);
    return out.tendon_force;
  };
  auto pathLength = [&](const State& st) {
    std::vector<Mat4> E;
    calcBodyPoses(m, st.q, E);
    return calcPathLength(m, mu.path, st.q, E);
  };
  const double L0 = pathLength(s);
  auto potential = [&](double L) {  // Simpson, 400 intervals
    const int n = 400;
    const double d = (L - L0) / n;
    double sum = tension(L0) + tension(L);
    for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * tension(L0 + i * d);
    return sum * d / 3.0;
  };
  IntegratorOptions io;
  io.rtol = io.atol = 1e-11;
  auto integ = makeIntegrator("rk45", io);
  const double E0 = energy(sys, s, ws);
  double prev = E0, worst_rise = 0.0, Lmax = L0;
  for (int k = 1; k <= 200; ++k) {
    integ->advance(sys, s, 0.01 * k);
    const double L = pathLength(s);
    Lmax = std::max(Lmax, L);
    const double E = energy(sys, s, ws) + potential(L);
    worst_rise = std::max(worst_rise, E - prev);
    prev = E;
  }
  std::printf("passive run, 2 s: E %.9g -> %.9g J, largest rise between samples %.3g J, path %.4g..%.4g m\n", E0, prev,
              worst_rise, L0, Lmax);
  EXPECT_GT(tension(Lmax), 1.0);  // the passive fibre was stretched
  EXPECT_LT(worst_rise, 1e-9);    // measured 8.5e-11 J (rk45 error)
  EXPECT_LT(prev, E0 - 1.0);      // and energy left through the damping: measured -10.785 -> -13.064 J
}

}  // namespace
}  // namespace redmax
