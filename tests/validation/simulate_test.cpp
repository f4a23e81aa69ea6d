// The simulation driver behind `redmax simulate` (validation/simulate): energy conservation on the
// project's double pendulums, a closed-form small-angle period, restarts from a states table,
// every integrator against a tight reference, and divergence reported with time, coordinate, step.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "converter/osim_reader.hpp"
#include "validation/simulate/simulate.hpp"

namespace {

using namespace redmax;
using namespace redmax::validation;
namespace fs = std::filesystem;

std::string scene(const std::string& file) { return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + file; }

SimulateOptions tight(double duration) {
  SimulateOptions o;
  o.integrator = "rk45";
  o.integrator_options.rtol = 1e-11;
  o.integrator_options.atol = 1e-12;
  o.duration = duration;
  return o;
}

// one pin joint about z, link hanging along -y: m = 1.3 kg, COM 0.45 m below the pin, Izz = 0.05
// about the COM; small-angle frequency w = sqrt(m g c / (Izz + m c^2))
const char* kSinglePendulum = R"(<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000">
  <Model name="single_pendulum">
    <Ground name="ground" />
    <gravity>0 -9.80665 0</gravity>
    <BodySet name="bodyset"><objects>
      <Body name="link"><mass>1.3</mass><mass_center>0 -0.45 0</mass_center>
        <inertia>0.05 0.01 0.05 0 0 0</inertia></Body>
    </objects></BodySet>
    <JointSet name="jointset"><objects>
      <PinJoint name="pin">
        <socket_parent_frame>ground_offset</socket_parent_frame>
        <socket_child_frame>link_offset</socket_child_frame>
        <coordinates><Coordinate name="theta">
          <default_value>0.001</default_value><default_speed_value>0</default_speed_value>
          <range>-3.14159 3.14159</range></Coordinate></coordinates>
        <frames>
          <PhysicalOffsetFrame name="ground_offset"><socket_parent>/ground</socket_parent>
            <translation>0 0 0</translation><orientation>0 0 0</orientation></PhysicalOffsetFrame>
          <PhysicalOffsetFrame name="link_offset"><socket_parent>/bodyset/link</socket_parent>
            <translation>0 0 0</translation><orientation>0 0 0</orientation></PhysicalOffsetFrame>
        </frames>
      </PinJoint>
    </objects></JointSet>
  </Model>
</OpenSimDocument>
)";

TEST(Simulate, DoublePendulumLumpedConservesEnergyWithTightRk45) {
  const SimulationModel m = loadSimulationModel(scene("double_pendulum_via.osim"), {});
  EXPECT_EQ(m.muscle_term, nullptr);  // lumped: the model as OpenSim sees it
  const SimulationResult r = simulate(m, defaultInitialState(m), tight(2.0));
  ASSERT_FALSE(r.failed) << r.failure;
  EXPECT_EQ(r.states.numRows(), 201);
  EXPECT_LE(r.energy_drift_rel, 1e-8);
  // it really moved: from 45 degrees at rest the kinetic energy reaches joules
  const int ke = r.states.findColumn("kinetic_energy");
  ASSERT_GE(ke, 0);
  EXPECT_GT(r.states.data.col(ke).maxCoeff(), 1.0);
  // the columns are OpenSim's state paths
  EXPECT_EQ(r.states.labels[0], "/jointset/pin1/q1/value");
  EXPECT_EQ(r.states.labels[3], "/jointset/pin2/q2/speed");
}

TEST(Simulate, MuscleMassConservesEnergyOnlyWithItsQuadraticVelocityVector) {
  // [D 6.2.4]: a straight muscle with the mass of a link (1 kg, 20 points); with its QVV the total
  // energy is conserved to the integrator's accuracy over 10 s, without it the energy drifts
  SimulationModelOptions mo;
  mo.explicit_masses = {{"straight_muscle", 1.0}};
  const SimulationModel with = loadSimulationModel(scene("double_pendulum_straight.osim"), mo);
  ASSERT_NE(with.muscle_term, nullptr);
  EXPECT_NEAR(with.muscle_mass, 1.0, 1e-14);
  EXPECT_NEAR(with.added_mass, 1.0, 1e-14);
  const SimulationResult r = simulate(with, defaultInitialState(with), tight(10.0));
  ASSERT_FALSE(r.failed) << r.failure;
  EXPECT_LE(r.energy_drift_rel, 1e-8);

  mo.quadratic_velocity = false;
  const SimulationModel without = loadSimulationModel(scene("double_pendulum_straight.osim"), mo);
  const SimulationResult r2 = simulate(without, defaultInitialState(without), tight(10.0));
  ASSERT_FALSE(r2.failed) << r2.failure;
  EXPECT_GE(r2.energy_drift_rel, 1e-3);
}

TEST(Simulate, ViaPointOnAMovingBodyLeavesOnlyThePassageJumps) {
  // double_pendulum_via.osim's via point rides on link1: mass points sliding past it change
  // velocity abruptly, so the energy jumps at each passage (docs/notes.md, conditional path points) even with
  // the QVV; dropping the QVV adds the smooth drift on top, several times larger
  SimulationModelOptions mo;
  mo.explicit_masses = {{"via_muscle", 1.0}};
  const SimulationModel with = loadSimulationModel(scene("double_pendulum_via.osim"), mo);
  const SimulationResult r = simulate(with, defaultInitialState(with), tight(2.0));
  mo.quadratic_velocity = false;
  const SimulationModel without = loadSimulationModel(scene("double_pendulum_via.osim"), mo);
  const SimulationResult r2 = simulate(without, defaultInitialState(without), tight(2.0));
  ASSERT_FALSE(r.failed || r2.failed);
  EXPECT_LE(5 * r.energy_drift_rel, r2.energy_drift_rel);
}

TEST(Simulate, SmallAnglePendulumFollowsTheClosedForm) {
  const fs::path dir = fs::temp_directory_path() / ("redmax_simulate_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / "single.osim";
  std::ofstream(file) << kSinglePendulum;
  const SimulationModel m = loadSimulationModel(file.string(), {});
  fs::remove_all(dir);
  const double mass = 1.3, c = 0.45, I = 0.05, g = 9.80665, theta0 = 1e-3;
  const double w = std::sqrt(mass * g * c / (I + mass * c * c));
  SimulateOptions o = tight(3 * 2 * M_PI / w);  // three periods
  o.output_dt = 1e-3;
  const SimulationResult r = simulate(m, defaultInitialState(m), o);
  ASSERT_FALSE(r.failed) << r.failure;
  // theta = theta0 cos(w t) up to the amplitude correction of the period, (theta0^2 / 16) ~ 6e-8
  double worst = 0.0;
  for (int k = 0; k < r.states.numRows(); ++k)
    worst = std::max(worst, std::abs(r.states.data(k, 0) / theta0 - std::cos(w * r.states.time[k])));
  EXPECT_LE(worst, 1e-5);
  // and the speed column is its derivative
  const int u = r.states.findColumn("/jointset/pin/theta/speed");
  ASSERT_GE(u, 0);
  for (int k = 0; k < r.states.numRows(); k += 97)
    EXPECT_NEAR(r.states.data(k, u) / (theta0 * w), -std::sin(w * r.states.time[k]), 1e-5);
}

TEST(Simulate, RestartFromAStatesRowContinuesTheSameTrajectory) {
  SimulationModelOptions mo;
  mo.explicit_masses = {{"via_muscle", 0.5}};
  const SimulationModel m = loadSimulationModel(scene("double_pendulum_via.osim"), mo);
  for (const char* integ : {"euler", "rk45"}) {
    SCOPED_TRACE(integ);
    SimulateOptions o;
    o.integrator = integ;
    o.integrator_options.rtol = 1e-10;
    o.integrator_options.atol = 1e-12;
    o.duration = 2.0;
    const SimulationResult full = simulate(m, defaultInitialState(m), o);
    ASSERT_FALSE(full.failed) << full.failure;
    // restart from the row at t = 1 s of the written table
    const State mid = initialStateFromStorage(m, full.states, "full.sto", 1.0);
    EXPECT_DOUBLE_EQ(mid.t, 1.0);
    o.duration = 1.0;
    const SimulationResult rest = simulate(m, mid, o);
    ASSERT_FALSE(rest.failed) << rest.failure;
    ASSERT_EQ(rest.states.numRows(), 101);
    // fixed steps repeat the same arithmetic (to round-off in the step times); the adaptive method
    // restarts its step-size sequence, so it agrees to its tolerance
    const double tol = std::string(integ) == "euler" ? 1e-11 : 1e-7;
    for (int k = 0; k < rest.states.numRows(); ++k) {
      EXPECT_NEAR(rest.states.time[k], full.states.time[100 + k], 1e-12);
      EXPECT_LE((rest.states.data.row(k) - full.states.data.row(100 + k)).cwiseAbs().maxCoeff(), tol) << k;
    }
  }
}

TEST(Simulate, InitialStateReadsCoordinateNamesAndDegrees) {
  const SimulationModel m = loadSimulationModel(scene("double_pendulum_via.osim"), {});
  osim::Storage t;
  t.in_degrees = true;
  t.labels = {"q2", "q2_u"};
  t.time = {0.5, 0.0};
  t.data.resize(2, 2);
  t.data << 1, 2, 30, 90;
  const State s = initialStateFromStorage(m, t, "t.sto");
  EXPECT_EQ(s.t, 0.0);  // the row at t = 0, not the first row
  EXPECT_NEAR(s.q[0], M_PI / 4, 1e-15);  // q1 absent: its default
  EXPECT_NEAR(s.q[1], M_PI / 6, 1e-15);
  EXPECT_NEAR(s.qdot[1], M_PI / 2, 1e-15);
  t.labels = {"nothing", "else"};
  EXPECT_THROW(initialStateFromStorage(m, t, "t.sto"), osim::ConvertError);
}

TEST(Simulate, EveryIntegratorRunsAndApproachesTheReference) {
  const SimulationModel m = loadSimulationModel(scene("double_pendulum_via.osim"), {});
  const State s0 = defaultInitialState(m);
  const SimulationResult ref = simulate(m, s0, tight(0.5));
  ASSERT_FALSE(ref.failed);
  // first-order methods at h = 1 ms err by O(h); second order by O(h^2); adaptive by their tolerance
  const std::vector<std::pair<std::string, double>> cases = {
      {"euler", 5e-3}, {"symplectic", 5e-3}, {"bdf1", 5e-3}, {"sdirk2", 1e-5}, {"rk45", 1e-6}, {"cvode", 2e-5}};
  for (const auto& [name, tol] : cases) {
    SCOPED_TRACE(name);
    SimulateOptions o;
    o.integrator = name;
    o.duration = 0.5;
    const SimulationResult r = simulate(m, s0, o);
    ASSERT_FALSE(r.failed) << r.failure;
    EXPECT_GT(r.stats.steps, 0);
    EXPECT_GT(r.stats.rhs_evals, 0);
    const double err = (r.final_state.q - ref.final_state.q).cwiseAbs().maxCoeff();
    EXPECT_LE(err, tol);
    EXPECT_GT(err, 0.0);
  }
  // halving the fixed step divides the error by 2^order (first order euler, second order sdirk2)
  for (const auto& [name, order] : std::vector<std::pair<std::string, int>>{{"euler", 1}, {"sdirk2", 2}}) {
    SCOPED_TRACE(name);
    double err[2];
    for (int k = 0; k < 2; ++k) {
      SimulateOptions o;
      o.integrator = name;
      o.integrator_options.dt = 1e-3 / (1 << k);
      o.duration = 0.5;
      err[k] = (simulate(m, s0, o).final_state.q - ref.final_state.q).cwiseAbs().maxCoeff();
    }
    EXPECT_NEAR(std::log2(err[0] / err[1]), order, 0.2);
  }
}

TEST(Simulate, DivergenceStopsWithTimeCoordinateAndStep) {
  SimulationModel m = loadSimulationModel(scene("double_pendulum_via.osim"), {});
  // a stiff joint spring on q2 (w = 1e4 rad/s) with explicit steps of 1 ms: h w = 10 >> 2
  ModelBuilder stiff(m.system->model());
  stiff.coordinateAt(1).stiffness = 1e8;
  m.system = std::make_shared<System>(stiff.finalize());
  SimulateOptions o;
  o.integrator = "euler";
  o.duration = 1.0;
  const SimulationResult r = simulate(m, defaultInitialState(m), o);
  ASSERT_TRUE(r.failed);
  EXPECT_NE(r.failure.find("coordinate 'q"), std::string::npos) << r.failure;
  EXPECT_NE(r.failure.find("step h = 0.001"), std::string::npos) << r.failure;
  EXPECT_GT(r.failure_time, 0.0);
  EXPECT_LT(r.failure_time, 1.0);
  EXPECT_EQ(r.failure_step, 1e-3);
  // the rows before the failure are kept, all finite
  EXPECT_GE(r.states.numRows(), 1);
  EXPECT_TRUE(r.states.data.allFinite());
}

TEST(Simulate, ImpulseGivesTheMomentumItCarries) {
  // a force F along x on the single pendulum's COM for tau seconds changes the angular momentum
  // about the pin by F c tau (gravity's torque at theta ~ 0 adds nothing at first order)
  const fs::path dir = fs::temp_directory_path() / ("redmax_simulate_imp_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / "single.osim";
  std::string text = kSinglePendulum;
  const std::string key = "<default_value>0.001";
  text.replace(text.find(key), key.size(), "<default_value>0");
  std::ofstream(file) << text;
  SimulationModelOptions mo;
  mo.impulses = {parseImpulse("link@0,-0.45,0:2,0,0:0.002")};
  const SimulationModel m = loadSimulationModel(file.string(), mo);
  fs::remove_all(dir);
  SimulateOptions o = tight(0.01);
  o.output_dt = 0.002;
  const SimulationResult r = simulate(m, defaultInitialState(m), o);
  ASSERT_FALSE(r.failed) << r.failure;
  const double J = 0.05 + 1.3 * 0.45 * 0.45;  // about the pin
  // row 1 is t = 2 ms: the end of the impulse; the rotation is about +z for a push along +x below
  EXPECT_NEAR(r.states.time[1], 0.002, 1e-15);
  EXPECT_NEAR(r.states.data(1, 1) * J, 2 * 0.45 * 0.002, 1e-4 * 2 * 0.45 * 0.002);
  // bad specs are rejected
  EXPECT_THROW(parseImpulse("link:1,2:0.1"), std::invalid_argument);
  EXPECT_THROW(parseImpulse("link:1,2,3:-1"), std::invalid_argument);
  EXPECT_THROW(parseImpulse(":1,2,3:1"), std::invalid_argument);
}

// A hard case found on a real model: subject_walk_armless_18musc swinging freely (no controls, no
// contact: it falls and its joints go far out of range) with physiological mass on glut_max2_* over
// the smooth wrap model. An end of the wrapped segment reached the pelvis's wrap cylinder, where
// the tangent construction's derivatives are infinite; rk45 crawled into it and qddot became NaN at
// t = 0.445 s. With the end-point fade of core/muscles/wrap/smooth.hpp the swing runs to 0.5 s.
TEST(Simulate, FreeSwingWithWrappingMuscleMassRunsThroughAnEndAtTheSurface) {
  const std::string model =
      std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-core/OpenSim/Moco/Test/subject_walk_armless_18musc.osim";
  if (!fs::exists(model)) GTEST_SKIP() << "shared OpenSim data not found: " << model;
  SimulationModelOptions mo;
  mo.muscle_mass.source = osim::MuscleMassOptions::Source::Physiological;
  mo.muscle_mass.muscles = "glut_max2_.*";
  mo.muscle_mass.wrap_mass = true;
  mo.muscle_mass.wrap.model = WrapModel::Smooth;
  const SimulationModel m = loadSimulationModel(model, mo);
  ASSERT_GT(m.muscle_mass, 0.1);
  osim::Storage init;
  init.labels = {"hip_flexion_r", "hip_flexion_r_u", "hip_flexion_l", "hip_flexion_l_u",
                 "knee_angle_r",  "knee_angle_r_u",  "knee_angle_l",  "knee_angle_l_u"};
  init.time = {0.0};
  init.data.resize(1, 8);
  init.data << 0.3, -3.0, -0.2, 3.0, -0.6, 6.0, -0.3, -5.0;
  const State s0 = initialStateFromStorage(m, init, "init");
  SimulateOptions o;
  o.integrator = "rk45";
  o.integrator_options.rtol = 1e-8;
  o.integrator_options.atol = 1e-8;
  o.duration = 0.5;
  const SimulationResult r = simulate(m, s0, o);
  ASSERT_FALSE(r.failed) << r.failure;
  EXPECT_NEAR(r.states.time.back(), 0.5, 1e-12);
  EXPECT_TRUE(r.final_state.q.allFinite() && r.final_state.qdot.allFinite());
  std::printf("[ measured ] free swing with glut_max2 mass: %ld steps, energy drift %.3e relative\n",
              static_cast<long>(r.stats.steps), r.energy_drift_rel);
}

}  // namespace
