// redmax's ForwardTool and AnalyzeTool against OpenSim's, in one process on the same setup files
// (docs/performance.md §11; built only where OpenSim is installed, like the plugin's tests):
//   - muscle-driven forward runs at tolerance 1e-8, where both integrators have converged: the
//     states agree (gait10dof18musc, Millard: measured 3.4e-9 rad; gait2354, Thelen, past the
//     knee's range where OpenSim's MovingPathPoint force term differs from the length's gradient:
//     2.6e-6 rad);
//   - a ForwardTool's own controls_file in a version-40000 document: ignored by both;
//   - MuscleAnalysis on set F with equilibrium: every file equal to OpenSim's print precision.
#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenSim/Common/Function.h>  // before the tools: ArrayPtrs<Function> needs the complete type
#include <OpenSim/Common/Logger.h>
#include <OpenSim/Tools/AnalyzeTool.h>
#include <OpenSim/Tools/ForwardTool.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "converter/analyze/analyze_tool.hpp"
#include "converter/analyze/setup_writer.hpp"
#include "converter/storage.hpp"
#include "validation/forward/constant_excitation.hpp"
#include "validation/forward/forward_tool.hpp"

namespace {

namespace fs = std::filesystem;

std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }

class SideBySide : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(shared("opensim-models"))) GTEST_SKIP() << "shared OpenSim data not found";
    OpenSim::Logger::setLevel(OpenSim::Logger::Level::Off);
    dir_ = fs::temp_directory_path() / ("redmax_side_by_side_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  // OpenSim resolves a setup's relative paths against the working directory
  struct InDirectory {
    fs::path old = fs::current_path();
    explicit InDirectory(const fs::path& d) { fs::current_path(d); }
    ~InDirectory() { fs::current_path(old); }
  };
  redmax::osim::Storage runOpenSimForward(const std::string& setup, const std::string& name) {
    const fs::path out = dir_ / ("opensim_" + name);
    {
      InDirectory in(fs::path(setup).parent_path());
      OpenSim::ForwardTool tool(setup);
      tool.setResultsDir(out.string());
      EXPECT_TRUE(tool.run());
    }
    return redmax::osim::readStorage((out / (name + "_states.sto")).string());
  }
  // largest |q| difference over the coordinates at the last rows (both at final_time)
  static double lastRowDifference(const redmax::osim::Storage& a, const redmax::osim::Storage& b) {
    EXPECT_NEAR(a.time.back(), b.time.back(), 1e-12);
    double worst = 0.0;
    int compared = 0;
    for (size_t c = 0; c < a.labels.size(); ++c) {
      const std::string& l = a.labels[c];
      if (l.size() < 6 || l.compare(l.size() - 6, 6, "/value") != 0) continue;
      const auto it = std::find(b.labels.begin(), b.labels.end(), l);
      if (it == b.labels.end()) continue;
      const int cb = static_cast<int>(it - b.labels.begin());
      worst = std::max(worst, std::abs(a.data(a.numRows() - 1, c) - b.data(b.numRows() - 1, cb)));
      ++compared;
    }
    EXPECT_GT(compared, 1);
    return worst;
  }
  double forwardDifference(const std::string& model, const std::string& name) {
    const std::string setup =
        redmax::validation::writeConstantExcitationSetup(model, (dir_ / name).string(), name, 0.1, 0.2, 1e-8);
    const redmax::osim::Storage theirs = runOpenSimForward(setup, name);
    redmax::validation::ForwardToolSettings s;
    s.setup_file = setup;
    s.out_dir = (dir_ / ("redmax_" + name)).string();
    const redmax::validation::ForwardTool tool(s);
    const redmax::validation::ForwardResult r = tool.run();
    EXPECT_FALSE(r.failed) << r.failure;
    const double d = lastRowDifference(r.states, theirs);
    std::printf("[ measured ] %s at 1e-8, 0.1 s: max |q - q_OpenSim| at the last row %.2e\n", name.c_str(), d);
    return d;
  }
  fs::path dir_;
};

TEST_F(SideBySide, MillardGaitModelForwardRunEqualsOpenSims) {
  EXPECT_LT(forwardDifference(shared("opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim"),
                              "gait10dof18musc"),
            1e-7);
}

TEST_F(SideBySide, ThelenGaitModelForwardRunEqualsOpenSimsPastTheKneesRange) {
  EXPECT_LT(forwardDifference(shared("opensim-models/Models/Gait2354_Simbody/gait2354_simbody.osim"), "gait2354"), 2e-5);
}

TEST_F(SideBySide, ToolLevelControlsFileOfAModernDocumentIsIgnoredByBoth) {
  const std::string model = shared("opensim-models/Models/DoublePendulum/double_pendulum.osim");
  std::ofstream(dir_ / "c.xml") << "<ControlSet><objects><ControlLinear name=\"Torq2.excitation\"><x_nodes>"
                                   "<ControlLinearNode><t>0</t><value>3</value></ControlLinearNode>"
                                   "<ControlLinearNode><t>1</t><value>3</value></ControlLinearNode>"
                                   "</x_nodes></ControlLinear></objects></ControlSet>";
  const std::string setup = (dir_ / "setup.xml").string();
  std::ofstream(setup) << "<OpenSimDocument Version=\"40000\"><ForwardTool name=\"p\"><model_file>" << model
                       << "</model_file><initial_time>0</initial_time><final_time>0.2</final_time>"
                          "<integrator_error_tolerance>1e-8</integrator_error_tolerance>"
                          "<controls_file>c.xml</controls_file></ForwardTool></OpenSimDocument>";
  const redmax::osim::Storage theirs = runOpenSimForward(setup, "p");
  const redmax::osim::Storage their_controls = redmax::osim::readStorage((dir_ / "opensim_p" / "p_controls.sto").string());
  EXPECT_EQ(their_controls.data.cwiseAbs().maxCoeff(), 0.0);
  redmax::validation::ForwardToolSettings s;
  s.setup_file = setup;
  s.out_dir = (dir_ / "redmax_p").string();
  const redmax::validation::ForwardTool tool(s);
  const redmax::validation::ForwardResult r = tool.run();
  ASSERT_FALSE(r.failed) << r.failure;
  EXPECT_EQ(r.controls.data.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(lastRowDifference(r.states, theirs), 1e-6);
}

TEST_F(SideBySide, MuscleAnalysisOnSetFEqualsOpenSimsToPrintPrecision) {
  redmax::osim::IdToolConfig t;
  const std::string f = "Pipelines/Gait10dof18musc/OutputReference/";
  t.model_file = shared("opensim-models@a26e12c/" + f + "subject01.osim");
  t.coordinates_file = shared("opensim-models/" + f + "IK/subject01_walk_IK.mot");
  t.external_loads_file = shared("opensim-models/" + f + "ExperimentalData/subject01_walk_grf.xml");
  t.lowpass_cutoff_hz = 6.0;
  t.t0 = 0.5;
  t.t1 = 1.0;
  const std::string so = redmax::osim::writeStaticOptimizationSetup(t, {}, (dir_ / "F").string()).setup_file;
  // the same setup with a MuscleAnalysis instead of static optimization, equilibrium on
  std::ifstream in(so);
  std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t a = xml.find("<StaticOptimization"), b = xml.find("</StaticOptimization>");
  ASSERT_NE(a, std::string::npos);
  xml.replace(a, b + 21 - a,
              "<MuscleAnalysis name=\"MuscleAnalysis\"><on>true</on><muscle_list>all</muscle_list>"
              "<moment_arm_coordinate_list>knee_angle_r hip_flexion_r ankle_angle_r</moment_arm_coordinate_list>"
              "<compute_moments>true</compute_moments></MuscleAnalysis>");
  xml.replace(xml.find("<results_directory>"), 0,
              "<solve_for_equilibrium_for_auxiliary_states>true</solve_for_equilibrium_for_auxiliary_states>");
  const std::string setup = (dir_ / "F" / "ma.xml").string();
  std::ofstream(setup) << xml;
  {
    InDirectory here(dir_ / "F");
    OpenSim::AnalyzeTool tool(setup);
    tool.setResultsDir((dir_ / "opensim_F").string());
    ASSERT_TRUE(tool.run());
  }
  redmax::osim::AnalyzeToolSettings s;
  s.setup_file = setup;
  s.out_dir = (dir_ / "redmax_F").string();
  const redmax::osim::AnalyzeTool tool(s);
  tool.writeMuscleAnalyses(tool.runMuscleAnalyses());
  int files = 0;
  double worst = 0.0;
  for (const auto& e : fs::directory_iterator(dir_ / "opensim_F")) {
    if (e.path().extension() != ".sto") continue;
    const fs::path ours = dir_ / "redmax_F" / e.path().filename();
    ASSERT_TRUE(fs::exists(ours)) << ours;
    const redmax::osim::Storage o = redmax::osim::readStorage(e.path().string()), r = redmax::osim::readStorage(ours.string());
    ASSERT_EQ(o.numRows(), r.numRows()) << e.path();
    for (size_t c = 0; c < o.labels.size(); ++c) {
      const auto it = std::find(r.labels.begin(), r.labels.end(), o.labels[c]);
      ASSERT_NE(it, r.labels.end()) << o.labels[c] << " in " << e.path();
      const int cr = static_cast<int>(it - r.labels.begin());
      for (int i = 0; i < o.numRows(); ++i) {
        const double d = std::abs(o.data(i, c) - r.data(i, cr));
        worst = std::max(worst, d);
        // the files print 8 decimals: one unit in the last place of either rounding
        EXPECT_LE(d, 2e-8) << e.path().filename() << " " << o.labels[c] << " t = " << o.time[i];
      }
    }
    ++files;
  }
  std::printf("[ measured ] set F MuscleAnalysis: %d files, largest difference from OpenSim's %.1e\n", files, worst);
  EXPECT_GE(files, 20);
}

}  // namespace
