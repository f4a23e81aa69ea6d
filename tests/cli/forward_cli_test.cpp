// `redmax forward` and `redmax simulate --controls` end to end: a ForwardTool setup on the
// double pendulum with CoordinateActuators driven by a ControlSet (states and controls written
// under OpenSim 4 names, results_directory and --out-dir), and bad input (exit 2, an `error:` line
// naming the file, nothing written).
#include <gtest/gtest.h>
#include <unistd.h>

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

}  // namespace
