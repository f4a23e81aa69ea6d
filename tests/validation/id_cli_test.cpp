// `redmax id` end to end: a project-authored double pendulum with a closed-form motion (runs
// everywhere), the setup-file route, both engines, OpenSim's output format, and bad input (exit 2,
// `error: FILE[:LINE]: ...`, no output written). Set E through the command line when ../shared
// is present. Correctness only; timings are never asserted.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "converter/storage.hpp"
#include "tests/validation/pendulum_cli_fixture.hpp"

namespace {

namespace fs = std::filesystem;

using namespace redmax_test;

class IdCli : public PendulumCliTest {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to validation_tests (build target redmax)";
    makeDir("redmax_id_cli_");
  }

  // closed-form torques of the pendulum above (Lagrange; link inertia Izz 0.05 about the COM)
  static Eigen::Vector2d tau(double t) { return closedFormTau(t); }

};

TEST_F(IdCli, WritesOpenSimStyleResultsMatchingTheClosedForm) {
  const CmdResult r = run("id --model dp.osim --coordinates dp.mot --t0 0.5 --t1 1.5 --full-precision --out res/id.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("id: 501 frames"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frames/s"), std::string::npos) << r.out;
  const std::string text = slurp(dir_ / "res/id.sto");
  EXPECT_EQ(text.rfind("Inverse Dynamics Generalized Forces\nversion=1\n", 0), 0u) << text.substr(0, 200);
  EXPECT_NE(text.find("inDegrees=no"), std::string::npos);
  const redmax::osim::Storage s = redmax::osim::readStorage((dir_ / "res/id.sto").string());
  ASSERT_EQ(s.labels, (std::vector<std::string>{"q1_moment", "q2_moment"}));
  double worst = 0, peak = 0;
  for (int k = 0; k < s.numRows(); ++k) {
    const Eigen::Vector2d ref = tau(s.time[k]);
    worst = std::max(worst, (s.data.row(k).transpose() - ref).cwiseAbs().maxCoeff());
    peak = std::max(peak, ref.cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-9 * peak);  // measured 5.7e-11 (quintic interpolation of the sampled motion)
  std::printf("[ measured ] redmax id on the double pendulum: worst error / peak = %.3g\n", worst / peak);

  // the Simbody engine on the same inputs
  const CmdResult rs = run("id --model dp.osim --coordinates dp.mot --t0 0.5 --t1 1.5 --engine simbody "
                           "--full-precision --quiet --out sim.sto");
  ASSERT_EQ(rs.code, 0) << rs.err;
  EXPECT_TRUE(rs.out.empty());
  const redmax::osim::Storage b = redmax::osim::readStorage((dir_ / "sim.sto").string());
  ASSERT_EQ(b.numRows(), s.numRows());
  EXPECT_LE((b.data - s.data).cwiseAbs().maxCoeff(), 1e-9 * peak);
}

TEST_F(IdCli, SetupFileWithFlagOverrides) {
  write("setup/id_setup.xml",
        "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\"><InverseDynamicsTool name=\"dp\">\n"
        "<results_directory>results</results_directory><model_file>../dp.osim</model_file>\n"
        "<coordinates_file>../dp.mot</coordinates_file><time_range>0 2</time_range>\n"
        "<lowpass_cutoff_frequency_for_coordinates>6</lowpass_cutoff_frequency_for_coordinates>\n"
        "<forces_to_exclude>Muscles</forces_to_exclude><output_gen_force_file>dp_id.sto</output_gen_force_file>\n"
        "</InverseDynamicsTool></OpenSimDocument>\n");
  const CmdResult r = run("id --setup setup/id_setup.xml --t0 1 --t1 1.2");
  ASSERT_EQ(r.code, 0) << r.err;
  const redmax::osim::Storage s = redmax::osim::readStorage((dir_ / "setup/results/dp_id.sto").string());
  // filtered: the grid is the padded one; rows from the last sample at or before 1 s
  ASSERT_GT(s.numRows(), 50);
  EXPECT_LE(s.time.front(), 1.0);
  EXPECT_GT(s.time.front(), 1.0 - 0.002 - 1e-9);
  EXPECT_LE(s.time.back(), 1.2);
}

TEST_F(IdCli, BadInputExitsWithTwoAndNamesTheFile) {
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"id --model missing.osim --coordinates dp.mot --out o.sto", "error: missing.osim"},
      {"id --model dp.osim --coordinates missing.mot --out o.sto", "error: missing.mot"},
      {"id --model dp.osim --coordinates dp.mot --external-loads none.xml --out o.sto", "error: none.xml"},
      {"id --model dp.osim --coordinates other.mot --out o.sto", "error: other.mot"},
      {"id --model dp.osim --coordinates dp.mot --bogus --out o.sto", "unknown option --bogus"},
      {"id --model dp.osim --coordinates dp.mot --engine warp --out o.sto", "--engine must be core or simbody"},
      {"id --model dp.osim --coordinates dp.mot --lowpass six --out o.sto", "--lowpass expects a number"},
      {"id --model dp.osim --coordinates dp.mot --t0 2 --t1 1 --out o.sto", "--t0 is after --t1"},
      {"id --model dp.osim --coordinates dp.mot", "no output file"},
      {"id --model dp.osim --out o.sto", "needs --setup"},
      {"id --model dp.osim --coordinates dp.mot --exact --opensim-compat --out o.sto", "exclude each other"},
      {"id --model dp.osim --coordinates dp.mot --muscle-mass heavy --out o.sto", "--muscle-mass must be none"},
      {"id --setup nosetup.xml --out o.sto", "error: nosetup.xml"},
  };
  write("other.mot", "x\nversion=1\nnRows=2\nnColumns=2\ninDegrees=no\nendheader\ntime\tfoo\n0\t1\n1\t2\n");
  for (const Case& c : cases) {
    const CmdResult r = run(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << "\nstderr: " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "o.sto")) << c.args;
  }
  // a malformed model names its line
  write("bad.osim", "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<Model name=\"x\">\n"
                    "<BodySet><objects><Body name=\"a\"><mass>abc</mass></Body></objects></BodySet>\n"
                    "</Model></OpenSimDocument>\n");
  const CmdResult r = run("id --model bad.osim --coordinates dp.mot --out o.sto");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("error: bad.osim:"), std::string::npos) << r.err;
}

TEST_F(IdCli, GimbalLockOfABallJointIsARunFailure) {
  // OpenSim-compatible mode reads a ball joint's Euler rates as angular velocity; the core maps
  // them back to rates, which is impossible at gimbal lock (middle angle 90 degrees): exit 1 with
  // the joint and time named. Exact mode needs no such map.
  write("ball.osim",
        "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\"><Model name=\"b\"><Ground name=\"ground\"/>\n"
        "<BodySet><objects><Body name=\"a\"><mass>1</mass><mass_center>0 -0.2 0</mass_center>"
        "<inertia>0.1 0.1 0.1 0 0 0</inertia></Body></objects></BodySet>\n<JointSet><objects>"
        "<BallJoint name=\"ball\"><socket_parent_frame>/ground</socket_parent_frame><socket_child_frame>"
        "/bodyset/a</socket_child_frame><coordinates><Coordinate name=\"b1\"/><Coordinate name=\"b2\"/>"
        "<Coordinate name=\"b3\"/></coordinates></BallJoint></objects></JointSet>\n</Model></OpenSimDocument>\n");
  std::ostringstream os;
  os << "m\nversion=1\nnRows=11\nnColumns=4\ninDegrees=yes\nendheader\ntime\tb1\tb2\tb3\n";
  for (int i = 0; i <= 10; ++i) os << 0.1 * i << "\t" << 10.0 * i << "\t90\t" << -5.0 * i << "\n";
  write("ball.mot", os.str());
  const CmdResult r = run("id --model ball.osim --coordinates ball.mot --out ball.sto");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("gimbal lock"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ball"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "ball.sto"));
  const CmdResult e = run("id --model ball.osim --coordinates ball.mot --exact --out ball.sto");
  EXPECT_EQ(e.code, 0) << e.err;
}

TEST_F(IdCli, SetEMatchesOpenSim46ThroughTheCommandLine) {
  const std::string sh = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  const std::string e = sh + "opensim-models/Pipelines/Gait2392_Simbody/";
  const std::string model = sh + "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim";
  if (!fs::exists(model) || !fs::exists(sh + "opensim-4.6-results/E.sto"))
    GTEST_SKIP() << "shared OpenSim data not found under " << sh;
  // the setup names the current (2024) model; the 2017 model is given by flag, as docs/shared_data.md's table
  const CmdResult r = run("id --setup " + e + "subject01_Setup_InverseDynamics.xml --model " + model +
                          " --out e.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  const redmax::osim::Storage ours = redmax::osim::readStorage((dir_ / "e.sto").string());
  const redmax::osim::Storage ref = redmax::osim::readStorage(sh + "opensim-4.6-results/E.sto");
  ASSERT_EQ(ours.labels, ref.labels);
  ASSERT_EQ(ours.numRows(), ref.numRows());
  for (int c = 0; c < ref.numColumns(); ++c) {
    const double peak = ref.data.col(c).cwiseAbs().maxCoeff();
    const double rms = std::sqrt((ours.data.col(c) - ref.data.col(c)).squaredNorm() / ref.numRows());
    // both files have 8 decimals: rounding of both is allowed for
    EXPECT_LE(rms, 1e-6 * peak + 1e-8) << ref.labels[c];
  }
}

}  // namespace
