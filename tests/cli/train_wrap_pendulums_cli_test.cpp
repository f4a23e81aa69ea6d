// `redmax train-wrap --pendulums NET`: wrapping double pendulums on one committed network
// (WrapModel::Neural) conserve energy to integrator error and report their smooth-model fallbacks;
// bad input exits 2 with a message and writes nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>

#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;

class TrainWrapPendulumsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_wrap_pendulums_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string net(const std::string& name) const {
    return std::string(REDMAX_SOURCE_DIR) + "/osim_models/networks/" + name;
  }
  fs::path dir_;
};

TEST_F(TrainWrapPendulumsCli, TwoPendulumsConserveEnergyAndWriteTheTable) {
  const fs::path report = dir_ / "report";
  const CmdResult r =
      runRedmax(dir_, "train-wrap --pendulums " + net("cylinder_3x64.txt") + " --count 2 --duration 0.5 --report " +
                          report.string());
  ASSERT_EQ(r.code, 0) << r.err;
  std::smatch m;
  const std::regex summary(R"(largest energy drift ([0-9.eE+-]+) J; ([0-9]+) of ([0-9]+) wrap evaluations fell back)");
  ASSERT_TRUE(std::regex_search(r.out, m, summary)) << r.out;
  EXPECT_LE(std::stod(m[1]), 1e-8) << r.out;  // integrator error (rk45 1e-12; measured 1.8e-13 J)
  EXPECT_EQ(std::stol(m[2]), 0) << r.out;     // the first two of seed 1 stay in the training box
  EXPECT_GT(std::stol(m[3]), 100);
  const std::string csv = slurp(report / "pendulums.csv");
  EXPECT_EQ(csv.rfind("pendulum,origin_x", 0), 0u) << csv;
  int lines = 0;
  for (char c : csv) lines += c == '\n';
  EXPECT_EQ(lines, 3) << csv;  // header + 2 pendulums
}

TEST_F(TrainWrapPendulumsCli, BadInputExitsTwo) {
  auto expectUsage = [&](const std::string& args, const std::string& needle) {
    const CmdResult r = runRedmax(dir_, "train-wrap " + args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\n" << r.err;
  };
  expectUsage("--pendulums " + (dir_ / "missing.txt").string(), "missing.txt");
  expectUsage("--pendulums " + net("sphere_3x64.txt"), "this network is for a sphere");
  expectUsage("--pendulums " + net("cylinder_3x64.txt") + " --count 0", "--count");
  expectUsage("--pendulums " + net("cylinder_3x64.txt") + " --duration -1", "--duration");
  expectUsage("--pendulums " + net("cylinder_3x64.txt") + " --compare", "exclude each other");
  EXPECT_FALSE(fs::exists(dir_ / "report"));
}

}  // namespace
