// Adjoint gradients through inertial muscles of every path type (validation/gradient, core/adjoint,
// docs/gradients.md): the double pendulums of osim_models/ with muscle mass, generalized-force,
// initial-state and muscle-mass parameters, against central differences of whole simulations.
#include <gtest/gtest.h>

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
  const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, p, true);
  const VecX fd = adjoint::finiteDifferenceGradient(g.problem, g.objective, p);
  // measured: 1.0e-10 (Type I), 5.0e-10 (Type II), euler and bdf1 alike (these models have no
  // joint springs, so bdf1's step is euler's); Type III 7.4e-7 (euler, bdf1) and 1.8e-7 (sdirk2),
  // every component off by about the same relative amount (the run crosses the wrap's contact
  // changes; whether the adjoint or the reference carries it is not resolved)
  const bool wraps = std::string(c.muscle) == "wrap_muscle";
  EXPECT_LE(adjoint::worstRelativeError(r.gradient, fd), wraps ? 1e-6 : 5e-9)
      << "adjoint " << r.gradient.transpose() << "\ndifferences " << fd.transpose();
  EXPECT_NE(r.gradient[5], 0.0);  // the muscle's mass moves the hand
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
  EXPECT_EQ(message("torque:q1", "speed"), "--params 'torque:q1': unknown kind 'torque' (torques, q0, qdot0 or masses)");
  EXPECT_EQ(message("torques:q1@0", "speed"), "--params 'torques:q1@0': the piece count after '@' must be a whole number >= 1");
  EXPECT_EQ(message("masses:straight_muscle", "speed"),
            "--params 'masses:straight_muscle': needs a positive mass for it in --muscle-mass-kg straight_muscle=KG");
  EXPECT_EQ(message("torques:q1", "point:hand@0,0,0=1,2,3"), "--objective 'point:hand@0,0,0=1,2,3': no body named 'hand'");
  EXPECT_EQ(message("torques:q1", "point:link2@0,0=1,2,3"),
            "--objective 'point:link2@0,0=1,2,3': the point must be three numbers x,y,z (m, body frame)");
  EXPECT_EQ(message("torques:q1", "x*speed"), "--objective 'x*speed': the weight before '*' must be a number >= 0");
  EXPECT_EQ(message("torques:q1", "rest"),
            "--objective 'rest': unknown term (point:BODY@x,y,z=X,Y,Z, speed or effort)");
}

}  // namespace
}  // namespace redmax::validation
