// `redmax simulate` end to end: states written as OpenSim reads them, energy through the command
// (with and without the muscles' quadratic velocity vector), restart from a written row, bad input
// (exit 2, a clear message, nothing written) and divergence (exit 1, time, coordinate and step named,
// nothing written).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "converter/storage.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;

namespace fs = std::filesystem;
using redmax::osim::readStorage;
using redmax::osim::Storage;

class SimulateCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_simulate_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  CmdResult run(const std::string& args) const {
    return runRedmax(dir_, "simulate " + args);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(SimulateCli, WritesOpenSimStatesWithEnergiesAndASummary) {
  const CmdResult r = run("--model " + scene("double_pendulum_via.osim") +
                          " --duration 2 --integrator rk45 --rtol 1e-11 --atol 1e-12 --full-precision --out " +
                          path("s.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage s = readStorage(path("s.sto"));
  EXPECT_FALSE(s.in_degrees);
  ASSERT_EQ(s.numRows(), 201);
  EXPECT_EQ(s.labels, (std::vector<std::string>{"/jointset/pin1/q1/value", "/jointset/pin2/q2/value",
                                                "/jointset/pin1/q1/speed", "/jointset/pin2/q2/speed",
                                                "kinetic_energy", "potential_energy", "total_energy"}));
  EXPECT_NEAR(s.data(0, 0), M_PI / 4, 1e-15);  // the default pose, from rest
  EXPECT_EQ(s.data(0, 2), 0.0);
  const double drift = energyDrift(s);
  EXPECT_LE(drift, 1e-10);  // measured 1.0e-11
  std::printf("[ measured ] double_pendulum_via lumped, rk45 1e-11, 2 s: energy drift %.3g\n", drift);
  // total = kinetic + potential in every row
  EXPECT_LE((s.data.col(6) - s.data.col(4) - s.data.col(5)).cwiseAbs().maxCoeff(), 1e-12);
  for (const char* word : {"steps", "rhs evaluations", "wall", "drift"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << "\n" << r.out;
}

TEST_F(SimulateCli, MuscleQuadraticVelocityVectorKeepsEnergy) {
  // [D 6.2.4, Fig. 6.6a-b] through the command: 1 kg in the straight muscle's mass points, 10 s
  const std::string base = "--model " + scene("double_pendulum_straight.osim") +
                           " --integrator rk45 --rtol 1e-11 --atol 1e-12 --full-precision --muscle-mass-kg straight_muscle=1 --quiet";
  CmdResult r = run(base + " --duration 10 --out " + path("qvv.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  const double qvv = energyDrift(readStorage(path("qvv.sto")));
  EXPECT_LE(qvv, 1e-10);  // measured 1.3e-11
  r = run(base + " --duration 10 --no-qvv --out " + path("noqvv.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  const double noqvv = energyDrift(readStorage(path("noqvv.sto")));
  EXPECT_GE(noqvv, 1e-3);
  std::printf("[ measured ] double_pendulum_straight, 1 kg muscle, rk45 1e-11, 10 s: energy drift %.3g with the QVV, "
              "%.3g without\n", qvv, noqvv);
}

TEST_F(SimulateCli, PhysiologicalMuscleMassMovesMassAndKeepsEnergy) {
  // mass taken from the bones into the straight muscle (density * F / tension * l_opt, 0.08 kg at
  // 200 kg/m^3; the default density would leave link1 with a non-physical inertia): the run
  // reports it and still conserves energy with tight rk45
  const CmdResult r = run("--model " + scene("double_pendulum_straight.osim") +
                          " --muscle-mass physiological --muscle-density 200 --duration 2 --integrator rk45 --rtol 1e-11 --atol 1e-12"
                          " --full-precision --out " + path("phys.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE((r.out + r.err).find("straight_muscle"), std::string::npos) << r.out << r.err;
  const double drift = energyDrift(readStorage(path("phys.sto")));
  EXPECT_LE(drift, 1e-10);  // measured 6.8e-12
  std::printf("[ measured ] double_pendulum_straight, physiological mass, rk45 1e-11, 2 s: energy drift %.3g\n", drift);
}

TEST_F(SimulateCli, RestartFromAWrittenRowReproducesTheRun) {
  const std::string base = "--model " + scene("double_pendulum_via.osim") +
                           " --integrator euler --dt 0.001 --muscle-mass-kg via_muscle=0.5 --full-precision --quiet";
  ASSERT_EQ(run(base + " --duration 2 --out " + path("full.sto")).code, 0);
  const CmdResult r = run(base + " --duration 1 --initial " + path("full.sto") + " --initial-time 1 --out " +
                          path("rest.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage full = readStorage(path("full.sto")), rest = readStorage(path("rest.sto"));
  ASSERT_EQ(rest.numRows(), 101);
  for (int k = 0; k < rest.numRows(); ++k) {
    EXPECT_NEAR(rest.time[k], full.time[100 + k], 1e-12);
    EXPECT_LE((rest.data.row(k) - full.data.row(100 + k)).cwiseAbs().maxCoeff(), 1e-10) << k;
  }
}

TEST_F(SimulateCli, ProgressGoesToStderrOnlyWhenAsked) {
  const std::string base = "--model " + scene("double_pendulum_via.osim") + " --duration 0.5 --out " + path("p.sto");
  CmdResult r = run(base + " --progress");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("simulate (ms simulated): 500/500"), std::string::npos) << r.err;
  r = run(base + " --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out, "");
}

TEST_F(SimulateCli, EveryIntegratorRuns) {
  for (const char* integ : {"euler", "symplectic", "bdf1", "sdirk2", "rk45", "cvode"}) {
    const CmdResult r = run("--model " + scene("double_pendulum_via.osim") + " --duration 0.2 --integrator " +
                            integ + " --out " + path(std::string(integ) + ".sto"));
    EXPECT_EQ(r.code, 0) << integ << ": " << r.err;
    const Storage s = readStorage(path(std::string(integ) + ".sto"));
    EXPECT_EQ(s.numRows(), 21) << integ;
    EXPECT_TRUE(s.data.allFinite()) << integ;
    EXPECT_LT(s.data(20, 0), s.data(0, 0)) << integ;  // released from 45 degrees it swings down
  }
}

TEST_F(SimulateCli, BadInputExitsTwoWithAClearMessageAndWritesNothing) {
  const std::string model = "--model " + scene("double_pendulum_via.osim");
  const std::string out = " --out " + path("never.sto");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--duration 1" + out, "needs --model"},
      {model + out, "needs --duration"},
      {model + " --duration 1", "needs --out"},
      {model + " --duration -1" + out, "--duration must be positive"},
      {model + " --duration x" + out, "expects a number"},
      {model + " --duration 1 --integrator rk4" + out, "--integrator must be"},
      {model + " --duration 1 --dt 0" + out, "--dt must be positive"},
      {model + " --duration 1 --wrap smooth" + out, "--wrap needs muscle mass"},
      {model + " --duration 1 --muscle-mass-kg via_muscle=1 --wrap bogus" + out, "--wrap must be"},
      {model + " --duration 1 --bogus" + out, "unknown option --bogus"},
      {model + " --duration 1 --muscle-mass-kg nobody=1" + out, "no muscle 'nobody'"},
      {model + " --duration 1 --muscle-mass-kg via_muscle=-1" + out, "KG >= 0"},
      {model + " --duration 1 --muscle-mass-kg via_muscle=1 --muscle-mass physiological" + out, "excludes"},
      {model + " --duration 1 --muscles via.*" + out, "--muscles needs --muscle-mass"},
      {model + " --duration 1 --muscle-mass heavy" + out, "heavy"},
      {model + " --duration 1 --impulse link2:1,2:0.1" + out, "FX,FY,FZ"},
      {model + " --duration 1 --impulse nobody:1,2,3:0.1" + out, "'nobody' is not a moving body"},
      {model + " --duration 1 --initial " + path("missing.sto") + out, "missing.sto"},
      {model + " --duration 1 --initial-time 1" + out, "--initial-time needs --initial"},
      {"--model " + path("missing.osim") + " --duration 1" + out, "missing.osim"},
      {model + " --duration 1 --prescribed-forces " + path("f.sto") + out, "--prescribed-forces needs --prescribe"},
      {model + " --duration 1 --prescribe-coordinates q1" + out, "--prescribe-coordinates needs --prescribe"},
      {model + " --duration 1 --prescribe " + path("missing.mot") + out, "missing.mot"},
      {model + " --duration 1 --engine simbody --prescribe " + path("q.mot") + out, "--prescribe needs --engine core"},
  };
  for (const auto& [args, message] : cases) {
    const CmdResult r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(path("never.sto")));
  // an initial-state table without a single matching column names the file
  std::ofstream(path("bad.sto")) << "bad\nversion=1\nnRows=1\nnColumns=2\ninDegrees=no\nendheader\ntime\tfoo\n0\t1\n";
  const CmdResult r = run(model + " --duration 1 --initial " + path("bad.sto") + out);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("bad.sto"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("never.sto")));
}

TEST_F(SimulateCli, PrescribedMotionWritesTheForcesItTakes) {
  // q1 follows a sine (the pendulum's hinge driven), q2 swings; the run may not outlast the motion
  std::ostringstream mot;
  mot << "drive\nversion=1\nnRows=101\nnColumns=2\ninDegrees=no\nendheader\ntime\tq1\n";
  for (int k = 0; k <= 100; ++k) mot << 0.01 * k << "\t" << 0.5 * std::sin(2.0 * 0.01 * k) << "\n";
  std::ofstream(path("q.mot")) << mot.str();
  const std::string base = "--model " + scene("double_pendulum_via.osim") + " --prescribe " + path("q.mot") +
                           " --rtol 1e-10 --atol 1e-10 --full-precision --prescribed-forces " + path("f.sto");
  CmdResult r = run(base + " --duration 1 --out " + path("s.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("prescribed from"), std::string::npos) << r.out;
  const Storage s = readStorage(path("s.sto")), f = readStorage(path("f.sto"));
  EXPECT_EQ(f.labels, (std::vector<std::string>{"q1_moment"}));
  ASSERT_EQ(f.numRows(), s.numRows());
  for (int row = 0; row < s.numRows(); ++row) EXPECT_NEAR(s.data(row, 0), 0.5 * std::sin(2.0 * s.time[row]), 1e-4);
  EXPECT_GT(s.data.col(1).cwiseAbs().maxCoeff(), 0.1);  // q2 moves forward
  // past the motion's last time: bad input, nothing written
  fs::remove(path("s.sto"));
  fs::remove(path("f.sto"));
  r = run(base + " --duration 1.5 --out " + path("s.sto"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("outside the motion's [0, 1] s"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("s.sto")));
  EXPECT_FALSE(fs::exists(path("f.sto")));
}

TEST_F(SimulateCli, DivergenceExitsOneNamingTimeCoordinateAndStepAndWritesNothing) {
  // a 2 kN flick on the light finger with explicit 1 ms steps: the distal joint spins up until the
  // velocity-product terms blow the state up
  const CmdResult r = run("--model " + scene("finger.osim") +
                          " --duration 1 --integrator euler --dt 0.001 --impulse fingertip:0,2000,0:0.002 --out " +
                          path("never.sto"));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" at t = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("coordinate '"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("step h = 0.001"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("never.sto")));
}

}  // namespace
