// Muscle-driven `redmax forward` runs end to end, each with the failure it guards against:
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

const std::string kArm26Dir =
    std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-core/Applications/Forward/tests/resources";

class ForwardMusclesCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_forward_muscles_cli_" + std::to_string(::getpid()));
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
  fs::path dir_;
};

TEST_F(ForwardMusclesCli, Arm26FibrePlacementCrossesTriLongsWrapJump) {
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

TEST_F(ForwardMusclesCli, NonFiniteRateStopsTheRunNamingStateAndTime) {
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
