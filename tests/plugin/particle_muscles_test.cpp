// Forward dynamics of muscle inertia in Simbody (plugin/simbody/particle_muscles.hpp): mass points
// as particles held on their paths by Constraint::Custom, against the core's MuscleTerm integrated
// by rk45. The double pendulum with two Type I muscles (one from the ground, one across the middle
// joint, 0.6 kg and 0.8 kg over 5 points each), released from a swinging state: q agrees to 1e-6
// (radians) at t = 0.25, 0.5, 0.75 and 1 s, with tolerances well below that (core rtol 1e-11,
// Simbody accuracy 1e-10, constraint tolerance 1e-11); without the muscles q differs by > 1e-2 at
// 1 s, so the agreement is the muscles'. Also a Type II muscle (no mass point crossing its via point)
// and moving points (functions of q1 and q2, on link1 and on the world). CPU times of both are printed (not asserted).
#include "plugin/simbody/particle_muscles.hpp"
#include "plugin/simbody/particle_simulation.hpp"

#include <gtest/gtest.h>

#include <ctime>
#include <cstdio>
#include <memory>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

std::vector<Muscle> pendulumMuscles() {
  MassPointOptions opt;
  opt.count = 5;
  opt.region = MassPointOptions::Region::WholePath;
  Muscle a;
  a.name = "ground_to_link1";
  a.path.points = {makeFixedPoint(-1, Vec3(0.3, 0.1, 0.0)), makeFixedPoint(0, Vec3(0.05, -0.7, 0.0))};
  a.mass_points = makeMassPoints(0.6, 1.0, 0.0, opt);
  Muscle b;
  b.name = "link1_to_link2";
  b.path.points = {makeFixedPoint(0, Vec3(0.06, -0.3, 0.02)), makeFixedPoint(1, Vec3(0.04, -0.5, -0.01))};
  b.mass_points = makeMassPoints(0.8, 1.0, 0.0, opt);
  return {a, b};
}

const std::vector<double> kTimes{0.25, 0.5, 0.75, 1.0};

std::vector<VecX> coreTrajectory(const Model& m, const std::vector<Muscle>& muscles, const State& s0, double& seconds,
                                 const std::vector<double>& times = kTimes) {
  System sys(m);
  if (!muscles.empty()) sys.addTerm(std::make_shared<MuscleTerm>(m, muscles));
  IntegratorOptions o;
  o.rtol = 1e-11;
  o.atol = 1e-12;
  auto integ = makeIntegrator("rk45", o);
  State s = s0;
  std::vector<VecX> q;
  const std::clock_t t0 = std::clock();
  for (double t : times) {
    integ->advance(sys, s, t);
    q.push_back(s.q);
  }
  seconds = double(std::clock() - t0) / CLOCKS_PER_SEC;
  return q;
}

TEST(SimbodyParticleMuscles, DoublePendulumTypeIMatchesCoreRk45) {
  const Model m = scenes::doublePendulum();
  const std::vector<Muscle> muscles = pendulumMuscles();
  State s0;
  s0.t = 0.0;
  s0.q = Vec2(0.7, -0.5);
  s0.qdot = Vec2(0.4, -0.3);

  double core_s = 0.0, plain_s = 0.0;
  const std::vector<VecX> q_core = coreTrajectory(m, muscles, s0, core_s);
  const std::vector<VecX> q_plain = coreTrajectory(m, {}, s0, plain_s);

  auto sm = simbody::makeSimbodyModel(m);
  simbody::ParticleMuscles particles(*sm, m, muscles);
  ASSERT_EQ(particles.numParticles(), 10);
  SimTK::State st = sm->default_state;
  simbody::setSimbodyState(*sm, m, s0, st);
  particles.placeParticles(st);
  // the placed particles satisfy the constraints (position and velocity)
  sm->system.realize(st, SimTK::Stage::Velocity);
  EXPECT_LT(st.getQErr().normInf(), 1e-14);
  EXPECT_LT(st.getUErr().normInf(), 1e-13);

  SimTK::RungeKuttaMersonIntegrator integ(sm->system);
  integ.setAccuracy(1e-10);
  integ.setConstraintTolerance(1e-11);
  SimTK::TimeStepper ts(sm->system, integ);
  const std::clock_t t0 = std::clock();
  ts.initialize(st);
  double worst = 0.0;
  for (size_t k = 0; k < kTimes.size(); ++k) {
    ts.stepTo(kTimes[k]);
    const State s = particles.coreState(m, ts.getState());
    const double err = (s.q - q_core[k]).cwiseAbs().maxCoeff();
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-6) << "t = " << kTimes[k] << ": simbody " << s.q.transpose() << " core " << q_core[k].transpose();
  }
  const double sb_s = double(std::clock() - t0) / CLOCKS_PER_SEC;
  EXPECT_GT((q_core.back() - q_plain.back()).cwiseAbs().maxCoeff(), 1e-2);
  std::printf("  particles vs core rk45 over 1 s: max |dq| %.3e rad; CPU: simbody %.3f s (%d steps), core %.3f s\n",
              worst, sb_s, integ.getNumStepsTaken(), core_s);
}

// Type II: a muscle from the ground over a via point on link1 to link2, 4 points over the whole
// path. A mass point that slides over the via point changes velocity direction abruptly (path.hpp),
// which a constrained particle cannot follow without an impulse; the motion is chosen so that none
// does, and the test checks that with the core's kinematics every 10 ms.
TEST(SimbodyParticleMuscles, DoublePendulumTypeIIMatchesCoreRk45) {
  const Model m = scenes::doublePendulum();
  MassPointOptions opt;
  opt.count = 4;
  opt.region = MassPointOptions::Region::WholePath;
  Muscle mu;
  mu.name = "via";
  mu.path.points = {makeFixedPoint(-1, Vec3(0.3, 0.1, 0.0)), makeFixedPoint(0, Vec3(0.12, -0.85, 0.0)),
                    makeFixedPoint(1, Vec3(0.05, -0.45, 0.0))};
  mu.mass_points = makeMassPoints(0.7, 1.0, 0.0, opt);
  const std::vector<Muscle> muscles{mu};
  State s0;
  s0.t = 0.0;
  s0.q = Vec2(0.3, -0.2);
  s0.qdot = Vec2(0.2, -0.1);

  // precondition: no mass point changes segment along the core trajectory
  {
    System sys(m);
    sys.addTerm(std::make_shared<MuscleTerm>(m, muscles));
    IntegratorOptions o;
    o.rtol = 1e-10;
    o.atol = 1e-12;
    auto integ = makeIntegrator("rk45", o);
    State s = s0;
    std::vector<int> seg0;
    for (int k = 0; k <= 100; ++k) {
      integ->advance(sys, s, 0.01 * k);
      SkeletonWorkspace sk(m);
      calcKinematics(m, s, sk);
      MuscleWorkspace ws(m, muscles);
      calcMuscleKinematics(m, s, sk, muscles, ws);
      if (k == 0) seg0 = ws.muscles[0].segment;
      ASSERT_EQ(ws.muscles[0].segment, seg0) << "a mass point crossed the via point at t = " << s.t;
    }
  }

  double core_s = 0.0;
  const std::vector<VecX> q_core = coreTrajectory(m, muscles, s0, core_s);
  auto sm = simbody::makeSimbodyModel(m);
  simbody::ParticleMuscles particles(*sm, m, muscles);
  SimTK::State st = sm->default_state;
  simbody::setSimbodyState(*sm, m, s0, st);
  particles.placeParticles(st);
  SimTK::RungeKuttaMersonIntegrator integ(sm->system);
  integ.setAccuracy(1e-10);
  integ.setConstraintTolerance(1e-11);
  SimTK::TimeStepper ts(sm->system, integ);
  ts.initialize(st);
  double worst = 0.0;
  for (size_t k = 0; k < kTimes.size(); ++k) {
    ts.stepTo(kTimes[k]);
    const State s = particles.coreState(m, ts.getState());
    worst = std::max(worst, (s.q - q_core[k]).cwiseAbs().maxCoeff());
    EXPECT_LT((s.q - q_core[k]).cwiseAbs().maxCoeff(), 1e-6) << "t = " << kTimes[k];
  }
  std::printf("  Type II particles vs core rk45 over 1 s: max |dq| %.3e rad\n", worst);
}

// moving points: a Type I muscle whose origin on link1 moves with q2 (a line and a cubic), and one
// from a world point that moves with q1 to link2; their coordinates become constrained mobilizers
TEST(SimbodyParticleMuscles, DoublePendulumMovingPointsMatchCoreRk45) {
  const Model m = scenes::doublePendulum();
  MassPointOptions opt;
  opt.count = 5;
  opt.region = MassPointOptions::Region::WholePath;
  auto line = std::make_shared<LinearFunction>(0.03, 0.08);
  auto cubic = std::make_shared<PolynomialFunction>(std::vector<double>{0.02, -0.03, 0.01, -0.8});
  Muscle a;
  a.name = "moving_on_link1";
  a.path.points = {makeMovingPoint(0, 1, {line, cubic, nullptr}), makeFixedPoint(1, Vec3(0.05, -0.5, 0.0))};
  a.mass_points = makeMassPoints(0.6, 1.0, 0.0, opt);
  Muscle b;
  b.name = "moving_world";
  b.path.points = {makeMovingPoint(-1, 0, {line, nullptr, nullptr}, Vec3(0.0, 0.1, 0.02)),
                   makeFixedPoint(1, Vec3(-0.04, -0.3, 0.0))};
  b.mass_points = makeMassPoints(0.5, 1.0, 0.0, opt);
  const std::vector<Muscle> muscles{a, b};
  State s0;
  s0.t = 0.0;
  s0.q = Vec2(0.6, -0.7);
  s0.qdot = Vec2(-0.3, 0.5);

  double core_s = 0.0, plain_s = 0.0;
  const std::vector<VecX> q_core = coreTrajectory(m, muscles, s0, core_s);
  const std::vector<VecX> q_plain = coreTrajectory(m, {}, s0, plain_s);
  auto sm = simbody::makeSimbodyModel(m);
  simbody::ParticleMuscles particles(*sm, m, muscles);
  SimTK::State st = sm->default_state;
  simbody::setSimbodyState(*sm, m, s0, st);
  particles.placeParticles(st);
  sm->system.realize(st, SimTK::Stage::Velocity);
  EXPECT_LT(st.getQErr().normInf(), 1e-14);
  EXPECT_LT(st.getUErr().normInf(), 1e-13);
  SimTK::RungeKuttaMersonIntegrator integ(sm->system);
  integ.setAccuracy(1e-10);
  integ.setConstraintTolerance(1e-11);
  SimTK::TimeStepper ts(sm->system, integ);
  ts.initialize(st);
  double worst = 0.0;
  for (size_t k = 0; k < kTimes.size(); ++k) {
    ts.stepTo(kTimes[k]);
    const State s = particles.coreState(m, ts.getState());
    worst = std::max(worst, (s.q - q_core[k]).cwiseAbs().maxCoeff());
    EXPECT_LT((s.q - q_core[k]).cwiseAbs().maxCoeff(), 1e-6) << "t = " << kTimes[k];
  }
  EXPECT_GT((q_core.back() - q_plain.back()).cwiseAbs().maxCoeff(), 1e-2);
  std::printf("  moving points, particles vs core rk45 over 1 s: max |dq| %.3e rad\n", worst);
}

// the driver: energies of skeleton + particles equal the core's skeleton + MuscleTerm energies at the
// start (1e-12 relative; potential energies share the world-origin reference), the total is
// conserved over 1 s (1e-7 relative at accuracy 1e-10), and the end state equals the core's (1e-6)
TEST(SimbodyParticleSimulation, EnergyMatchesCoreAndIsConserved) {
  const Model m = scenes::doublePendulum();
  const std::vector<Muscle> muscles = pendulumMuscles();
  State s0;
  s0.t = 0.0;
  s0.q = Vec2(0.7, -0.5);
  s0.qdot = Vec2(0.4, -0.3);
  System sys(m);
  sys.addTerm(std::make_shared<MuscleTerm>(m, muscles));
  DynamicsWorkspace ws(sys.model());
  const double T_core = sys.kineticEnergy(s0, ws), V_core = sys.potentialEnergy(s0, ws);

  simbody::ParticleSimulationOptions opt;
  opt.accuracy = 1e-10;
  opt.constraint_tolerance = 1e-11;
  simbody::ParticleSimulation sim(makeMusculoskeletalModel(m, muscles), s0, opt);
  EXPECT_NEAR(sim.kineticEnergy(), T_core, 1e-12 * (1.0 + std::abs(T_core)));
  EXPECT_NEAR(sim.potentialEnergy(), V_core, 1e-12 * (1.0 + std::abs(V_core)));
  const double E0 = sim.kineticEnergy() + sim.potentialEnergy();
  double drift = 0.0;
  for (double t : kTimes) {
    sim.advance(t);
    drift = std::max(drift, std::abs(sim.kineticEnergy() + sim.potentialEnergy() - E0));
  }
  EXPECT_LT(drift, 1e-7 * std::abs(E0));
  double core_s = 0.0;
  const std::vector<VecX> q_core = coreTrajectory(m, muscles, s0, core_s);
  EXPECT_LT((sim.state().q - q_core.back()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_GT(sim.steps(), 0);
  EXPECT_THROW(sim.advance(0.5), std::invalid_argument);
  EXPECT_THROW(simbody::ParticleSimulation(makeMusculoskeletalModel(m, muscles), s0, [] {
                 simbody::ParticleSimulationOptions o;
                 o.integrator = "euler";
                 return o;
               }()), std::invalid_argument);
  std::printf("  particle simulation: energy drift %.3e J of %.3f J over 1 s, %ld steps\n", drift, E0, sim.steps());
}

// the finger scene over 1 s: tests/plugin/particle_finger_test.cpp; conditional points (switching
// during a run): tests/plugin/simbody_wrap_test.cpp

}  // namespace
}  // namespace redmax
