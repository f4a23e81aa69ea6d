// TRC marker files (converter/trc_file.hpp): values in metres from mm and m files, gaps kept as
// gaps, OpenSim's header checks, and every malformed variant an error naming FILE:LINE.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "converter/trc_file.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using test::TempDir;

const std::string kKeys =
    "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n";

// two markers, three rows; B has a gap in the second row (empty fields), the file's own tabbing
std::string trc(const std::string& units, const std::string& counts = "3\t2") {
  return "PathFileType\t4\t(X/Y/Z)\ttrial.trc\n" + kKeys + "100\t100\t" + counts + "\t" + units +
         "\t100\t1\t3\n"
         "Frame#\tTime\tA\t\t\tB\t\t\t\n"
         "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\t\n"
         "\n"
         "1\t0\t1\t2\t3\t4\t5\t6\t\n"
         "2\t0.01\t1.5\t2.5\t3.5\t\t\t\t\n"
         "3\t0.02\t2\t3\t4\t7\t8\t9\n";
}

TEST(TrcFile, ReadsMillimetresAndMetresWithGaps) {
  TempDir dir;
  for (const std::string units : {"mm", "m"}) {
    SCOPED_TRACE(units);
    const double s = units == "mm" ? 1e-3 : 1.0;
    const MarkerTable t = readTrc(dir.write("trial.trc", trc(units)));
    EXPECT_EQ(t.markers, (std::vector<std::string>{"A", "B"}));
    EXPECT_EQ(t.units, units);
    EXPECT_EQ(t.time, (std::vector<double>{0.0, 0.01, 0.02}));
    EXPECT_EQ(t.frame, (std::vector<int>{1, 2, 3}));
    EXPECT_EQ(t.data_rate, 100.0);
    EXPECT_EQ(t.label_line, 4);
    EXPECT_EQ(t.first_data_line, 7);
    EXPECT_EQ(t.findMarker("B"), 1);
    EXPECT_EQ(t.findMarker("C"), -1);
    EXPECT_EQ(t.position(0, 1), Vec3(4, 5, 6) * s);
    EXPECT_EQ(t.position(1, 0), Vec3(1.5, 2.5, 3.5) * s);
    EXPECT_EQ(t.position(2, 1), Vec3(7, 8, 9) * s);
    EXPECT_TRUE(t.present(1, 0));
    EXPECT_FALSE(t.present(1, 1));  // the gap
    EXPECT_TRUE(std::isnan(t.data(1, 3)));
    EXPECT_TRUE(t.warnings.empty());
  }
}

TEST(TrcFile, WritesWhatItReads) {
  TempDir dir;
  const MarkerTable t = readTrc(dir.write("trial.trc", trc("mm")));
  for (const std::string units : {"mm", "m"}) {
    SCOPED_TRACE(units);
    const std::string again = dir.write("again_" + units + ".trc", formatTrc(t, units));
    const MarkerTable u = readTrc(again);
    EXPECT_EQ(u.markers, t.markers);
    EXPECT_EQ(u.time, t.time);
    EXPECT_EQ(u.units, units);
    for (int r = 0; r < t.numRows(); ++r)
      for (int k = 0; k < t.numMarkers(); ++k) {
        ASSERT_EQ(u.present(r, k), t.present(r, k)) << r << " " << k;
        if (t.present(r, k)) {
          EXPECT_LE((u.position(r, k) - t.position(r, k)).norm(), 1e-15) << r << " " << k;
        }
      }
  }
  writeTrc(dir.file("w.trc"), t);
  EXPECT_EQ(readTrc(dir.file("w.trc")).numRows(), 3);
}

TEST(TrcFile, NumFramesDisagreeingAndDataAfterABlankLineAreWarnings) {
  TempDir dir;
  std::string text = trc("m", "5\t2");
  text += "\n4\t0.03\t1\t1\t1\t1\t1\t1\n";
  const MarkerTable t = readTrc(dir.write("trial.trc", text));
  EXPECT_EQ(t.numRows(), 3);  // the blank line ends the data, as OpenSim reads it
  ASSERT_EQ(t.warnings.size(), 2u);
  EXPECT_NE(t.warnings[0].find("the data ends at the blank line 10"), std::string::npos) << t.warnings[0];
  EXPECT_NE(t.warnings[1].find("NumFrames=5 but 3 rows"), std::string::npos) << t.warnings[1];
}

// the text with line `line` (1-based) replaced, or removed when `with` is null
std::string editLine(const std::string& text, int line, const char* with) {
  std::string out;
  int n = 1;
  size_t a = 0;
  while (a < text.size()) {
    const size_t b = text.find('\n', a);
    const std::string l = text.substr(a, b - a);
    if (n != line) out += l + "\n";
    else if (with) out += std::string(with) + "\n";
    a = b == std::string::npos ? text.size() : b + 1;
    ++n;
  }
  return out;
}

TEST(TrcFile, MalformedFilesNameTheLine) {
  const std::string good = trc("mm");
  struct Case {
    std::string text;
    int line;
    std::string what;
  };
  const std::vector<Case> cases = {
      {"", 1, "empty file"},
      {editLine(good, 1, "Frame#\tTime"), 1, "PathFileType"},
      {"PathFileType\t4\n" + kKeys, 2, "ends inside the TRC header"},
      {editLine(good, 2, "DataRate\tCameraRate\tNumFrames"), 2, "header keys must be"},
      {editLine(good, 3, "100\t100\t3\t2\tmm"), 3, "has 5 values for the 8 keys"},
      {editLine(good, 3, "100\t100\t3\ttwo\tmm\t100\t1\t3"), 3, "NumMarkers must be a non-negative count"},
      {editLine(good, 3, "100\t100\t3\t-2\tmm\t100\t1\t3"), 3, "NumMarkers must be a non-negative count"},
      {editLine(good, 3, "100\t100\t3\t99999999999\tmm\t100\t1\t3"), 3, "NumMarkers"},
      {editLine(good, 3, "100\t100\t3\t3\tmm\t100\t1\t3"), 4, "NumMarkers=3 but the label line names 2 markers"},
      {editLine(good, 3, "fast\t100\t3\t2\tmm\t100\t1\t3"), 3, "DataRate must be a number"},
      {editLine(good, 3, "100\t100\t3\t2\tinches\t100\t1\t3"), 3, "Units must be mm, cm or m"},
      {editLine(good, 4, "Time\tA\t\t\tB"), 4, "must start with Frame# and Time"},
      {editLine(good, 4, "Frame#\tTime\tA\t\t\tA"), 4, "marker 'A' is named twice"},
      {editLine(good, 5, "\t\tX1\tY1\tZ1\tX2\tY2"), 5, "has 5 labels"},
      {editLine(good, 5, "\t\tX1\tY1\tZ1\tX2\tZ2\tY2"), 5, "must be 'Y2', found 'Z2'"},
      {editLine(good, 7, "1\t0\t1\t2\t3\t4\t5"), 7, "row has 7 fields, expected 8"},
      {editLine(good, 7, "1\t0\t1\t2\t3\t4\t5\t6\t7\t8"), 7, "row has 10 fields, expected 8"},
      {editLine(good, 8, "2\t0.01\t1.5\tabc\t3.5\t\t\t"), 8, "'abc' (marker 'A') is not a number"},
      {editLine(good, 8, "2\t\t1.5\t2.5\t3.5\t\t\t"), 8, "time '' is not a finite number"},
      {editLine(good, 8, "x\t0.01\t1.5\t2.5\t3.5\t\t\t"), 8, "Frame# 'x' is not a number"},
      {editLine(good, 8, "2\t0\t1.5\t2.5\t3.5\t\t\t"), 8, "does not increase"},
      {editLine(good, 8, "2\t0.01\t1.5\tinf\t3.5\t\t\t"), 8, "infinite"},
      {editLine(editLine(editLine(good, 9, nullptr), 8, nullptr), 7, nullptr), 6, "no data rows"},
  };
  TempDir dir;
  for (const Case& c : cases) {
    const std::string path = dir.write("bad.trc", c.text);
    try {
      readTrc(path);
      ADD_FAILURE() << "no error for: " << c.what;
    } catch (const ConvertError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_EQ(e.line(), c.line) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(path + ":" + std::to_string(c.line) + ": ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.what), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(readTrc(dir.file("missing.trc")), ConvertError);
}

}  // namespace
}  // namespace redmax::osim
