// The reaching task (validation/optimize/reach.hpp, docs/gradients.md §7) on osim_models/reach_arm.osim
// with the physiological mass of all six wrapping muscles: L-BFGS on the adjoint gradient and BOBYQA
// both bring the hand to the target from zero torques, L-BFGS with fewer simulations; the objective
// that the hand also comes to rest slows it; bad input is refused with the flag named.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/skeleton/kinematics.hpp"
#include "validation/optimize/reach.hpp"

namespace redmax::validation {
namespace {

ReachOptions reachOptions() {
  ReachOptions o;
  o.model_path = std::string(REDMAX_SOURCE_DIR) + "/osim_models/reach_arm.osim";
  o.model_options.muscle_mass.source = osim::MuscleMassOptions::Source::Physiological;
  o.model_options.muscle_mass.wrap_mass = true;  // the deltoids and triceps over the smooth wrap model
  o.body = "hand";
  o.point = Vec3(0.0, -0.08, 0.0);
  o.target = Vec3(0.25, -0.55, 0.05);  // 0.11 m from the hand's start (0.168, -0.607, 0), elbow within its limits
  o.duration = 0.3;
  o.dt = 0.01;
  return o;
}

// the hand point at the end of a run at the given torques, computed here from the final state
Vec3 finalPoint(const ReachSetup& s, const VecX& torques) {
  const adjoint::Result r = adjoint::evaluate(s.gradient.problem, s.gradient.objective, torques, false);
  const Model& model = s.gradient.model.system->model();
  SkeletonWorkspace sk(model);
  calcKinematics(model, r.final, sk);
  const auto& pt = s.gradient.objective.points.front();
  return transformPoint(sk.E_wi[pt.body], pt.x_i);
}

TEST(Reach, LbfgsAndBobyqaReachTheTargetLbfgsWithFewerSimulations) {
  const ReachSetup s = makeReachSetup(reachOptions());
  ASSERT_EQ(s.gradient.param_names.size(), 4u);  // three shoulder rotations and the elbow
  EXPECT_GT(s.gradient.model.muscle_mass, 0.5);    // 0.82 kg in the six muscles' mass points
  EXPECT_GT((s.start_point - s.options.target).norm(), 0.09);
  const ReachResult lbfgs = optimizeReach(s, "lbfgs");
  const ReachResult bobyqa = optimizeReach(s, "bobyqa");
  for (const ReachResult* r : {&lbfgs, &bobyqa}) {
    // reached: the hand within the 1 mm tolerance, checked on a fresh run of the returned torques
    const double error = (finalPoint(s, r->torques) - s.options.target).norm();
    EXPECT_LE(error, 1e-3) << r->method << ": " << r->stop;
    EXPECT_TRUE(r->reached) << r->method;
    EXPECT_NEAR(r->error, error, 1e-12) << r->method;
    EXPECT_NEAR(r->objective, 0.5 * error * error, 1e-15) << r->method;
    EXPECT_EQ(r->simulations, static_cast<long>(r->evaluations.size()));
    EXPECT_EQ(r->failed_simulations, 0) << r->method;
    // the best objective never rises and ends at the result
    for (size_t i = 1; i < r->evaluations.size(); ++i)
      EXPECT_LE(r->evaluations[i].best_objective, r->evaluations[i - 1].best_objective);
    EXPECT_EQ(r->evaluations.back().best_objective, r->objective);
  }
  // the dissertation's comparison: far fewer simulations with the gradient
  EXPECT_LT(lbfgs.simulations, bobyqa.simulations) << lbfgs.simulations << " vs " << bobyqa.simulations;
  // an L-BFGS evaluation runs the adjoint too, whose analytic step Jacobians evaluate no step
  // (the wrapping muscles' share by local differences, docs/gradients.md §2.1): the same
  // integrator steps per simulation
  EXPECT_EQ(lbfgs.step_evaluations / lbfgs.simulations, bobyqa.step_evaluations / bobyqa.simulations);
}

TEST(Reach, CubicSplineTorquesReachTheTargetAndComeToRest) {
  // beyond the dissertation's constant torques: each torque a cubic B-spline of 4 control points
  // (16 parameters), with the objective that the hand also comes to rest; L-BFGS on the adjoint.
  // The lumped arm (muscle mass off) keeps the test short.
  ReachOptions o = reachOptions();
  o.model_options = SimulationModelOptions{};
  o.torques_in_time = "4~cubic";
  o.rest_weight = 1e-3;
  const ReachSetup s = makeReachSetup(o);
  ASSERT_EQ(s.gradient.param_names.size(), 16u);
  EXPECT_EQ(s.gradient.param_names.front(), "torque shoulder_flexion control point 1/4");
  const ReachResult r = optimizeReach(s, "lbfgs");
  const double error = (finalPoint(s, r.torques) - s.options.target).norm();
  const adjoint::Result fin = adjoint::evaluate(s.gradient.problem, s.gradient.objective, r.torques, false);
  std::printf("[ measured ] cubic torques: %ld simulations, error %.3e m, final speed %.3e rad/s (%s)\n",
              r.simulations, error, fin.final.qdot.norm(), r.stop.c_str());
  EXPECT_LE(error, 1e-3);  // measured 4.7e-4 m (reached: the stop objective)
  // the spline torques bring it nearer rest than constant torques can: compare
  ReachOptions c = reachOptions();
  c.model_options = SimulationModelOptions{};
  c.rest_weight = 1e-3;
  const ReachSetup sc = makeReachSetup(c);
  const ReachResult rc = optimizeReach(sc, "lbfgs");
  const adjoint::Result fc = adjoint::evaluate(sc.gradient.problem, sc.gradient.objective, rc.torques, false);
  std::printf("[ measured ] constant torques with the same objective: objective %.3e against %.3e (splines), final "
              "speed %.3e rad/s\n",
              rc.objective, r.objective, fc.final.qdot.norm());
  EXPECT_LT(r.objective, 1e-2 * rc.objective);  // measured 4.3e-7 against 1.25e-3
  EXPECT_LT(fin.final.qdot.norm(), 0.2 * fc.final.qdot.norm());
  // a bad shape is refused with the flag named
  o.torques_in_time = "3~cubic";
  EXPECT_THROW(makeReachSetup(o), std::invalid_argument);
}

TEST(Reach, TheRestObjectiveSlowsTheHand) {
  ReachOptions o = reachOptions();
  o.model_options = SimulationModelOptions{};  // lumped muscles: the objective's wiring, quickly
  o.max_simulations = 60;
  const ReachResult free = optimizeReach(makeReachSetup(o), "lbfgs");
  o.rest_weight = 1e-3;
  const ReachSetup rest_setup = makeReachSetup(o);
  const ReachResult rest = optimizeReach(rest_setup, "lbfgs");
  ASSERT_TRUE(free.reached);
  // the speed term is in the objective: J = 1/2 e^2 + w/2 |qdot|^2 at the returned torques
  const adjoint::Result r = adjoint::evaluate(rest_setup.gradient.problem, rest_setup.gradient.objective, rest.torques, false);
  EXPECT_NEAR(rest.objective, 0.5 * rest.error * rest.error + 0.5e-3 * r.final.qdot.squaredNorm(), 1e-14);
  EXPECT_NEAR(rest.final_speed, r.final.qdot.norm(), 1e-12);
  EXPECT_LT(rest.final_speed, 0.5 * free.final_speed) << rest.final_speed << " vs " << free.final_speed;
}

// beyond the dissertation: the reach driven by muscle excitations through activation and fibre
// dynamics, on tug_of_war_step.osim (two Millard muscles on a 20 kg block, each carrying 0.5 kg):
// L-BFGS-B on the adjoint gradient of 3 nodes per muscle moves the block 3 cm to the target
TEST(Reach, ExcitationsDriveTheBlockToTheTarget) {
  ReachOptions o;
  o.model_path = std::string(REDMAX_SOURCE_DIR) + "/osim_models/tug_of_war_step.osim";
  o.model_options.explicit_masses = {{"left_muscle", 0.5}, {"right_muscle", 0.5}};
  o.model_options.muscle_mass.mass_points = 8;
  o.body = "block";
  o.target = Vec3(0.03, 0.0, 0.0);
  o.duration = 0.2;
  o.dt = 0.001;
  o.drive = "excitations";
  o.nodes = 3;
  o.initial_excitation = 0.5;
  const ReachSetup s = makeReachSetup(o);
  ASSERT_EQ(s.gradient.p0.size(), 6);
  ASSERT_TRUE(s.bounded);
  const ReachResult r = optimizeReach(s, "lbfgs");
  EXPECT_TRUE(r.reached) << r.stop << ", error " << r.error;
  EXPECT_LE((finalPoint(s, r.torques) - o.target).norm(), 1e-3);
  for (Eigen::Index i = 0; i < r.torques.size(); ++i) {
    EXPECT_GE(r.torques[i], s.lower[i]);
    EXPECT_LE(r.torques[i], s.upper[i]);
  }
  // the right muscle pulls the block to +x: on average it is excited more than the left
  EXPECT_GT(r.torques.tail(3).sum(), r.torques.head(3).sum());
  // the best run replayed: per step the excitations the run used, and the same excitations on the
  // lumped model land elsewhere (the muscles' 1 kg is 5 % of the block's mass; measured 1.2e-5 m
  // apart after 0.2 s)
  const ReachReplay rp = replayReach(s, r.torques);
  ASSERT_EQ(rp.muscles.size(), 2u);
  ASSERT_EQ(rp.hand.size(), rp.t.size());
  EXPECT_NEAR((rp.hand.back() - o.target).norm(), r.error, 1e-12);
  EXPECT_NEAR(rp.excitation[0].front(), r.torques[0], 1e-12);  // node 1 at t = 0
  EXPECT_GT(rp.tendon_force[1][100], 0.0);
  ASSERT_EQ(rp.lumped_hand.size(), rp.t.size());
  EXPECT_GT((rp.lumped_hand.back() - rp.hand.back()).norm(), 5e-6);
  EXPECT_NEAR(rp.lumped_error, (rp.lumped_hand.back() - o.target).norm(), 1e-15);
}

// reach_arm.osim driven by its six Thelen muscles (lumped, elbow_limit applied): a target the
// muscles themselves reach - the hand's end point of a run with DELT1, DELT3 and TRIlong excited at
// 0.3 and the others at their min_control - is reached again from 0.1 everywhere by L-BFGS-B on one
// constant excitation per muscle (docs/gradients.md §7, where the 3-node table is measured)
TEST(Reach, ExcitationsReachATargetTheMusclesMade) {
  ReachOptions o;
  o.model_path = std::string(REDMAX_SOURCE_DIR) + "/osim_models/reach_arm.osim";
  o.point = Vec3(0.0, -0.08, 0.0);
  o.duration = 0.2;
  o.dt = 0.00025;  // the Thelen fibres' explicit Euler (docs/gradients.md §2)
  o.drive = "excitations";
  o.nodes = 1;
  o.tolerance = 0.005;
  ReachOptions made = o;
  made.muscles = {"DELT1", "DELT3", "TRIlong"};
  made.initial_excitation = 0.3;
  const ReachSetup ms = makeReachSetup(made);
  o.target = replayReach(ms, ms.x0).hand.back();
  o.initial_excitation = 0.1;
  const ReachSetup s = makeReachSetup(o);
  ASSERT_EQ(s.gradient.p0.size(), 6);
  EXPECT_GT((s.start_point - o.target).norm(), 0.25);  // measured 0.31 m
  const ReachResult r = optimizeReach(s, "lbfgs");
  EXPECT_TRUE(r.reached) << r.stop << ", error " << r.error;
  EXPECT_LE((finalPoint(s, r.torques) - o.target).norm(), 0.005);
  EXPECT_LT(r.simulations, 20) << r.stop;  // measured 5 simulations, error 1.0 mm, 12 s
}

TEST(Reach, BadInputNamesTheFlag) {
  ReachOptions o = reachOptions();
  o.body = "foot";
  try {
    makeReachSetup(o);
    FAIL() << "unknown body accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--body 'foot': no body named so"), std::string::npos) << e.what();
  }
  o = reachOptions();
  o.target[1] = std::nan("");
  EXPECT_THROW(makeReachSetup(o), std::invalid_argument);
  o = reachOptions();
  o.coordinates = {"shoulder_flexion", "wrist"};
  try {
    makeReachSetup(o);
    FAIL() << "unknown coordinate accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--coordinates 'wrist': no coordinate named 'wrist'");
  }
  const ReachSetup s = makeReachSetup(reachOptions());
  EXPECT_THROW(optimizeReach(s, "newton"), std::invalid_argument);
  auto message = [](ReachOptions o) -> std::string {
    try {
      makeReachSetup(o);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  ReachOptions e = reachOptions();
  e.drive = "muscles";
  EXPECT_EQ(message(e), "--drive 'muscles': unknown (torques or excitations)");
  e.drive = "excitations";
  e.muscles = {"BIC"};
  EXPECT_EQ(message(e), "--excite 'BIC': no muscle named 'BIC'");
  e.muscles = {"DELT1"};
  e.initial_excitation = 2.0;
  EXPECT_EQ(message(e),
            "--initial-excitation: the value must lie in the muscle's [min_control, max_control] = [0.010000, 1.000000]");
}

}  // namespace
}  // namespace redmax::validation
