// Storage (.sto/.mot) reading on every shared header variant and on generated edge cases,
// degrees vs radians as OpenSim decides (docs/opensim_compatibility.md §1.5), and the atomic writer.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "converter/storage.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using test::sharedOpenSim;

struct SharedStorage {
  const char* path;
  int version;
  bool in_degrees;
  int rows;
  int columns;  // data columns, time excluded
  const char* first_label;
  double first_time;
};

TEST(Storage, EverySharedFileReadsWithItsHeader) {
  REDMAX_REQUIRE_SHARED();
  const SharedStorage files[] = {
      // version 1 with nRows/nColumns, inDegrees=yes plus "Angles are in degrees."
      {"opensim-models/Pipelines/Gait2392_Simbody/subject01_walk1_ik.mot", 1, true, 211, 23,
       "pelvis_tilt", 0.5},
      {"opensim-models/Pipelines/Gait10dof18musc/OutputReference/IK/subject01_walk_IK.mot", 1, true,
       151, 10, "pelvis_tilt", 0.0},
      {"opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/InverseKinematics/"
       "arm26_InverseKinematics.mot",
       1, true, 121, 2, "r_shoulder_elev", 0.0},
      // header lines with trailing tabs
      {"opensim-models/Pipelines/Gait2392_Simbody/subject01_walk1_grf.mot", 1, true, 1501, 18,
       "ground_force_vx", 0.0},
      {"opensim-models/Pipelines/Gait10dof18musc/OutputReference/ExperimentalData/subject01_walk_grf.mot",
       1, true, 1501, 18, "ground_force_vx", 0.0},
      {"opensim-core/OpenSim/Moco/Test/walk_gait1018_subject01_grf.mot", 1, true, 1501, 18,
       "ground_force_vx", 0.0},
      {"opensim-core/OpenSim/Moco/Test/subject_walk_armless_grfs.mot", 1, false, 4778, 18,
       "ground_force_r_vx", 0.0},
      {"opensim-core/OpenSim/Moco/Test/subject_walk_armless_coordinates.mot", 1, true, 238, 39,
       "pelvis_tilt", 0.0},
      // absolute state names as labels
      {"opensim-core/OpenSim/Moco/Test/walk_gait1018_state_reference.mot", 1, true, 151, 10,
       "/jointset/ground_pelvis/pelvis_tilt/value", 0.0},
      {"opensim-core/Applications/ID/tests/resources/ThorascapularShoulderModel_static.mot", 1,
       false, 6, 17, "ground_thorax_rot_x", 0.01},
      // OpenSim ID outputs (inDegrees=no)
      {"opensim-4.6-results/E.sto", 1, false, 73, 23, "pelvis_tilt_moment", 0.39999934},
      {"opensim-4.6-results/F.sto", 1, false, 151, 10, "pelvis_tilt_moment", -0.0000005},
      {"opensim-4.6-results/A-filtered.sto", 1, false, 121, 2, "r_shoulder_elev_moment", -0.0000002},
      {"opensim-4.6-results/A-unfiltered.sto", 1, false, 121, 2, "r_shoulder_elev_moment", 0.0},
      {"opensim-models/Pipelines/Gait2392_Simbody/OutputReference/ResultsInverseDynamics/"
       "InverseDynamicsOutput.sto",
       1, false, 73, 23, "pelvis_tilt_moment", 0.39999934},
      {"opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/Results/subject01_walk_ID.sto",
       1, false, 151, 10, "pelvis_tilt_moment", -0.0000005},
      // version 3 (STOFileAdapter): no row or column counts, '|' in labels
      {"opensim-core/OpenSim/Tests/Wrapping/std_testGeometryPathWrapping_walk_gait1018_muscle_lengths.sto",
       3, false, -1, 18, "/forceset/hamstrings_r|length", 0.0},
      {"opensim-core/OpenSim/Tests/Wrapping/"
       "std_testGeometryPathWrapping_subject_walk_armless_muscle_lengths.sto",
       3, false, -1, 18, "/forceset/bifemsh_r|length", 0.0},
  };
  for (const auto& f : files) {
    SCOPED_TRACE(f.path);
    const Storage s = readStorage(sharedOpenSim(f.path));
    EXPECT_EQ(s.version, f.version);
    EXPECT_EQ(s.in_degrees, f.in_degrees);
    if (f.rows > 0) {
      EXPECT_EQ(s.numRows(), f.rows);
    }
    EXPECT_GT(s.numRows(), 1);
    EXPECT_EQ(s.numColumns(), f.columns);
    EXPECT_EQ(s.data.rows(), s.numRows());
    EXPECT_EQ(s.data.cols(), s.numColumns());
    ASSERT_FALSE(s.labels.empty());
    EXPECT_EQ(s.labels[0], f.first_label);
    EXPECT_NEAR(s.time[0], f.first_time, 1e-12);
    for (int r = 1; r < s.numRows(); ++r) EXPECT_GT(s.time[r], s.time[r - 1]);
    EXPECT_TRUE(s.data.allFinite());
  }
}

TEST(Storage, SpotValuesAndNames) {
  REDMAX_REQUIRE_SHARED();
  const Storage ik = readStorage(sharedOpenSim("opensim-models/Pipelines/Gait2392_Simbody/subject01_walk1_ik.mot"));
  EXPECT_EQ(ik.name, "Coordinates");
  EXPECT_EQ(ik.data(0, 0), 4.76281529);  // pelvis_tilt at 0.5 s, as written (degrees)
  const int hip = ik.findColumn("hip_flexion_r");
  ASSERT_GE(hip, 0);
  EXPECT_EQ(ik.data(0, hip), 19.18693645);
  const Storage grf = readStorage(sharedOpenSim("opensim-models/Pipelines/Gait2392_Simbody/subject01_walk1_grf.mot"));
  EXPECT_EQ(grf.name, "subject01_walk1_grf.mot");
  EXPECT_EQ(grf.data(1, 1), 743.0973413);  // ground_force_vy at 0.0017 s
  EXPECT_EQ(grf.time[1], 0.0017);
  // prefix matching keeps "1_ground_force_v" apart from "ground_force_v"
  EXPECT_EQ(grf.findColumnsWithPrefix("ground_force_v"), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(grf.findColumnsWithPrefix("1_ground_force_v"), (std::vector<int>{6, 7, 8}));
  const Storage v3 = readStorage(sharedOpenSim(
      "opensim-core/OpenSim/Tests/Wrapping/std_testGeometryPathWrapping_walk_gait1018_muscle_lengths.sto"));
  EXPECT_EQ(v3.data(0, 0), 0.4510537601596267);
  EXPECT_EQ(v3.name, "DataType=double");  // an unrecognized first line names the storage
}

std::string header(const std::string& lines) { return lines + "endheader\n"; }

TEST(Storage, DegreesDecidedAsOpenSimDoes) {
  test::TempDir dir;
  const std::string body = "time\ta\n0\t1\n1\t2\n";
  auto read = [&](const std::string& name, const std::string& text) {
    return readStorage(dir.write(name, text));
  };
  // a .mot without a version line is a SIMM motion: forced to degrees
  EXPECT_TRUE(read("simm.mot", header("nRows=2\nnColumns=2\n") + body).in_degrees);
  EXPECT_TRUE(read("simm2.mot", header("nRows=2\nnColumns=2\ninDegrees=no\n") + body).in_degrees);
  // the same as .sto: radians by default
  EXPECT_FALSE(read("plain.sto", header("nRows=2\nnColumns=2\n") + body).in_degrees);
  // version=1: the header decides; yes / y (any case) mean degrees, anything else radians
  EXPECT_FALSE(read("v1.mot", header("version=1\nnRows=2\nnColumns=2\n") + body).in_degrees);
  EXPECT_TRUE(read("v1y.mot", header("version=1\nnRows=2\nnColumns=2\ninDegrees=Y\n") + body).in_degrees);
  EXPECT_FALSE(read("v1t.sto", header("version=1\nnRows=2\nnColumns=2\ninDegrees=true\n") + body).in_degrees);
  // "Angles are in degrees." counts only while no version line has been seen
  EXPECT_TRUE(read("ang.sto", header("nRows=2\nnColumns=2\nAngles are in degrees.\n") + body).in_degrees);
  EXPECT_FALSE(read("ang2.sto", header("version=1\nnRows=2\nnColumns=2\nAngles are in degrees.\n") + body)
                   .in_degrees);
  EXPECT_FALSE(read("ang3.sto", header("inDegrees=yes\nnRows=2\nnColumns=2\nAngles are in radians.\n") + body)
                   .in_degrees);
}

TEST(Storage, LegacyRowsFlowAcrossLinesAndCountsMustAgree) {
  test::TempDir dir;
  // numbers are read with >>: line breaks inside a row do not matter
  const Storage s = readStorage(dir.write("flow.sto", header("version=1\nnRows=2\nnColumns=3\n") +
                                                          "\n\ntime a b\n0 1\n2 1 3\n4\n"));
  EXPECT_EQ(s.numRows(), 2);
  EXPECT_EQ(s.data(1, 1), 4.0);
  EXPECT_EQ(s.time[1], 1.0);
  // too few values
  const std::string shortp = dir.write("short.sto", header("version=1\nnRows=3\nnColumns=2\n") +
                                                         "time\ta\n0\t1\n1\t2\n");
  try {
    readStorage(shortp);
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), 7);  // the last line with data
    EXPECT_NE(std::string(e.what()).find("nRows=3"), std::string::npos);
  }
  // nColumns disagreeing with the labels
  const std::string wide = dir.write("wide.sto", header("version=1\nnRows=1\nnColumns=4\n") +
                                                      "time\ta\n0\t1\n");
  try {
    readStorage(wide);
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), 5);
    EXPECT_NE(std::string(e.what()).find("nColumns=4 but the label line has 2"), std::string::npos);
  }
  // a bad number names its line
  const std::string bad = dir.write("bad.mot", header("version=1\nnRows=2\nnColumns=2\n") +
                                                   "time\ta\n0\t1\n1\t2x\n");
  try {
    readStorage(bad);
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_EQ(std::string(e.what()), bad + ":7: '2x' is not a number");
  }
}

// OpenSim's Storage reads rows through append(), whose duplicate-time check (on by default) lets a
// row with the previous row's time replace it: OpenSim's own walk_subject01_Kinematics_q.sto ends
// with a repeated row, which would otherwise stop every spline through the times
TEST(Storage, ARowRepeatingThePreviousTimeReplacesIt) {
  test::TempDir dir;
  const Storage s = readStorage(dir.write("dup.sto", header("version=1\nnRows=4\nnColumns=2\n") +
                                                        "time\ta\n0\t1\n1\t2\n1\t3\n2\t4\n"));
  ASSERT_EQ(s.numRows(), 3);
  EXPECT_EQ(s.time, (std::vector<double>{0, 1, 2}));
  EXPECT_EQ(s.data(1, 0), 3.0);  // the later row
  EXPECT_EQ(s.data(2, 0), 4.0);
  bool named = false;
  for (const std::string& w : s.warnings) named = named || w.find("1 row(s) repeat the previous row's time") != std::string::npos;
  EXPECT_TRUE(named);
}

TEST(Storage, HeaderErrors) {
  test::TempDir dir;
  auto expectErr = [&](const std::string& name, const std::string& text, const std::string& what) {
    const std::string p = dir.write(name, text);
    try {
      readStorage(p);
      ADD_FAILURE() << name;
    } catch (const ConvertError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(p + ":", 0), 0u);
    }
  };
  expectErr("noend.sto", "version=1\nnRows=1\nnColumns=2\ntime\ta\n0 1\n", "no 'endheader'");
  expectErr("nocounts.mot", header("name x\n") + "time\ta\n0 1\n", "neither nRows nor nColumns");
  expectErr("badcount.sto", header("nRows=abc\n") + "time\ta\n0 1\n", "non-negative count");
  expectErr("nolabels.sto", header("version=1\nnRows=1\nnColumns=2\n"), "no column labels");
  expectErr("v3row.sto", header("version=3\n") + "time\ta\tb\n0\t1\n", "row has 2 values");
  expectErr("vec3.sto", header("DataType=Vec3\nversion=3\n") + "time\ta\n0\t~[1,2,3]\n", "DataType=Vec3");
  expectErr("data.csv", "time,a\n0,1\n", "not a .sto or .mot file");
  try {
    readStorage(dir.file("missing.sto"));
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open file"), std::string::npos);
  }
}

TEST(Storage, SimmMotionWithoutTimeUsesRange) {
  test::TempDir dir;
  const Storage s = readStorage(dir.write("simm.mot", header("nRows=3\nnColumns=2\nrange 1 2\n") +
                                                          "a b\n10 20\n11 21\n12 22\n"));
  ASSERT_EQ(s.numRows(), 3);
  EXPECT_EQ(s.numColumns(), 2);
  EXPECT_DOUBLE_EQ(s.time[1], 1.5);
  EXPECT_EQ(s.data(2, 1), 22.0);
  EXPECT_TRUE(s.in_degrees);
}

TEST(Storage, WriterRoundTripsAndIsAtomic) {
  test::TempDir dir;
  Storage s;
  s.name = "Inverse Dynamics Generalized Forces";
  s.labels = {"q1_moment", "q2_force"};
  s.time = {0.0, 0.0083333333, 1.0};
  s.data.resize(3, 2);
  s.data << 1.5, -2.25, 1e-9, 123456.789, -0.000000004, 7.0;
  const std::string p = dir.file("out.sto");
  writeStorage(p, s);
  const Storage r = readStorage(p);
  EXPECT_EQ(r.name, s.name);
  EXPECT_EQ(r.version, 1);
  EXPECT_FALSE(r.in_degrees);
  EXPECT_EQ(r.labels, s.labels);
  ASSERT_EQ(r.numRows(), 3);
  // %16.8lf keeps 8 decimals: differences up to 5e-9 are the format's, not the reader's
  EXPECT_LE((r.data - s.data).cwiseAbs().maxCoeff(), 5e-9);
  EXPECT_NEAR(r.time[1], 0.00833333, 1e-12);
  // the exact OpenSim layout of a data line
  const std::string text = formatStorage(s);
  EXPECT_NE(text.find("\ntime\tq1_moment\tq2_force\n      0.00000000\t      1.50000000\t     -2.25000000\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("nColumns=3\ninDegrees=no\nendheader\ntime\tq1_moment\tq2_force\n"),
            std::string::npos);
  // scientific keeps the small values
  StorageWriteOptions sci;
  sci.scientific = true;
  sci.decimals = 12;
  writeStorage(p, s, sci);
  EXPECT_LE((readStorage(p).data - s.data).cwiseAbs().maxCoeff(), 1e-12 * 123456.789);
  // no temporary file is left beside the output
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.str())) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  // an inconsistent table is refused before anything is written; an unwritable path throws
  Storage broken = s;
  broken.labels.pop_back();
  EXPECT_THROW(writeStorage(dir.file("broken.sto"), broken), ConvertError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("broken.sto")));
  EXPECT_THROW(writeStorage(dir.file("no/such/dir/x.sto"), s), ConvertError);
}

TEST(Storage, ResultWriterCreatesTheFolderAndTakesFullPrecision) {
  // the one writer of `redmax id`, `lengths` and `simulate` results
  test::TempDir dir;
  Storage s;
  s.name = "states";
  s.labels = {"a"};
  s.time = {0.0, 1.0};
  s.data.resize(2, 1);
  s.data << 0.12345678901234567, -4e-12;
  const std::string p = dir.file("new/sub/out.sto");
  writeResultStorage(p, s, false, "made by a test");
  const std::string text = formatStorage(s, [] {
    StorageWriteOptions o;
    o.description = "made by a test";
    return o;
  }());
  std::ifstream in(p);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(written, text);
  EXPECT_NE(written.find("made by a test\n"), std::string::npos) << written;
  EXPECT_LE((readStorage(p).data - s.data).cwiseAbs().maxCoeff(), 5e-9);
  // full precision: %.16e, so the tiny value and all digits survive
  writeResultStorage(p, s, true);
  const Storage r = readStorage(p);
  EXPECT_EQ(r.data(0, 0), s.data(0, 0));
  EXPECT_EQ(r.data(1, 0), s.data(1, 0));
  // a folder that cannot be made is the write's error
  dir.write("file", "x");
  EXPECT_THROW(writeResultStorage(dir.file("file/out.sto"), s, false), ConvertError);
}

}  // namespace
}  // namespace redmax::osim
