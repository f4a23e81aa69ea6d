// `redmax analyze` on OpenSim's arm26 static-optimization setup: the files and the summary, and a
// model the class refuses: exit 2 with FILE:LINE and nothing written.
#include <gtest/gtest.h>
#include <unistd.h>

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

}  // namespace
}  // namespace redmax::cli_test
