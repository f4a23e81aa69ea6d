// `redmax bench` end to end on a tiny scene: it runs, prints the table, writes JSON, and rejects
// bad input with exit code 2. Correctness only; timings are never asserted.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;

namespace fs = std::filesystem;

class BenchCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_bench_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  fs::path dir_;
};

TEST_F(BenchCli, RunsOnATinySceneAndWritesJson) {
  const fs::path json = dir_ / "bench.json";
  const CmdResult r = runRedmax(dir_, "bench --scene chain2 --repeats 2 --batches 1 --integrators euler --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ratio"), std::string::npos) << r.out;
  for (const char* op : {"kinematics", "mass_matrix", "id_redmax", "id_recursive", "forward_dynamics", "step_euler"})
    EXPECT_NE(r.out.find(op), std::string::npos) << op << "\n" << r.out;
  const std::string js = slurp(json);
  EXPECT_NE(js.find("\"scene\": \"chain2\""), std::string::npos) << js;
  EXPECT_NE(js.find("\"operation\": \"step_euler\""), std::string::npos) << js;
  EXPECT_EQ(js.find("step_rk45"), std::string::npos);  // only the integrators asked for
}

TEST_F(BenchCli, BadInputIsAUsageError) {
  CmdResult r = runRedmax(dir_, "bench --scene nowhere");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown scene 'nowhere'"), std::string::npos) << r.err;
  r = runRedmax(dir_, "bench --scene chain2 --repeats 0");
  EXPECT_EQ(r.code, 2);
  r = runRedmax(dir_, "bench --scene chain2 --repeats many");
  EXPECT_EQ(r.code, 2);
  r = runRedmax(dir_, "bench --scene chain2 --integrators warp");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("warp"), std::string::npos) << r.err;
  const fs::path missing = dir_ / "no_such_folder" / "out.json";
  r = runRedmax(dir_, "bench --scene chain2 --repeats 1 --json " + missing.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(missing));
}

}  // namespace
