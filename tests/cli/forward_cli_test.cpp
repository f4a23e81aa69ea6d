// `redmax forward` and `redmax simulate --controls` end to end: a ForwardTool setup on the
// double pendulum with CoordinateActuators driven by a ControlSet (states and controls written
// under OpenSim 4 names, results_directory and --out-dir), and bad input (exit 2, an `error:` line
// naming the file, nothing written); force_set_files (PointActuator, TorqueActuator,
// CoordinateLimitForce, PointToPointSpring), replace_force_set and external_loads_file.
//
// Muscle-driven runs, each with the failure it guards against:
//   - arm26 (OpenSim's ForwardTool setup, Thelen2003Muscle_Deprecated) with 30% of r_humerus's
//     mass moved into the muscles, fibre-following placement: it used to stop at t = 0.242 s with
//     a NaN rate of TRIlong's fibre length. The cause (docs/forward.md §5): TRIlong's wrapped
//     length is 8.5 mm longer in a 1.3 mrad band of shoulder elevation (OpenSim's WrapCylinder
//     TRIlongglen, r 3 mm, quadrant x, wraps a 25.8 mm helical arc only there), which only this
//     run's shoulder reaches; an rk45 trial stage across that jump at activation 0.01 sent the
//     fibre to -5.5 m, where the Deprecated force-velocity secant was 0/0;
//   - a non-finite rate stops the run, names the state and the time, exits 1 and writes nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "converter/storage.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;
namespace fs = std::filesystem;
using redmax::osim::readStorage;
using redmax::osim::Storage;

const std::string kPendulum = std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-models/Models/DoublePendulum/double_pendulum.osim";

const std::string kArm26Dir =
    std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-core/Applications/Forward/tests/resources";

class ForwardCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    if (!fs::exists(kPendulum)) GTEST_SKIP() << "shared OpenSim data not found: " << kPendulum;
    dir_ = fs::temp_directory_path() / ("redmax_forward_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  // a setup beside its files (paths relative to it)
  std::string setup(const std::string& extra, const std::string& controls = "controls.xml",
                    const std::string& name = "setup.xml") const {
    return write(name, "<OpenSimDocument Version=\"40000\">\n<ForwardTool name=\"pend\">\n"
                              "<model_file>" + kPendulum + "</model_file>\n"
                              "<results_directory>res</results_directory>\n"
                              "<initial_time>0</initial_time>\n<final_time>0.2</final_time>\n"
                              "<ControllerSet><objects><ControlSetController name=\"c\">\n"
                              "<controls_file>" + controls + "</controls_file>\n"
                              "</ControlSetController></objects></ControllerSet>\n" + extra +
                              "</ForwardTool>\n</OpenSimDocument>\n");
  }
  void writeControls() const {
    write("controls.xml", "<ControlSet><objects>\n"
                          "<ControlLinear name=\"Torq1.excitation\"><x_nodes>\n"
                          "<ControlLinearNode><t>0</t><value>2</value></ControlLinearNode>\n"
                          "<ControlLinearNode><t>1</t><value>0</value></ControlLinearNode>\n"
                          "</x_nodes></ControlLinear>\n"
                          "<ControlLinear name=\"Torq2\"><x_nodes>\n"
                          "<ControlLinearNode><t>0</t><value>-1</value></ControlLinearNode>\n"
                          "</x_nodes></ControlLinear>\n"
                          "</objects></ControlSet>\n");
  }
  fs::path dir_;
};

TEST_F(ForwardCli, WritesStatesAndControlsUnderOpenSimNames) {
  writeControls();
  const std::string s = setup("");
  const CmdResult r = runRedmax(dir_, "forward --setup " + s + " --report-interval 0.05");
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage st = readStorage((dir_ / "res" / "pend_states.sto").string());
  ASSERT_EQ(st.numRows(), 5);
  EXPECT_EQ(st.labels[0].rfind("/jointset/", 0), 0u);
  EXPECT_NE(st.findColumn(st.labels[0].substr(0, st.labels[0].size() - 6) + "/speed"), -1);
  const Storage c = readStorage((dir_ / "res" / "pend_controls.sto").string());
  ASSERT_EQ(c.labels, (std::vector<std::string>{"Torq1", "Torq2"}));
  EXPECT_NEAR(c.data(2, 0), 2.0 * (1 - 0.1), 1e-12);  // linear between the nodes, t = 0.1
  EXPECT_NEAR(c.data(2, 1), -1.0, 1e-12);
  // --out-dir replaces results_directory
  const CmdResult r2 = runRedmax(dir_, "forward --quiet --setup " + s + " --out-dir " + (dir_ / "other").string());
  ASSERT_EQ(r2.code, 0) << r2.err;
  EXPECT_TRUE(fs::exists(dir_ / "other" / "pend_states.sto"));
  // simulate --controls: the same controls drive the same model; the end state agrees
  const CmdResult r3 = runRedmax(dir_, "simulate --quiet --model " + kPendulum + " --controls " +
                                           (dir_ / "controls.xml").string() +
                                           " --duration 0.2 --rtol 1e-5 --atol 1e-5 --full-precision --out " +
                                           (dir_ / "sim.sto").string());
  ASSERT_EQ(r3.code, 0) << r3.err;
  const Storage sim = readStorage((dir_ / "sim.sto").string());
  for (int j = 0; j < 4; ++j)
    EXPECT_NEAR(sim.data(sim.numRows() - 1, j), st.data(st.numRows() - 1, j), 1e-3) << st.labels[j];
}

TEST_F(ForwardCli, BadInputExitsTwoAndWritesNothing) {
  writeControls();
  struct Case {
    const char* what;
    std::string args;
    std::string expect;  // in the error line
  };
  const Case cases[] = {
      {"no setup flag", "forward", "--setup"},
      {"missing setup", "forward --setup " + (dir_ / "nope.xml").string(), "nope.xml"},
      {"malformed setup", "forward --setup " + write("m.xml", "<ForwardTool name=\"x\"><final_time>"), "m.xml"},
      {"missing controls", "forward --setup " + setup("", "absent.xml", "s1.xml"), "absent.xml"},
      {"bad controls", "forward --setup " + (write("bc.xml", "<ControlSet><objects><ControlLinear name=\"Torq1\"><x_nodes>"
                                                             "<ControlLinearNode><t>x</t><value>1</value></ControlLinearNode>"
                                                             "</x_nodes></ControlLinear></objects></ControlSet>"),
                                             setup("", "bc.xml", "s2.xml")),
       "bc.xml:1:"},
      {"bad states", "forward --setup " + (write("st.sto", "garbage\n1 2 3\n"), setup("<states_file>st.sto</states_file>\n", "controls.xml", "s3.xml")),
       "st.sto"},
      {"bad report interval", "forward --setup " + setup("", "controls.xml", "s4.xml") + " --report-interval -1",
       "--report-interval"},
      {"simulate bad controls", "simulate --model " + kPendulum + " --duration 0.1 --controls " +
                                    (dir_ / "bc.xml").string() + " --out " + (dir_ / "x.sto").string(),
       "bc.xml:1:"},
  };
  for (const Case& c : cases) {
    fs::remove_all(dir_ / "res");
    const CmdResult r = runRedmax(dir_, c.args);
    EXPECT_EQ(r.code, 2) << c.what << ": " << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << c.what << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.what << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "res")) << c.what;
    EXPECT_FALSE(fs::exists(dir_ / "x.sto")) << c.what;
  }
}

// a ForceSet file for the double pendulum (rod1, rod2; q1, q2)
std::string forceSet(const std::string& objects) {
  return "<OpenSimDocument Version=\"40000\">\n<ForceSet name=\"extra\">\n<objects>\n" + objects +
         "</objects>\n</ForceSet>\n</OpenSimDocument>\n";
}

const char* kPushActuator =
    "<PointActuator name=\"push\">\n<body>rod2</body>\n<point>0 0.1 0</point>\n<point_is_global>false</point_is_global>\n"
    "<direction>3 0 4</direction>\n<force_is_global>true</force_is_global>\n<optimal_force>5</optimal_force>\n"
    "</PointActuator>\n";

// An external load and a PointActuator that apply the same force give the same motion: the
// ExternalLoads path (sampled in time) and force_set_files' PointActuator check each other.
TEST_F(ForwardCli, ForceSetPointActuatorEqualsTheSameExternalLoad) {
  write("push.xml", "<ControlSet><objects><ControlLinear name=\"push\"><x_nodes>\n"
                    "<ControlLinearNode><t>0</t><value>1</value></ControlLinearNode>\n"
                    "<ControlLinearNode><t>1</t><value>1</value></ControlLinearNode>\n"
                    "</x_nodes></ControlLinear></objects></ControlSet>\n");
  write("fs.xml", forceSet(kPushActuator));
  // F = 5 (0.6, 0, 0.8) N, in ground, at rod2's station (0, 0.1, 0), every time
  write("grf.mot", "grf\nversion=1\nnRows=2\nnColumns=7\ninDegrees=no\nendheader\n"
                   "time\tf_vx\tf_vy\tf_vz\tp_px\tp_py\tp_pz\n"
                   "0\t3\t0\t4\t0\t0.1\t0\n1\t3\t0\t4\t0\t0.1\t0\n");
  write("loads.xml", "<OpenSimDocument Version=\"40000\"><ExternalLoads name=\"l\"><objects>\n"
                     "<ExternalForce name=\"f\"><applied_to_body>rod2</applied_to_body>\n"
                     "<force_expressed_in_body>ground</force_expressed_in_body>\n"
                     "<point_expressed_in_body>rod2</point_expressed_in_body>\n"
                     "<force_identifier>f_v</force_identifier><point_identifier>p_p</point_identifier>\n"
                     "</ExternalForce></objects><datafile>grf.mot</datafile></ExternalLoads></OpenSimDocument>\n");
  const std::string with_actuator = setup("<force_set_files>fs.xml</force_set_files>\n", "push.xml", "a.xml");
  const std::string with_loads = setup("<external_loads_file>loads.xml</external_loads_file>\n", "push.xml", "b.xml");
  ASSERT_EQ(runRedmax(dir_, "forward --quiet --setup " + with_actuator + " --out-dir " + (dir_ / "a").string()).code, 0);
  const CmdResult rb = runRedmax(dir_, "forward --setup " + with_loads + " --out-dir " + (dir_ / "b").string());
  ASSERT_EQ(rb.code, 0) << rb.err;
  const Storage a = readStorage((dir_ / "a" / "pend_states.sto").string());
  const Storage b = readStorage((dir_ / "b" / "pend_states.sto").string());
  const Storage c = readStorage((dir_ / "a" / "pend_controls.sto").string());
  EXPECT_EQ(c.labels, (std::vector<std::string>{"Torq1", "Torq2", "push"}));
  ASSERT_EQ(a.numRows(), b.numRows());
  double worst = 0.0;
  for (int r = 0; r < a.numRows(); ++r)
    for (int j = 0; j < 4; ++j) worst = std::max(worst, std::abs(a.data(r, j) - b.data(r, j)));
  std::printf("external load vs PointActuator: worst state difference %.3g\n", worst);
  // measured 0 in the written states (%.8e): allow a few units of their last digit
  EXPECT_LT(worst, 5e-8);
  // and the force does something: the run without it differs
  ASSERT_EQ(runRedmax(dir_, "forward --quiet --setup " + setup("", "push.xml", "c.xml") + " --out-dir " + (dir_ / "c").string()).code, 0);
  const Storage n = readStorage((dir_ / "c" / "pend_states.sto").string());
  EXPECT_GT(std::abs(n.data(n.numRows() - 1, 0) - a.data(a.numRows() - 1, 0)), 1e-3);
}

TEST_F(ForwardCli, ReplaceForceSetKeepsOnlyTheFilesForces) {
  writeControls();
  write("fs.xml", forceSet(std::string(kPushActuator) +
                           "<TorqueActuator name=\"twist\"><bodyA>rod1</bodyA><bodyB>ground</bodyB>\n"
                           "<axis>0 0 1</axis><torque_is_global>true</torque_is_global><optimal_force>2</optimal_force></TorqueActuator>\n"
                           "<CoordinateLimitForce name=\"lim\"><coordinate>q2</coordinate><upper_stiffness>1</upper_stiffness>\n"
                           "<upper_limit>10</upper_limit><lower_stiffness>1</lower_stiffness><lower_limit>-10</lower_limit>\n"
                           "<damping>0.01</damping><transition>5</transition></CoordinateLimitForce>\n"
                           "<PointToPointSpring name=\"spr\"><socket_body1>/ground</socket_body1><socket_body2>/bodyset/rod2</socket_body2>\n"
                           "<point1>0 0 0</point1><point2>0 0 0</point2><stiffness>10</stiffness><rest_length>0.5</rest_length></PointToPointSpring>\n"));
  const std::string s = setup("<replace_force_set>true</replace_force_set>\n<force_set_files>fs.xml</force_set_files>\n");
  const CmdResult r = runRedmax(dir_, "forward --setup " + s);
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage c = readStorage((dir_ / "res" / "pend_controls.sto").string());
  EXPECT_EQ(c.labels, (std::vector<std::string>{"push", "twist"}));
  // the controls file's Torq1, Torq2 drive nothing now: named
  EXPECT_NE(r.err.find("Torq1"), std::string::npos) << r.err;
}

TEST_F(ForwardCli, BadForceSetFilesExitTwoWithFileAndLine) {
  writeControls();
  struct Case {
    const char* what;
    std::string objects;
    std::string expect;
  };
  const Case cases[] = {
      {"unknown body", "<PointActuator name=\"p\">\n<body>femur</body>\n</PointActuator>\n", "bad.xml:5:"},
      {"zero direction", "<PointActuator name=\"p\"><body>rod1</body>\n<direction>0 0 0</direction>\n</PointActuator>\n",
       "bad.xml:5:"},
      {"zero axis", "<TorqueActuator name=\"t\"><bodyA>rod1</bodyA><bodyB>ground</bodyB>\n<axis>0 0 0</axis>\n</TorqueActuator>\n",
       "bad.xml:5:"},
      {"unknown torque body", "<TorqueActuator name=\"t\">\n<bodyA>nope</bodyA><bodyB>ground</bodyB></TorqueActuator>\n",
       "bad.xml:5:"},
      {"negative stiffness", "<CoordinateLimitForce name=\"l\"><coordinate>q2</coordinate>\n<upper_stiffness>-3</upper_stiffness>\n"
                             "</CoordinateLimitForce>\n", "bad.xml:5:"},
      {"unknown coordinate", "<SpringGeneralizedForce name=\"g\">\n<coordinate>q9</coordinate></SpringGeneralizedForce>\n",
       "bad.xml:5:"},
      {"spring on one body", "<PointToPointSpring name=\"s\"><socket_body1>/bodyset/rod1</socket_body1>\n"
                             "<socket_body2>/bodyset/rod1</socket_body2></PointToPointSpring>\n", "bad.xml:4:"},
  };
  for (const Case& c : cases) {
    write("bad.xml", forceSet(c.objects));
    fs::remove_all(dir_ / "res");
    const CmdResult r = runRedmax(dir_, "forward --setup " + setup("<force_set_files>bad.xml</force_set_files>\n", "controls.xml", "sb.xml"));
    EXPECT_EQ(r.code, 2) << c.what << ": " << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << c.what << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.what << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "res")) << c.what;
  }
  // a force_set_files file that does not exist
  const CmdResult r = runRedmax(dir_, "forward --setup " + setup("<force_set_files>absent_fs.xml</force_set_files>\n", "controls.xml", "sm.xml"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("absent_fs.xml"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "res"));
}

TEST_F(ForwardCli, Arm26FibrePlacementCrossesTriLongsWrapJump) {
  if (!fs::exists(kArm26Dir + "/arm26_Setup_Forward.xml")) GTEST_SKIP() << "shared OpenSim data not found: " << kArm26Dir;
  const CmdResult r = runRedmax(dir_, "forward --setup " + kArm26Dir +
                                          "/arm26_Setup_Forward.xml --muscle-class Thelen2003Muscle_Deprecated "
                                          "--muscle-mass transfer --transfer-body r_humerus --transfer-fraction 0.3 "
                                          "--mass-placement fibre --report-interval 0.0005 --out-dir " +
                                          (dir_ / "out").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage st = readStorage((dir_ / "out" / "arm26_states.sto").string());
  ASSERT_EQ(st.numRows(), 2001);
  const int sh = st.findColumn("/jointset/r_shoulder/r_shoulder_elev/value");
  const int lf = st.findColumn("/forceset/TRIlong/fiber_length");
  ASSERT_GE(sh, 0);
  ASSERT_GE(lf, 0);
  // the run crosses the band [-0.2897, -0.2883] rad (measured minimum -0.3012 rad), where the
  // 8.5 mm longer path stretches TRIlong's slack-activated fibre by up to 8 mm (measured 8.3 mm)
  double sh_min = 0, lf_rise = 0;
  for (int k = 0; k < st.numRows(); ++k) {
    for (int j = 0; j < st.numColumns(); ++j) ASSERT_TRUE(std::isfinite(st.data(k, j))) << st.labels[j];
    sh_min = std::min(sh_min, st.data(k, sh));
    if (k > 0 && st.time[k] > 0.24 && st.time[k] < 0.25) lf_rise = std::max(lf_rise, st.data(k, lf) - st.data(k - 1, lf));
  }
  EXPECT_LT(sh_min, -0.2897);
  EXPECT_GT(lf_rise, 2e-3);  // measured 4.8e-3 m in one 0.5 ms row as the band is entered
}

TEST_F(ForwardCli, NonFiniteRateStopsTheRunNamingStateAndTime) {
  // the left muscle's excitation steps to 1e308 at t = 0.05: its activation rate is infinite
  write("setup.xml", "<OpenSimDocument Version=\"40000\">\n<ForwardTool name=\"tow\">\n"
                     "<model_file>" + scene("tug_of_war_step.osim") + "</model_file>\n"
                     "<results_directory>res</results_directory>\n"
                     "<initial_time>0</initial_time>\n<final_time>0.2</final_time>\n"
                     "<ControllerSet><objects><PrescribedController name=\"step\"><FunctionSet><objects>\n"
                     "<PiecewiseConstantFunction name=\"left_muscle\"><x>0 0.05</x><y>0.05 1e308</y>"
                     "</PiecewiseConstantFunction>\n"
                     "<Constant name=\"right_muscle\"><value>0.05</value></Constant>\n"
                     "</objects></FunctionSet></PrescribedController></objects></ControllerSet>\n"
                     "</ForwardTool>\n</OpenSimDocument>\n");
  for (const std::string integrator : {"rk45", "cvode"}) {
    const CmdResult r = runRedmax(dir_, "forward --setup setup.xml --integrator " + integrator, true);
    EXPECT_EQ(r.code, 1) << integrator << ": " << r.err;
    EXPECT_NE(r.err.find("error: setup.xml: " + integrator + ": step failed"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("non-finite rate of state /forceset/left_muscle/activation = inf at t = 0.0"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "res")) << integrator << ": nothing is written";
  }
}

}  // namespace
