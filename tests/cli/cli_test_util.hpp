#pragma once
// Running the `redmax` executable of the same build from the CLI tests.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "converter/storage.hpp"

namespace redmax::cli_test {

namespace fs = std::filesystem;

/// the redmax executable of the same build: <build>/tests/cli_tests -> <build>/cli/redmax ("" if absent)
inline fs::path redmaxExe() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path exe = self.parent_path().parent_path() / "cli" / "redmax";
  return fs::exists(exe) ? exe : fs::path{};
}

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct CmdResult {
  int code;
  std::string out, err;
};

/// `redmax ARGS` with stdout and stderr captured in files of `dir`; with in_dir the command runs
/// with `dir` as its working directory
inline CmdResult runRedmax(const fs::path& dir, const std::string& args, bool in_dir = false) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = (in_dir ? "cd " + dir.string() + " && " : std::string()) + redmaxExe().string() + " " +
                          args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

/// a project-authored scene: <source>/osim_models/FILE
/// A CLI test with its own temporary folder (redmax_<tag>_<pid>, made fresh and removed after), skipped
/// when the redmax executable was not built: the fixture the CLI test files share.
class CliTempDirTest : public ::testing::Test {
 protected:
  explicit CliTempDirTest(std::string tag) : tag_(std::move(tag)) {}
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_" + tag_ + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;

 private:
  std::string tag_;
};

inline std::string scene(const std::string& file) { return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + file; }

/// relative energy drift of written states: max |E(t) - E(0)| / max(|E(0)|, max kinetic energy)
/// from the total_energy and kinetic_energy columns; a missing column or an empty table is a test
/// failure and gives NaN, which no EXPECT_LE / EXPECT_GE bound accepts
inline double energyDrift(const osim::Storage& s) {
  const int e = s.findColumn("total_energy"), k = s.findColumn("kinetic_energy");
  if (e < 0 || k < 0 || s.numRows() == 0) {
    ADD_FAILURE() << "energyDrift: no rows or no total_energy / kinetic_energy column";
    return std::numeric_limits<double>::quiet_NaN();
  }
  const double E0 = s.data(0, e);
  const double scale = std::max(std::abs(E0), s.data.col(k).maxCoeff());
  return (s.data.col(e).array() - E0).abs().maxCoeff() / scale;
}

}  // namespace redmax::cli_test
