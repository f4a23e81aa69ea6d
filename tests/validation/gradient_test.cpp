// Adjoint gradients through inertial muscles of every path type (validation/gradient, core/adjoint,
// docs/gradients.md): the double pendulums of osim_models/ with muscle mass, generalized-force,
// initial-state and muscle-mass parameters, against central differences of whole simulations.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "validation/gradient/gradient.hpp"

namespace redmax::validation {
namespace {

struct Case {
  const char* file;
  const char* muscle;
  const char* integrator;
};

class MuscleGradient : public ::testing::TestWithParam<Case> {};

TEST_P(MuscleGradient, AdjointMatchesCentralDifferences) {
  const Case c = GetParam();
  SimulationModelOptions mo;
  mo.explicit_masses = {{c.muscle, 0.5}};
  mo.muscle_mass.mass_points = 8;
  mo.muscle_mass.wrap_mass = true;  // Type III: mass over the smooth wrap model
  const std::string file = std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + c.file;
  GradientSetup g = makeGradientSetup(file, mo, c.integrator, 0.2, 0.005,
                                      std::string("torques:q1@2,q2;q0:q2=0.4;qdot0:q1;masses:") + c.muscle,
                                      "point:link2@0,-1,0=0.5,-1.5,0;0.1*speed;0.01*effort");
  ASSERT_GT(g.model.muscle_mass, 0.4);
  ASSERT_EQ(g.p0.size(), 6);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-4.0, 4.0);
  VecX p = g.p0;
  for (int i = 0; i < 3; ++i) p[i] = u(rng);
  p[4] = 0.5 * u(rng);
  const VecX fd = adjoint::finiteDifferenceGradient(g.problem, g.objective, p);
  const bool wraps = std::string(c.muscle) == "wrap_muscle";
  // both routes of the step Jacobians
  for (const char* route : {"differences", "analytic"}) {
    g.problem.step_jacobians = route;
    const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, p, true);
    const double err = adjoint::worstRelativeError(r.gradient, fd);
    std::printf("[ measured ] %s, %s, %s step Jacobians: %.2e\n", c.muscle, c.integrator, route, err);
    // measured, differenced: 9.4e-11 (Type I), 3.2e-10 (Type II), euler and bdf1 alike (these
    // models have no joint springs, so bdf1's step is euler's); Type III 7.4e-7 (euler, bdf1) and
    // 1.8e-7 (sdirk2), every component off by about the same relative amount (the run crosses the
    // wrap's contact changes; whether the adjoint or the reference carries it is not resolved).
    // Analytic, the mass's column from dtau/ds: 1.5e-11 (Type I), 1.8e-10 (Type II), 1.8e-7 (Type
    // III, euler, bdf1) and 5.6e-7 (sdirk2): the two routes differ from the reference, and from each
    // other, by the same order here, where the run crosses the wrap's contact changes
    EXPECT_LE(err, wraps ? 1e-6 : 5e-9) << route << "\nadjoint " << r.gradient.transpose() << "\ndifferences "
                                         << fd.transpose();
    EXPECT_NE(r.gradient[5], 0.0);  // the muscle's mass moves the hand
  }
}

INSTANTIATE_TEST_SUITE_P(
    PathTypes, MuscleGradient,
    ::testing::Values(Case{"double_pendulum_straight.osim", "straight_muscle", "euler"},
                      Case{"double_pendulum_via.osim", "via_muscle", "euler"},
                      Case{"double_pendulum_wrap.osim", "wrap_muscle", "euler"},
                      Case{"double_pendulum_straight.osim", "straight_muscle", "bdf1"},
                      Case{"double_pendulum_via.osim", "via_muscle", "bdf1"},
                      Case{"double_pendulum_wrap.osim", "wrap_muscle", "bdf1"},
                      Case{"double_pendulum_wrap.osim", "wrap_muscle", "sdirk2"}),
    [](const ::testing::TestParamInfo<Case>& info) {
      std::string n = std::string(info.param.muscle) + "_" + info.param.integrator;
      return n;
    });

// The ForceSet's passive forces are in the gradient's system, as in `redmax simulate`:
// reach_arm.osim's elbow_limit (CoordinateLimitForce, 1 N m/deg past 0 and 150 deg over a 5 deg
// transition) stops the elbow driven toward hyperextension, and its force is differentiated with
// the rest of the step; the muscles (no excitation parameters) are named as not applied.
TEST(GradientPassiveForces, CoordinateLimitForceActsAndIsDifferentiated) {
  const std::string file = std::string(REDMAX_SOURCE_DIR) + "/osim_models/reach_arm.osim";
  GradientSetup g = makeGradientSetup(file, SimulationModelOptions{}, "euler", 0.3, 0.002,
                                      "torques:elbow_flexion=-2,shoulder_flexion;q0:elbow_flexion=0.1;qdot0:elbow_flexion=-1",
                                      "point:hand@0,-0.08,0=0.2,-0.6,0;0.1*speed");
  bool limit = false;
  for (const auto& t : g.model.system->terms()) limit = limit || t->name() == "coordinate_limit_forces";
  EXPECT_TRUE(limit);
  ASSERT_FALSE(g.not_applied.empty());
  EXPECT_NE(g.not_applied.front().find("6 path forces exert no force without excitation parameters"), std::string::npos)
      << g.not_applied.front();
  const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, g.p0, true);
  const int elbow = g.model.system->model().findCoordinate("elbow_flexion");
  // -2 N m toward hyperextension from 0.1 rad at -1 rad/s: held within the 5 deg transition
  // (measured final angle below)
  EXPECT_GT(r.final.q[elbow], -0.0873);
  EXPECT_LT(r.final.q[elbow], 0.0);
  const VecX fd = adjoint::finiteDifferenceGradient(g.problem, g.objective, g.p0);
  const double err = adjoint::worstRelativeError(r.gradient, fd);
  EXPECT_LE(err, 2e-7) << "adjoint " << r.gradient.transpose() << "\ndifferences " << fd.transpose();
  std::printf("[ measured ] elbow_limit in the gradient: final elbow %.4f rad, adjoint vs differences %.2e\n",
              r.final.q[elbow], err);
}

TEST(GradientSpec, BadSpecsNameTheItem) {
  const std::string file = std::string(REDMAX_SOURCE_DIR) + "/osim_models/double_pendulum_straight.osim";
  SimulationModelOptions mo;
  auto message = [&](const std::string& params, const std::string& objective) -> std::string {
    try {
      makeGradientSetup(file, mo, "euler", 0.1, 0.01, params, objective);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message("torques:elbow", "speed"), "--params 'torques:elbow': no coordinate named 'elbow'");
  EXPECT_EQ(message("torque:q1", "speed"), "--params 'torque:q1': unknown kind 'torque' (torques, excitations, q0, qdot0 or masses)");
  EXPECT_EQ(message("torques:q1@0", "speed"), "--params 'torques:q1@0': the piece count after '@' must be a whole number >= 1");
  EXPECT_EQ(message("masses:straight_muscle", "speed"),
            "--params 'masses:straight_muscle': needs a positive mass for it in --muscle-mass-kg straight_muscle=KG");
  EXPECT_EQ(message("torques:q1", "point:hand@0,0,0=1,2,3"), "--objective 'point:hand@0,0,0=1,2,3': no body named 'hand'");
  EXPECT_EQ(message("torques:q1", "point:link2@0,0=1,2,3"),
            "--objective 'point:link2@0,0=1,2,3': the point must be three numbers x,y,z (m, body frame)");
  EXPECT_EQ(message("torques:q1", "x*speed"), "--objective 'x*speed': the weight before '*' must be a number >= 0");
  EXPECT_EQ(message("torques:q1", "rest"),
            "--objective 'rest': unknown term (point:BODY@x,y,z=X,Y,Z, marker:NAME=X,Y,Z, track:MARKER=FILE.trc, "
            "coords:FILE.mot[@C,...], speed, effort or excitation)");
  EXPECT_EQ(message("torques:q1", "excitation"),
            "--objective 'excitation': needs excitation parameters (--params 'excitations:...')");
  EXPECT_EQ(message("excitations:nobody", "speed"), "--params 'excitations:nobody': no muscle named 'nobody'");
  EXPECT_EQ(message("excitations:straight_muscle@0", "speed"),
            "--params 'excitations:straight_muscle@0': the node count after '@' must be a whole number >= 1");
  EXPECT_EQ(message("excitations:straight_muscle=1.5", "speed"),
            "--params 'excitations:straight_muscle=1.5': the value must lie in the muscle's [min_control, "
            "max_control] = [0.010000, 1.000000]");
  EXPECT_EQ(message("excitations:straight_muscle,straight_muscle@2", "speed"),
            "--params 'excitations:straight_muscle@2': muscle 'straight_muscle' is named twice");
}

// ---- Hill-type muscles (docs/gradients.md §2, §5): with excitation parameters the muscles pull,
// their activation and fibre length are states of the run

std::string osimModel(const char* file) { return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + file; }

class HillGradient : public ::testing::TestWithParam<const char*> {};

// tug_of_war_step.osim: a 20 kg block between two Millard muscles (Type I), both well excited so
// that their tendons stay taut; excitation nodes, initial position and speed, and the left
// muscle's mass (0.5 kg in 8 points) against central differences of whole runs
TEST_P(HillGradient, TugOfWarNodesInitialStateAndMassAgainstDifferences) {
  SimulationModelOptions mo;
  mo.explicit_masses = {{"left_muscle", 0.5}};
  mo.muscle_mass.mass_points = 8;
  GradientSetup g = makeGradientSetup(osimModel("tug_of_war_step.osim"), mo, GetParam(), 0.1, 0.001,
                                      "excitations:left_muscle@5,right_muscle@3;q0:block_x=0.01;qdot0:block_x;"
                                      "masses:left_muscle",
                                      "point:block@0,0,0=0.05,0,0;0.1*speed;0.01*excitation");
  ASSERT_EQ(g.p0.size(), 11);
  ASSERT_EQ(g.model.system->numStates(), 4);  // activation and fibre length of each muscle
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.6, 0.95);
  VecX p = g.p0;
  for (int i = 0; i < 8; ++i) p[i] = u(rng);
  p[9] = 0.02;  // qdot0
  const VecX fd = adjoint::finiteDifferenceGradient(g.problem, g.objective, p);
  // differenced route: measured 1.7e-9 (euler and bdf1 alike: no joint springs; sdirk2 2.5e-9)
  // with the step Jacobians' relative difference step 2e-7 that makeGradientSetup picks for
  // non-wrapping Hill muscles; 3.2e-6 at the default 6e-6, whose truncation error the tendon's
  // curvature near slack makes (§2, §5). Analytic route (the muscles' term differenced alone at
  // the same step, docs/gradients.md §2.1): measured 2.9e-9 (euler, bdf1), 2.6e-9 (sdirk2)
  EXPECT_DOUBLE_EQ(g.problem.jacobian_step, 2e-7);
  for (const char* route : {"differences", "analytic"}) {
    g.problem.step_jacobians = route;
    const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, p, true);
    const double err = adjoint::worstRelativeError(r.gradient, fd);
    std::printf("[ measured ] %s, %s step Jacobians: %.2e\n", GetParam(), route, err);
    EXPECT_LE(err, 6e-9) << route << "\nadjoint " << r.gradient.transpose() << "\ndifferences " << fd.transpose();
    for (int i = 0; i < 8; ++i) EXPECT_NE(r.gradient[i], 0.0) << i;  // every node moves the block
    EXPECT_NE(r.gradient[10], 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Integrators, HillGradient, ::testing::Values("euler", "bdf1", "sdirk2"));

// the muscles pull: the same excitations on a lumped model give a run, and a gradient, that
// differs from the one without Hill muscles (where the block would not move at all)
TEST(HillGradientTerms, ExcitationsMakeTheMusclesPull) {
  SimulationModelOptions mo;
  GradientSetup g = makeGradientSetup(osimModel("tug_of_war_step.osim"), mo, "euler", 0.1, 0.001,
                                      "excitations:left_muscle=0.9,right_muscle=0.3", "point:block@0,0,0=0.05,0,0");
  const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, g.p0, true);
  // the left muscle pulls harder: the block moves left (towards -x) by more than a millimetre
  EXPECT_LT(r.final.q[0], -1e-3);
  EXPECT_GT(r.gradient[0], 0.0);  // more left excitation: further from the target at +0.05
  EXPECT_LT(r.gradient[1], 0.0);
  // the same equal excitations cancel exactly (the model is a mirror image)
  GradientSetup e = makeGradientSetup(osimModel("tug_of_war_step.osim"), mo, "euler", 0.1, 0.001,
                                      "excitations:left_muscle=0.5,right_muscle=0.5", "speed");
  EXPECT_EQ(adjoint::evaluate(e.problem, e.objective, e.p0, false).final.q[0], 0.0);
}

// excitations are clamped to the muscle's [min_control, max_control]: nodes above max_control
// drive the run as max_control does, and their derivative is zero (the clamp is flat there)
TEST(HillGradientTerms, ClampedNodesHaveZeroDerivative) {
  SimulationModelOptions mo;
  GradientSetup g = makeGradientSetup(osimModel("tug_of_war_step.osim"), mo, "euler", 0.05, 0.001,
                                      "excitations:left_muscle@2,right_muscle=0.7", "point:block@0,0,0=0.05,0,0");
  VecX p = g.p0;
  p << 1.3, 1.6, 0.7;  // both left nodes above max_control = 1
  const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, p, true);
  EXPECT_EQ(r.gradient[0], 0.0);
  EXPECT_EQ(r.gradient[1], 0.0);
  EXPECT_NE(r.gradient[2], 0.0);
  VecX at_max = p;
  at_max << 1.0, 1.0, 0.7;
  EXPECT_EQ(adjoint::evaluate(g.problem, g.objective, at_max, false).objective, r.objective);
}

// the cost does not depend on the number of nodes: one difference pair per excited muscle per
// step, N (1 + 2 n_excited + 2 (2 n + n_z)) step evaluations
TEST(HillGradientTerms, StepEvaluationsDoNotGrowWithTheNodes) {
  SimulationModelOptions mo;
  auto count = [&](const std::string& params, const char* route) {
    GradientSetup g = makeGradientSetup(osimModel("tug_of_war_step.osim"), mo, "euler", 0.05, 0.001, params,
                                        "point:block@0,0,0=0.05,0,0");
    g.problem.step_jacobians = route;
    const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, g.p0, true);
    EXPECT_EQ(r.analytic_jacobians, std::string(route) == "analytic");
    return r.step_evaluations;
  };
  const long two = count("excitations:left_muscle@2=0.6,right_muscle@2=0.5", "differences");
  const long forty = count("excitations:left_muscle@40=0.6,right_muscle@40=0.5", "differences");
  EXPECT_EQ(two, forty);
  EXPECT_EQ(two, 50 * (1 + 2 * 2 + 2 * (2 * 1 + 4)));
  // the analytic route evaluates the forward run's steps only, whatever the nodes
  EXPECT_EQ(count("excitations:left_muscle@2=0.6,right_muscle@2=0.5", "analytic"), 50);
  EXPECT_EQ(count("excitations:left_muscle@40=0.6,right_muscle@40=0.5", "analytic"), 50);
}

// zero muscle mass is the massless (lumped) model: the same gradient, bit for bit
TEST(HillGradientTerms, ZeroMuscleMassReproducesTheMasslessGradient) {
  const std::string params = "excitations:left_muscle@4=0.8,right_muscle@2=0.7;q0:block_x=0.01;qdot0:block_x";
  const std::string objective = "point:block@0,0,0=0.05,0,0;0.1*speed";
  SimulationModelOptions lumped, zero;
  zero.explicit_masses = {{"left_muscle", 0.0}, {"right_muscle", 0.0}};
  zero.muscle_mass.mass_points = 8;
  GradientSetup a = makeGradientSetup(osimModel("tug_of_war_step.osim"), lumped, "euler", 0.05, 0.001, params, objective);
  GradientSetup b = makeGradientSetup(osimModel("tug_of_war_step.osim"), zero, "euler", 0.05, 0.001, params, objective);
  const adjoint::Result ra = adjoint::evaluate(a.problem, a.objective, a.p0, true);
  const adjoint::Result rb = adjoint::evaluate(b.problem, b.objective, b.p0, true);
  ASSERT_EQ(ra.gradient.size(), rb.gradient.size());
  EXPECT_EQ(ra.objective, rb.objective);
  for (Eigen::Index i = 0; i < ra.gradient.size(); ++i) EXPECT_EQ(ra.gradient[i], rb.gradient[i]) << i;
  // and a small mass moves it a little, continuously
  SimulationModelOptions small = zero;
  small.explicit_masses = {{"left_muscle", 1e-3}, {"right_muscle", 1e-3}};
  GradientSetup c = makeGradientSetup(osimModel("tug_of_war_step.osim"), small, "euler", 0.05, 0.001, params, objective);
  const adjoint::Result rc = adjoint::evaluate(c.problem, c.objective, c.p0, true);
  EXPECT_NE(rc.gradient, ra.gradient);
  EXPECT_LE(adjoint::worstRelativeError(rc.gradient, ra.gradient), 1e-5);  // measured 2.6e-6
}

// arm26 (OpenSim's model, Thelen2003 muscles) from the shared data: the gradient is that of the
// run computed, but Thelen's force-velocity inverse has a kink at isometric contraction (the
// concentric and eccentric branches meet with different slopes) and the run starts there (fibres
// equilibrated), so central differences of the steps and of the runs disagree at the 1e-3 level
TEST(HillGradientTerms, Arm26ThelenMusclesMeasured) {
  const std::string model = std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-models/Models/Arm26/arm26.osim";
  if (!std::filesystem::exists(model)) GTEST_SKIP() << "shared OpenSim data not found: " << model;
  SimulationModelOptions mo;
  GradientSetup g = makeGradientSetup(model, mo, "euler", 0.1, 0.001,
                                      "excitations:BIClong@3=0.8,TRIlong@3=0.7,TRIlat=0.6,TRImed=0.6,BICshort=0.7,"
                                      "BRA=0.8;qdot0:r_elbow_flex",
                                      "point:r_ulna_radius_hand@0,-0.2,0=0.3,0.1,0.4;0.1*speed");
  const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, g.p0, true);
  const VecX fd = adjoint::finiteDifferenceGradient(g.problem, g.objective, g.p0);
  // measured 1.9e-3
  EXPECT_LE(adjoint::worstRelativeError(r.gradient, fd), 4e-3)
      << "adjoint " << r.gradient.transpose() << "\ndifferences " << fd.transpose();
}

// leg6dof9musc (shared data: its knee's coordinate coupler, nine Thelen muscles, physiological
// mass points) with two muscles excited and a hip torque, each integrator: the analytic route (the
// muscles differenced alone, the coupler's rows written, the mass points' tangent) against the
// differenced route, and both against central differences of whole runs
class HillGradientModels : public ::testing::TestWithParam<const char*> {};

TEST_P(HillGradientModels, Leg6Dof9MuscBothRoutes) {
  const std::string model =
      std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-models/Models/Leg6Dof9Musc/leg6dof9musc.osim";
  if (!std::filesystem::exists(model)) GTEST_SKIP() << "shared OpenSim data not found: " << model;
  SimulationModelOptions mo;
  mo.muscle_mass.source = osim::MuscleMassOptions::Source::Physiological;
  GradientSetup g = makeGradientSetup(model, mo, GetParam(), 0.02, 0.001,
                                      "excitations:vas_int_r@2=0.5,bifemsh_r=0.3;torques:hip_flexion_r", "speed");
  const VecX fd = adjoint::finiteDifferenceGradient(g.problem, g.objective, g.p0);
  VecX grads[2];
  int i = 0;
  for (const char* route : {"analytic", "differences"}) {
    g.problem.step_jacobians = route;
    const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, g.p0, true);
    EXPECT_EQ(r.analytic_jacobians, i == 0);
    grads[i++] = r.gradient;
  }
  const double fd_a = adjoint::worstRelativeError(grads[0], fd), fd_d = adjoint::worstRelativeError(grads[1], fd);
  const double routes = adjoint::worstRelativeError(grads[0], grads[1]);
  std::printf("[ measured ] leg6dof9musc, %s: analytic %.2e, differenced %.2e against whole runs; routes %.2e apart\n",
              GetParam(), fd_a, fd_d, routes);
  // measured 9.7e-7 (euler, bdf1) and 5.2e-7 (sdirk2) for both routes: the Thelen kinks (above),
  // which the two routes meet alike (their gradients 1.1e-8 .. 5.7e-8 apart)
  EXPECT_LE(fd_a, 2e-6);
  EXPECT_LE(fd_d, 2e-6);
  EXPECT_LE(routes, 2e-7);
}

INSTANTIATE_TEST_SUITE_P(Integrators, HillGradientModels, ::testing::Values("euler", "bdf1", "sdirk2"));

}  // namespace
}  // namespace redmax::validation
