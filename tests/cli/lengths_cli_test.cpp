// `redmax lengths` end to end against OpenSim's own muscle-length references (OpenSim 4.4.1,
// opensim-core/OpenSim/Tests/Wrapping, its test tolerance 1e-6 m): walk_gait1018 (conditional and
// moving points, no wraps) and subject_walk_armless_18musc (40 WrapCylinders, muscles over one or
// two cylinders). arm26 (2 ellipsoids + 2 cylinders, no OpenSim length reference) and the shoulder
// model with path springs (cylinders, spheres, ellipsoids, tori) run through the command: finite
// lengths, continuity along the motion. Bad input: exit 2, `error: ...`, nothing written.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "converter/storage.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;

namespace fs = std::filesystem;
using redmax::osim::readStorage;
using redmax::osim::Storage;

const std::string kShared = REDMAX_SHARED_DIR;
const std::string kCore = kShared + "/opensim/opensim-core/OpenSim/";

class LengthsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_lengths_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  bool haveShared() const { return fs::exists(kShared + "/opensim"); }
  CmdResult run(const std::string& args) const {
    return runRedmax(dir_, args, true);
  }

  // max |ours - OpenSim| over all rows and the reference's columns (/forceset/NAME|length)
  double compareWithReference(const Storage& ours, const Storage& ref, int* columns) const {
    EXPECT_EQ(ours.numRows(), ref.numRows());
    double worst = 0;
    *columns = 0;
    for (int c = 0; c < ref.numColumns(); ++c) {
      std::string name = ref.labels[c];
      if (name.rfind("/forceset/", 0) == 0) name = name.substr(10);
      if (const auto bar = name.find('|'); bar != std::string::npos) name = name.substr(0, bar);
      const int k = ours.findColumn(name);
      EXPECT_GE(k, 0) << "no column for " << name;
      if (k < 0) continue;
      ++*columns;
      double w = 0;
      for (int r = 0; r < std::min(ours.numRows(), ref.numRows()); ++r) {
        EXPECT_NEAR(ours.time[r], ref.time[r], 1e-9);
        w = std::max(w, std::abs(ours.data(r, k) - ref.data(r, c)));
      }
      EXPECT_LT(w, 1e-6) << name;
      worst = std::max(worst, w);
    }
    return worst;
  }

  fs::path dir_;
};

TEST_F(LengthsCli, Gait1018MatchesOpenSim) {
  if (!haveShared()) GTEST_SKIP() << "../shared/opensim is absent: OpenSim's length reference is not available";
  const CmdResult r = run("lengths --model " + kCore + "Moco/Test/walk_gait1018_subject01.osim --coordinates " +
                          kCore + "Moco/Test/walk_gait1018_state_reference.mot --full-precision --out out/l.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("lengths: 151 frames, 18 muscles"), std::string::npos) << r.out;
  const Storage ours = readStorage((dir_ / "out/l.sto").string());
  const Storage ref = readStorage(kCore + "Tests/Wrapping/std_testGeometryPathWrapping_walk_gait1018_muscle_lengths.sto");
  int columns = 0;
  const double worst = compareWithReference(ours, ref, &columns);
  EXPECT_EQ(columns, 18);
  std::printf("[ measured ] walk_gait1018 lengths vs OpenSim 4.4.1: max |difference| %.3g m over %d muscles\n",
              worst, columns);
}

TEST_F(LengthsCli, SubjectWalkArmlessWithFortyCylindersMatchesOpenSim) {
  if (!haveShared()) GTEST_SKIP() << "../shared/opensim is absent: OpenSim's length reference is not available";
  const CmdResult r = run("lengths --model " + kCore + "Moco/Test/subject_walk_armless_18musc.osim --coordinates " +
                          kCore + "Moco/Test/subject_walk_armless_coordinates.mot --wrap exact --full-precision "
                          "--out l.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("238 frames, 18 muscles (14 wrapping"), std::string::npos) << r.out;
  const Storage ours = readStorage((dir_ / "l.sto").string());
  const Storage ref = readStorage(kCore + "Tests/Wrapping/std_testGeometryPathWrapping_subject_walk_armless_muscle_lengths.sto");
  int columns = 0;
  const double worst = compareWithReference(ours, ref, &columns);
  EXPECT_EQ(columns, 18);
  std::printf("[ measured ] subject_walk_armless (40 cylinders) lengths vs OpenSim 4.4.1: max |difference| %.3g m\n",
              worst);

  // the surface lengths l: one column per PathWrap (16 on these 14 muscles), cylinders >= 0, and
  // a muscle with one wrap is as long as its straight length when l = 0
  const CmdResult rw = run("lengths --model " + kCore + "Moco/Test/subject_walk_armless_18musc.osim --coordinates " +
                           kCore + "Moco/Test/subject_walk_armless_coordinates.mot --quiet --out l2.sto "
                           "--wrap-lengths w.sto");
  ASSERT_EQ(rw.code, 0) << rw.err;
  const Storage wl = readStorage((dir_ / "w.sto").string());
  EXPECT_EQ(wl.numColumns(), 16);
  EXPECT_EQ(wl.numRows(), 238);
  EXPECT_GE(wl.data.minCoeff(), 0.0);
  EXPECT_GT(wl.data.maxCoeff(), 1e-3);
  EXPECT_GE(wl.findColumn("med_gas_r/Gastroc_at_condyles_r"), 0);

  // without the wraps the wrapping muscles are shorter, by up to centimetres: the comparison above
  // really exercises the wrap code
  const CmdResult rn = run("lengths --model " + kCore + "Moco/Test/subject_walk_armless_18musc.osim --coordinates " +
                           kCore + "Moco/Test/subject_walk_armless_coordinates.mot --wrap none --quiet --out n.sto");
  ASSERT_EQ(rn.code, 0) << rn.err;
  const Storage none = readStorage((dir_ / "n.sto").string());
  const double extra = (ours.data - none.data).maxCoeff();
  EXPECT_GT(extra, 5e-3);
  // never shorter, except by nanometres where a wrap barely starts (OpenSim's tangent points are
  // not exactly tangent there)
  EXPECT_GE((ours.data - none.data).minCoeff(), -1e-7);
  std::printf("[ measured ] subject_walk_armless: wrapping adds up to %.4f m\n", extra);
}

TEST_F(LengthsCli, Arm26EllipsoidsAndCylindersGiveContinuousLengths) {
  // no OpenSim length reference exists for arm26; the ellipsoid itself is checked against a
  // brute-force shortest path in tests/core/muscles/wrap_exact_test.cpp
  if (!haveShared()) GTEST_SKIP() << "../shared/opensim is absent";
  const std::string model = kShared + "/opensim/opensim-models/Models/Arm26/arm26.osim";
  const std::string motion = kShared +
      "/opensim/opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/InverseKinematics/arm26_InverseKinematics.mot";
  if (!fs::exists(motion)) GTEST_SKIP() << "arm26 motion absent: " << motion;
  const CmdResult r = run("lengths --model " + model + " --coordinates " + motion + " --full-precision --out a.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage s = readStorage((dir_ / "a.sto").string());
  ASSERT_EQ(s.numColumns(), 6);
  ASSERT_GT(s.numRows(), 100);
  EXPECT_TRUE(s.data.allFinite());
  // 120 Hz motion: a muscle's length changes by far less than a millimetre per frame; a wrap that
  // switched surfaces or sides discontinuously would show as a jump
  double worst = 0;
  for (int k = 1; k < s.numRows(); ++k) worst = std::max(worst, (s.data.row(k) - s.data.row(k - 1)).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 2e-3);
  const CmdResult rn = run("lengths --model " + model + " --coordinates " + motion + " --wrap none --quiet --out n.sto");
  ASSERT_EQ(rn.code, 0) << rn.err;
  const Storage none = readStorage((dir_ / "n.sto").string());
  std::printf("[ measured ] arm26: max length step between frames %.3g m; wrapping adds up to %.4f m\n", worst,
              (s.data - none.data).maxCoeff());
}

TEST_F(LengthsCli, ShoulderPathSpringsOverAllFourSurfaceTypesAreFinite) {
  // 103 path springs over 3 cylinders, 2 spheres, 5 ellipsoids and 3 tori (no OpenSim length
  // reference): a sweep of shoulder elevation and elbow flexion, in degrees
  if (!haveShared()) GTEST_SKIP() << "../shared/opensim is absent";
  const std::string model = kCore + "Tests/Wrapping/testGeometryPathWrapping_ShoulderWrappingWithPathSprings.osim";
  std::ostringstream q;
  q << "sweep\nversion=1\nnRows=91\nnColumns=3\ninDegrees=yes\nendheader\ntime\tshoulder_elv\telbow_flexion\n";
  for (int k = 0; k <= 90; ++k) q << 0.01 * k << "\t" << k << "\t" << 0.8 * k << "\n";
  std::ofstream(dir_ / "q.mot") << q.str();
  const CmdResult r = run("lengths --model " + model + " --coordinates q.mot --all-paths --quiet --out s.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  const Storage s = readStorage((dir_ / "s.sto").string());
  EXPECT_EQ(s.numColumns(), 103);
  EXPECT_EQ(s.numRows(), 91);
  EXPECT_TRUE(s.data.allFinite());
  EXPECT_GT(s.data.minCoeff(), 0.0);
  // a file with no coordinate column is bad input
  std::ofstream(dir_ / "t.sto") << "t\nversion=1\nnRows=2\nnColumns=1\ninDegrees=no\nendheader\ntime\n0\n1\n";
  const CmdResult r2 = run("lengths --model " + model + " --coordinates t.sto --all-paths --quiet --out t_out.sto");
  EXPECT_EQ(r2.code, 2) << r2.err;
  EXPECT_NE(r2.err.find("no column names a coordinate"), std::string::npos) << r2.err;
  EXPECT_FALSE(fs::exists(dir_ / "t_out.sto"));
}

TEST_F(LengthsCli, BadInputExitsTwoAndWritesNothing) {
  const CmdResult r1 = run("lengths --model missing.osim --coordinates q.mot --out x.sto");
  EXPECT_EQ(r1.code, 2);
  EXPECT_EQ(r1.err.rfind("error: ", 0), 0u) << r1.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.sto"));
  const CmdResult r2 = run("lengths --model m.osim --coordinates q.mot --wrap bogus --out x.sto");
  EXPECT_EQ(r2.code, 2);
  EXPECT_NE(r2.err.find("--wrap"), std::string::npos) << r2.err;
  const CmdResult r3 = run("lengths --model m.osim");
  EXPECT_EQ(r3.code, 2);
  EXPECT_FALSE(fs::exists(dir_ / "x.sto"));
}

}  // namespace
