// `redmax scene NAME` end to end (docs/deformable.md §4, §6): the cantilever's summary line parsed
// against beam theory computed here, the hand's prescription errors, the files each scene writes
// (states, one VTK per frame, the .pvd collection), the VTK frames read back by the mesh reader,
// and bad names.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "core/deformable/tet_mesh.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;
namespace fs = std::filesystem;

class SceneCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_scene_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(SceneCli, CantileverPrintsTipDeflectionAgainstBeamTheory) {
  const CmdResult r = runRedmax(dir_, "scene cantilever --out " + (dir_ / "c").string());
  ASSERT_EQ(r.code, 0) << r.err;
  std::smatch m;
  const std::regex re(R"(^tip deflection ([0-9.eE+-]+) m, beam theory ([0-9.eE+-]+) m$)");
  bool found = false;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);)
    if (std::regex_match(line, m, re)) {
      found = true;
      const double D = std::stod(m[1]), B = std::stod(m[2]);
      // w L^4 / (8 E I) of the default beam (1 x 0.1 x 0.1 m, E 1e9, rho 1000, g 9.81)
      EXPECT_NEAR(B, 1000 * 9.81 * 0.01 / (8 * 1e9 * 1e-4 / 12), 1e-8);
      EXPECT_NEAR(D / B, 0.831, 0.002);  // refinement 4 (docs/deformable.md §4)
    }
  EXPECT_TRUE(found) << r.out;
  EXPECT_TRUE(fs::exists(dir_ / "c" / "states.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "c" / "cantilever.pvd"));
  const redmax::TetMesh loaded = redmax::readVtkTetMesh((dir_ / "c" / "cantilever_0001.vtk").string());
  EXPECT_EQ(loaded.numNodes(), 41 * 5 * 5);
}

TEST_F(SceneCli, DynamicScenesWriteStatesAndAVtkSeries) {
  for (const std::string name : {"strand", "soft-pendulum", "soft-insertion"}) {
    const fs::path out = dir_ / name;
    const CmdResult r = runRedmax(dir_, "scene " + name + " --out " + out.string());
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string states = slurp(out / "states.csv");
    EXPECT_EQ(states.rfind("time,", 0), 0u);
    int rows = 0;
    for (char c : states) rows += c == '\n';
    EXPECT_EQ(rows, 1 + (name == "strand" ? 101 : name == "soft-pendulum" ? 51 : 31));  // header + frames every 0.02 s
    const std::string pvd = slurp(out / (name + ".pvd"));
    int frames = 0;
    for (size_t at = pvd.find("<DataSet"); at != std::string::npos; at = pvd.find("<DataSet", at + 1)) ++frames;
    EXPECT_EQ(frames, rows - 1);
    EXPECT_TRUE(fs::exists(out / (name + "_0000.vtk")));
    if (name == "soft-pendulum") {
      const redmax::TetMesh last = redmax::readVtkTetMesh((out / "soft-pendulum_0050.vtk").string());
      EXPECT_EQ(last.numNodes(), 45);
      EXPECT_NE(r.out.find("rigid block"), std::string::npos);
    } else if (name == "soft-insertion") {
      // the node's columns are in the states, and the summary compares with the rigid insertion
      EXPECT_NE(states.find("node"), std::string::npos);
      EXPECT_NE(r.out.find("rigid insertion"), std::string::npos);
      EXPECT_NE(r.out.find("largest tendon force"), std::string::npos);
    } else {
      EXPECT_NE(r.out.find("largest change"), std::string::npos);
    }
  }
}

TEST_F(SceneCli, HandPrintsItsPrescriptionErrors) {
  const fs::path out = dir_ / "hand";
  const CmdResult r = runRedmax(dir_, "scene hand --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  // the lines the issue asks for (docs/deformable.md §6): with a projection every step the
  // errors are round-off (bounds as in tests/core/deformable/hybrid_scenes_test.cpp)
  std::smatch m;
  const std::regex point(R"(^largest prescribed-point error ([0-9.eE+-]+) m \(([0-9.eE+-]+) m within a step.*$)");
  const std::regex angle(R"(^largest prescribed-angle error ([0-9.eE+-]+) rad \(([0-9.eE+-]+) rad within a step.*$)");
  const std::regex coupling(R"(^largest DIP - 0.5 PIP deviation ([0-9.eE+-]+) rad$)");
  int found = 0;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    if (std::regex_match(line, m, point)) {
      ++found;
      EXPECT_LE(std::stod(m[1]), 2e-14);
      EXPECT_NEAR(std::stod(m[2]), 8.63e-8, 0.1e-8);
    } else if (std::regex_match(line, m, angle)) {
      ++found;
      EXPECT_EQ(std::stod(m[1]), 0.0);
      // A w^2 h^2 / 2 with A 0.02 rad, w = pi rad/s, h 1e-3 s
      EXPECT_NEAR(std::stod(m[2]), 0.02 * M_PI * M_PI * 1e-6 / 2, 1e-10);
    } else if (std::regex_match(line, m, coupling)) {
      ++found;
      EXPECT_EQ(std::stod(m[1]), 0.0);
    }
  }
  EXPECT_EQ(found, 3) << r.out;
  const std::string states = slurp(out / "states.csv");
  EXPECT_EQ(states.rfind("time,elbow,wrist_flexion,", 0), 0u);
  // points and bones only (no tets, so not for the tet reader): elbow, wrist, 4 x (MCP, PIP, DIP,
  // tip) joined by 17 lines
  const std::string last = slurp(out / "hand_0100.vtk");
  EXPECT_NE(last.find("POINTS 18 double"), std::string::npos);
  EXPECT_NE(last.find("CELLS 17 51"), std::string::npos) << last.substr(0, 200);
  EXPECT_TRUE(fs::exists(out / "hand.pvd"));
}

TEST_F(SceneCli, ContactScenesPrintTheirClosedFormsAndWriteStates) {
  // the closed-form agreement itself is tested in tests/core/dynamics/unilateral/contact_scenes_test.cpp
  CmdResult r = runRedmax(dir_, "scene limit-pendulum --out " + (dir_ / "lp").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("after 1.22622 J (e^2 before 1.22622 J)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("QP iterations"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir_ / "lp" / "states.csv"));
  r = runRedmax(dir_, "scene block-slide --out " + (dir_ / "bs").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("v0^2/(2 mu g) 0.407747 m"), std::string::npos) << r.out;
}

TEST_F(SceneCli, UnknownOrMissingNameIsAUsageError) {
  CmdResult r = runRedmax(dir_, "scene octopus");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("error: "), std::string::npos);
  EXPECT_NE(r.err.find("cantilever, strand, soft-pendulum, soft-insertion, hand, starfish, spline-leg, ball-drop, block-slide, "
                       "box-stack or limit-pendulum"),
            std::string::npos)
      << r.err;
  r = runRedmax(dir_, "scene");
  EXPECT_EQ(r.code, 2);
  // the spline-leg options are refused for the other scenes; a model that cannot be read is the
  // user's error, with nothing written
  r = runRedmax(dir_, "scene strand --duration 1 --out " + (dir_ / "s").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("error: --model and --duration are for the spline-leg scene"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "s"));
  const fs::path bad = dir_ / "bad.osim";
  { std::ofstream(bad) << "<OpenSimDocument Version=\"40000\">\n<Model name=\"m\">\n<BodySet>\n"; }
  r = runRedmax(dir_, "scene spline-leg --model " + bad.string() + " --out " + (dir_ / "leg").string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: " + bad.string(), 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "leg"));
  EXPECT_TRUE(fs::is_empty(dir_) || !fs::exists(dir_ / "scene-octopus"));
}

}  // namespace
