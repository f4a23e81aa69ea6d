// `redmax analyze` on OpenSim's arm26 static-optimization setup: the files and the summary, and a
// model the class refuses: exit 2 with FILE:LINE and nothing written.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "tests/cli/cli_test_util.hpp"

namespace redmax::cli_test {
namespace {

const std::string kSetup = std::string(REDMAX_SHARED_DIR) +
                           "/opensim/opensim-core/Applications/Analyze/tests/resources/arm26_Setup_StaticOptimization.xml";

TEST(AnalyzeCli, Arm26WritesOpenSimsFilesAndRefusesWhatOpenSimRefuses) {
  if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built";
  if (!fs::exists(kSetup)) GTEST_SKIP() << "shared OpenSim data not found at " REDMAX_SHARED_DIR "/opensim";
  const fs::path dir = fs::temp_directory_path() / ("redmax_analyze_cli_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const CmdResult ok = runRedmax(dir, "analyze --setup " + kSetup + " --out-dir " + (dir / "out").string() +
                                          " --muscle-class Thelen2003Muscle_Deprecated");
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find("61 frames (0 failed), 6 actuators"), std::string::npos) << ok.out;
  const osim::Storage act = osim::readStorage((dir / "out" / "arm26_StaticOptimization_activation.sto").string());
  const osim::Storage force = osim::readStorage((dir / "out" / "arm26_StaticOptimization_force.sto").string());
  EXPECT_EQ(act.numRows(), 61);
  EXPECT_EQ(force.labels, (std::vector<std::string>{"TRIlong", "TRIlat", "TRImed", "BIClong", "BICshort", "BRA"}));

  const CmdResult bad = runRedmax(dir, "analyze --setup " + kSetup + " --out-dir " + (dir / "bad").string() +
                                           " --muscle-class Thelen2003Muscle");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("arm26.osim:1122: Thelen2003Muscle muscle 'TRIlong': minimum_activation"), std::string::npos)
      << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
  fs::remove_all(dir);
}


// MuscleAnalysis and Actuation from a states file (Tug_of_War_Millard_Iso's ramp activation):
// OpenSim's file names, exit 0; an analysis class OpenSim does not have: exit 2 at its line, nothing
// written
TEST(AnalyzeCli, MuscleAnalysisFromStatesFileAndAnUnknownAnalysis) {
  if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built";
  const std::string res = std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-core/Applications/Analyze/tests/resources";
  if (!fs::exists(res)) GTEST_SKIP() << "shared OpenSim data not found at " REDMAX_SHARED_DIR "/opensim";
  const fs::path dir = fs::temp_directory_path() / ("redmax_analyze_ma_cli_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto setup = [&](const std::string& analyses) {
    return "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<AnalyzeTool name=\"tow\"><model_file>" + res +
           "/Tug_of_War_Millard_Iso.osim</model_file><results_directory>out</results_directory>"
           "<initial_time>0</initial_time><final_time>1</final_time>"
           "<solve_for_equilibrium_for_auxiliary_states>true</solve_for_equilibrium_for_auxiliary_states>\n"
           "<AnalysisSet name=\"a\"><objects>\n" + analyses + "</objects></AnalysisSet><states_file>" + res +
           "/Tug_of_War_ConstantVelocity_RampActivation.sto</states_file></AnalyzeTool>\n</OpenSimDocument>\n";
  };
  {
    std::ofstream(dir / "ma.xml") << setup("<MuscleAnalysis name=\"MuscleAnalysis\"/>\n<Actuation name=\"Actuation\"/>\n");
  }
  const CmdResult ok = runRedmax(dir, "analyze --setup " + (dir / "ma.xml").string());
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find("101 frames, 1 muscles"), std::string::npos) << ok.out;
  for (const char* f : {"tow_MuscleAnalysis_FiberLength.sto", "tow_MuscleAnalysis_TendonForce.sto",
                        "tow_MuscleAnalysis_MomentArm_block_tz.sto", "tow_Actuation_force.sto"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  {
    std::ofstream(dir / "typo.xml") << setup("<MuscleAnalysys name=\"x\"/>\n");
  }
  const CmdResult bad = runRedmax(dir, "analyze --setup " + (dir / "typo.xml").string() + " --out-dir " +
                                           (dir / "bad").string());
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("typo.xml:5: unknown analysis <MuscleAnalysys>"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace redmax::cli_test
