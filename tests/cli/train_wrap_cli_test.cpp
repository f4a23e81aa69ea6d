// `redmax train-wrap` end to end: a tiny training run writes a loadable network (with its command
// and seed), the loss CSV, and the same weights for the same seed; --compare writes its table; bad
// input exits 2 with a message. Timings are never asserted.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/muscles/wrap/network.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;

namespace fs = std::filesystem;

// the file without its wall-time line
std::string withoutTime(const std::string& text) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line))
    if (line.rfind("meta train_seconds", 0) != 0) out += line + "\n";
  return out;
}

class TrainWrapCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_train_wrap_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  CmdResult run(const std::string& args) const {
    return runRedmax(dir_, args);
  }
  fs::path dir_;
};

TEST_F(TrainWrapCli, TinyTrainingWritesAReproducibleNetworkAndItsLossCurve) {
  const std::string net = (dir_ / "net.txt").string(), rep = (dir_ / "rep").string();
  const std::string args =
      "train-wrap --surface cylinder --hidden 2x8 --samples 300 --epochs 3 --batch 32 --seed 2 --out " + net + " --report " + rep;
  CmdResult r = run(args);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("epoch 3/3"), std::string::npos) << r.out;  // progress on stdout
  const redmax::Mlp m = redmax::Mlp::load(net);
  EXPECT_EQ(m.architecture(), "2x8");
  EXPECT_EQ(m.meta.at("seed"), "2");
  EXPECT_EQ(m.meta.at("surface"), "cylinder");
  EXPECT_NE(m.meta.at("command").find("--seed 2"), std::string::npos);
  // loss.csv: header and one row per epoch
  const std::string csv = slurp(fs::path(rep) / "loss.csv");
  EXPECT_EQ(csv.rfind("epoch,steps,train_mse,val_mse,val_rms,elapsed_s\n", 0), 0u) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);
  // the same command gives the same file (apart from the wall time)
  const std::string first = slurp(net);
  r = run(args);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(withoutTime(slurp(net)), withoutTime(first));
}

TEST_F(TrainWrapCli, CompareWritesTheSpeedErrorTable) {
  const std::string rep = (dir_ / "cmp").string();
  const CmdResult r = run("train-wrap --compare --surface sphere --untrained 2x8 --muscles 4 --mass-points 3 --report " + rep);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = slurp(fs::path(rep) / "speed_error.csv");
  EXPECT_EQ(csv.rfind("method,parameters,us_per_point,rms_error,max_error,note\n", 0), 0u) << csv;
  EXPECT_NE(csv.find("exact library"), std::string::npos);
  EXPECT_NE(csv.find("smooth model"), std::string::npos);
  EXPECT_NE(csv.find("2x8 (untrained"), std::string::npos);
  // every surface type has the smooth model now
  for (const char* surface : {"ellipsoid", "torus"}) {
    const std::string rep2 = (dir_ / (std::string("cmp_") + surface)).string();
    const CmdResult r2 = run(std::string("train-wrap --compare --surface ") + surface +
                             " --untrained none --muscles 2 --mass-points 3 --report " + rep2);
    ASSERT_EQ(r2.code, 0) << r2.err;
    const std::string csv2 = slurp(fs::path(rep2) / "speed_error.csv");
    EXPECT_NE(csv2.find("smooth model"), std::string::npos) << surface;
  }
}

TEST_F(TrainWrapCli, StudyWritesCurvesForEveryThresholdAndArchitecture) {
  const std::string rep = (dir_ / "study").string();
  const CmdResult r = run("train-wrap --study --samples 200 --epochs 2 --thresholds 0.01,0.1 --architectures 1x4 --report " + rep);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = slurp(fs::path(rep) / "study.csv");
  EXPECT_EQ(csv.rfind("ins_x,x_exact,dxdins_exact,x_1x4 thr 0.01,dxdins_1x4 thr 0.01,x_1x4 thr 0.1,dxdins_1x4 thr 0.1\n", 0), 0u) << csv.substr(0, 200);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 252);  // header + 251 positions
  EXPECT_EQ(run("train-wrap --study --thresholds 2 --report " + rep).code, 2);
}

TEST_F(TrainWrapCli, BadInputExitsTwoWithAMessage) {
  const std::string out = " --out " + (dir_ / "n.txt").string();
  CmdResult r = run("train-wrap --surface cube" + out);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown surface 'cube'"), std::string::npos) << r.err;
  r = run("train-wrap --hidden 0x3" + out);
  EXPECT_EQ(r.code, 2);
  r = run("train-wrap --surface sphere");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--out"), std::string::npos) << r.err;
  r = run("train-wrap --out /nonexistent_redmax_dir/n.txt");
  EXPECT_EQ(r.code, 2);
  r = run("train-wrap --threshold 2" + out);
  EXPECT_EQ(r.code, 2);
  r = run("train-wrap --compare --surface torus --muscles 0 --report " + (dir_ / "c").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--muscles and --mass-points must be positive"), std::string::npos) << r.err;
  // a file that is not a network: named with its line
  const fs::path bad = dir_ / "bad.txt";
  std::ofstream(bad) << "redmax-mlp 1\ninputs 8\noutputs 3\nhidden 1 4\nactivation relu\n";
  r = run("train-wrap --compare --nets " + bad.string() + " --report " + (dir_ / "c").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(bad.string() + ":5: only 'activation tanh'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "n.txt"));
}

}  // namespace
