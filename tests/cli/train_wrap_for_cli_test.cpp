// `redmax train-wrap --for MODEL.osim` (issue 22) end to end: one network per wrap object and a
// manifest that `--wrap neural --wrap-network DIR` reads; --check reports fallbacks and errors;
// bad input gives `error: ...` as the first line of stderr, exit 2, and writes nothing. On
// subject_walk_armless_18musc (../shared) networks trained on its trial serve every wrapped-segment
// evaluation of `redmax lengths` over that trial (measured 0 of 2856 fallbacks, 17.6 s of training
// on the shared 2-core machine; the committed 3x64 network fell back in 1110 of 2856), and so do
// networks trained on poses within the coordinate ranges (out of sample).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/network_set.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;
namespace fs = std::filesystem;

const std::string kMoco = std::string(REDMAX_SHARED_DIR) + "/opensim/opensim-core/OpenSim/Moco/Test/";

class TrainWrapForCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_train_wrap_for_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  CmdResult run(const std::string& args) const { return runRedmax(dir_, args); }
  std::string path(const std::string& f) const { return (dir_ / f).string(); }
  fs::path dir_;
};

// "network: F of E wrapped-segment evaluations fell back" of `redmax lengths`
std::pair<long, long> fallbacks(const std::string& out) {
  std::smatch m;
  const std::regex re("network: ([0-9]+) of ([0-9]+) wrapped-segment evaluations fell back");
  if (!std::regex_search(out, m, re)) return {-1, -1};
  return {std::stol(m[1]), std::stol(m[2])};
}

TEST_F(TrainWrapForCli, PendulumNetworksManifestAndCheck) {
  const std::string model = scene("double_pendulum_wrap.osim");
  const std::string train = "train-wrap --for " + model + " --ranges default --frames 60 --samples 1500 --epochs 8";
  const CmdResult r = run(train + " --out " + path("nets"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("[1/1] wrap object 'joint_cylinder' (cylinder, 1 muscle(s), 60 evaluations)"), std::string::npos)
      << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;  // progress on stdout
  ASSERT_TRUE(fs::exists(dir_ / "nets" / "wrap_networks.txt"));
  // the manifest loads; its network has the compact map and names its wrap object
  const redmax::WrapNetworkSet set = redmax::loadWrapNetworks(path("nets"));
  ASSERT_EQ(set.by_wrap.count("joint_cylinder"), 1u);
  const auto& net = *set.by_wrap.at("joint_cylinder");
  EXPECT_EQ(net.meta.at("wrap_map").rfind("compact 4", 0), 0u);
  EXPECT_EQ(net.meta.at("surface"), "cylinder");
  EXPECT_EQ(net.architecture(), "3x32");
  EXPECT_NE(net.meta.at("command").find("--ranges default --frames 60 --samples 1500 --epochs 8 --out " + path("nets")),
            std::string::npos)
      << net.meta.at("command");  // as typed
  // same seed, same network
  const CmdResult again = run(train + " --out " + path("nets2"));
  ASSERT_EQ(again.code, 0) << again.err;
  auto strip = [](const std::string& f) {
    std::ifstream in(f);
    std::string line, out;
    while (std::getline(in, line))
      if (line.rfind("meta train_seconds", 0) != 0 && line.rfind("meta command", 0) != 0) out += line + "\n";
    return out;
  };
  EXPECT_EQ(strip(path("nets/joint_cylinder.txt")), strip(path("nets2/joint_cylinder.txt")));
  // --check on other poses: the table and the total; this cylinder's quadrant is the only reason
  const CmdResult c = run("train-wrap --for " + model + " --ranges default --frames 60 --seed 2 --check " + path("nets"));
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(c.out.find("joint_cylinder               cylinder"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("wrapped-segment evaluations fell back to the smooth model"), std::string::npos) << c.out;
  EXPECT_EQ(c.out.find("outside the training box"), std::string::npos) << c.out;
  // `--wrap neural --wrap-network DIR` and the manifest itself simulate
  for (const std::string& nets : {path("nets"), path("nets/wrap_networks.txt")}) {
    const CmdResult s = run("simulate --model " + model + " --muscle-mass physiological --muscle-density 50 --duration 0.05"
                            " --wrap neural --wrap-network " + nets + " --out " + path("s.sto"));
    EXPECT_EQ(s.code, 0) << s.err;
    EXPECT_NE(s.err.find("wrap model neural"), std::string::npos) << s.err;
  }
}

TEST_F(TrainWrapForCli, CompactPlainTrainingRecordsItsMap) {
  const CmdResult r = run("train-wrap --surface sphere --hidden 2x8 --samples 300 --epochs 3 --batch 32 --lr 1e-3 "
                          "--compact 4 --out " + path("s.txt"));
  ASSERT_EQ(r.code, 0) << r.err;
  const auto net = redmax::loadWrapNetwork(path("s.txt"));
  EXPECT_EQ(net->meta.at("wrap_map"), redmax::formatCompactWrapMap(4.0));
  EXPECT_EQ(net->input_names[0], "ori_u");
  // the box is the default box's image: ori_u within (3 / (1 + 3 / 4) + 0.08) = 1.794 (asserted to 1e-12)
  EXPECT_NEAR(net->input_max[0], 3.0 / 1.75 + 0.08, 1e-12);
  EXPECT_EQ(net->input_min[7], 1.0);
  // --init must match the map
  const CmdResult bad = run("train-wrap --surface sphere --hidden 2x8 --samples 300 --epochs 1 --init " + path("s.txt") +
                            " --out " + path("t.txt"));
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--compact asks for the older map"), std::string::npos) << bad.err;
  EXPECT_EQ(run("train-wrap --surface torus --compact 4 --out " + path("t.txt")).code, 2);
  EXPECT_FALSE(fs::exists(path("t.txt")));
}

TEST_F(TrainWrapForCli, BadInputIsTheFirstErrorLineAndWritesNothing) {
  const std::string model = scene("double_pendulum_wrap.osim");
  std::ofstream(path("bad_manifest.txt")) << "redmax-wrap-networks 1\nwrap joint_cylinder\n";
  std::ofstream(path("bad.osim")) << "<OpenSimDocument Version=\"40000\">\n<Model name=\"m\">\n<BodySet>\n";
  struct Case {
    std::string args, first_line;
  };
  const std::vector<Case> cases = {
      {"train-wrap --for " + model + " --out " + path("o"), "error: --for needs one of --coordinates"},
      {"train-wrap --for " + model + " --ranges wide --out " + path("o"), "error: --ranges takes 'default'"},
      {"train-wrap --for " + model + " --coordinates " + path("none.mot") + " --out " + path("o"), "error: " + path("none.mot")},
      {"train-wrap --for " + model + " --ranges default", "error: --for needs --out DIR (train) or --check NETWORKS"},
      {"train-wrap --for " + model + " --ranges default --architecture 0x3 --out " + path("o"), "error: --hidden"},
      {"train-wrap --for " + model + " --ranges default --surface sphere --out " + path("o"), "error: --surface does not go with --for"},
      {"train-wrap --coordinates a.mot --out " + path("o"), "error: --coordinates needs --for MODEL.osim"},
      {"train-wrap --for " + path("bad.osim") + " --ranges default --out " + path("o"), "error: " + path("bad.osim") + ":"},
      {"train-wrap --for " + model + " --ranges default --check " + path("bad_manifest.txt"),
       "error: " + path("bad_manifest.txt") + ":2: 'wrap' takes a name and a file"},
      {"lengths --model " + model + " --coordinates " + scene("running_leg_swing.mot") + " --wrap neural --wrap-network " +
           path("bad_manifest.txt") + " --out " + path("o.sto"),
       "error: " + path("bad_manifest.txt") + ":2: "},
  };
  for (const Case& c : cases) {
    const CmdResult r = run(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    // the error line comes first (warnings aside): nothing but "warning:" lines before it
    std::istringstream in(r.err);
    std::string line;
    while (std::getline(in, line) && line.rfind("warning: ", 0) == 0) {
    }
    EXPECT_EQ(line.rfind(c.first_line, 0), 0u) << c.args << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(dir_ / "o"));
  EXPECT_FALSE(fs::exists(dir_ / "o.sto"));
}

TEST_F(TrainWrapForCli, SubjectWalkNetworksServeItsTrial) {
  const std::string model = kMoco + "subject_walk_armless_18musc.osim", trial = kMoco + "subject_walk_armless_coordinates.mot";
  if (!fs::exists(model)) GTEST_SKIP() << "../shared/opensim is absent: subject_walk_armless_18musc is not available";
  const CmdResult t = run("train-wrap --for " + model + " --coordinates " + trial + " --out " + path("sw"));
  ASSERT_EQ(t.code, 0) << t.err;
  // med_gas_r/l: two cylinders able to share a segment, which the wrap models refuse: no network
  EXPECT_NE(t.out.find("muscle 'med_gas_r' skipped"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("trained 10 network(s)"), std::string::npos) << t.out;
  // the committed generic network, for comparison (measured 1110 of 2856 with the older map)
  const std::string lengths = "lengths --model " + model + " --coordinates " + trial + " --wrap neural --out " + path("l.sto");
  const CmdResult l = run(lengths + " --wrap-network " + path("sw"));
  ASSERT_EQ(l.code, 0) << l.err;
  const auto [f, e] = fallbacks(l.out);
  EXPECT_EQ(e, 2856) << l.out;
  EXPECT_EQ(f, 0) << l.out;  // measured 0: in-sample, no quadrant or length cut-off on this trial
  // --check: the same count, and the position error where the networks serve (measured worst RMS
  // 0.0037 radii, KnExt_at_fem_l; bound 0.01)
  const CmdResult c = run("train-wrap --for " + model + " --coordinates " + trial + " --check " + path("sw"));
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(c.out.find("total: 0 of 2856 wrapped-segment evaluations fell back"), std::string::npos) << c.out;
  // the --check table's cylinder rows: name surface evaluations fallbacks share rms max
  auto forEachRow = [](const std::string& out, const std::function<void(const std::string&, double, double)>& f) {
    std::istringstream in(out);
    std::string line;
    int rows = 0;
    while (std::getline(in, line)) {
      std::istringstream ls(line);
      std::string name, surface, share;
      long ev = 0, fb = 0;
      double rms = 0.0, max = 0.0;
      if (!(ls >> name >> surface >> ev >> fb >> share >> rms >> max) || surface != "cylinder") continue;
      ++rows;
      f(line, rms, max);
    }
    return rows;
  };
  int rows = forEachRow(c.out, [](const std::string& line, double rms, double max) {
    EXPECT_LT(rms, 0.01) << line;
    EXPECT_LT(max, 0.1) << line;
  });
  EXPECT_EQ(rows, 10) << c.out;
  std::printf("[ measured ] %s", c.out.c_str());
  // out of sample: trained on poses within the coordinate ranges (coupled coordinates following their
  // functions), checked on the trial (measured 0 of 2856, worst RMS 0.011 radii, Gmax2_at_pelvis_l)
  const CmdResult tr = run("train-wrap --for " + model + " --ranges default --out " + path("swr"));
  ASSERT_EQ(tr.code, 0) << tr.err;
  EXPECT_NE(tr.out.find("2 coupled coordinate(s) following their function"), std::string::npos) << tr.out;
  const CmdResult cr = run("train-wrap --for " + model + " --coordinates " + trial + " --check " + path("swr"));
  ASSERT_EQ(cr.code, 0) << cr.err;
  EXPECT_NE(cr.out.find("total: 0 of 2856 wrapped-segment evaluations fell back"), std::string::npos) << cr.out;
  rows = forEachRow(cr.out, [](const std::string& line, double rms, double) { EXPECT_LT(rms, 0.03) << line; });
  EXPECT_EQ(rows, 10) << cr.out;
  std::printf("[ measured ] trained on --ranges default: %s", cr.out.c_str());
}

}  // namespace
