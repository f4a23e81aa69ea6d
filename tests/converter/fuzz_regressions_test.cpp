// The fuzz seeds (fuzz/corpus/<reader>/) and inputs the fuzzers derived from them.
//  - Every seed is valid and reads with the counts written in it (counted here by hand), so the
//    fuzzers start from inputs that reach the deep code (builder, functions, loads, setup merge).
//  - Mutations of the kinds the fuzz driver makes (non-finite and overflowing numbers, negative
//    counts, broken orders, truncation) give a ConvertError naming the file and line with the exact
//    message below. Inputs that once crashed a reader are added here with their error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "converter/build/build_core_model.hpp"
#include "converter/external_loads.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/id_setup.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

namespace fs = std::filesystem;

std::string corpus(const std::string& rel) {
  return std::string(REDMAX_SOURCE_DIR) + "/fuzz/corpus/" + rel;
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// text with the first occurrence of `from` replaced by `to` (the test fails if it is absent)
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the seed";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// `call(path)` must throw a ConvertError whose what() is exactly "path:line: message"
template <class Call>
void expectExactError(const test::TempDir& dir, const std::string& name, const std::string& text,
                      int line, const std::string& message, Call call) {
  const std::string path = dir.write(name, text);
  try {
    call(path);
    ADD_FAILURE() << "no error; expected " << message;
  } catch (const ConvertError& e) {
    const std::string expected = path + (line > 0 ? ":" + std::to_string(line) : "") + ": " + message;
    EXPECT_EQ(std::string(e.what()), expected);
  }
}

// ---- seeds ------------------------------------------------------------------------------------

TEST(FuzzSeeds, OsimSeedsReadAndBuild) {
  struct Seed {
    const char* file;
    int bodies, dofs, muscles, constraints, version;
  };
  // counted from the files: all_joints has bodies a..k (10) and joints with 2+1+1+3+3+2+3+3+6+0
  // coordinates, three path forces (two muscles and a PathSpring) and three constraints
  const Seed seeds[] = {
      {"osim/all_joints_40000.osim", 10, 24, 3, 3, 40000},
      {"osim/legacy_30000.osim", 2, 2, 1, 1, 30000},
      {"osim/legacy_20001.osim", 1, 1, 1, 0, 20001},
      {"osim/legacy_10901.osim", 1, 1, 1, 0, 10901},
  };
  for (const auto& s : seeds) {
    SCOPED_TRACE(s.file);
    const ModelDescription d = readOsimModel(corpus(s.file));
    EXPECT_EQ(static_cast<int>(d.bodies.size()), s.bodies);
    EXPECT_EQ(d.numDofs(), s.dofs);
    EXPECT_EQ(static_cast<int>(d.muscles.size()), s.muscles);
    EXPECT_EQ(static_cast<int>(d.constraints.size()), s.constraints);
    EXPECT_EQ(d.osim_version, s.version);
    const BuildResult r = buildCoreModel(d);
    EXPECT_EQ(r.model.nr(), s.dofs);
    for (const auto& u : r.unsupported) ADD_FAILURE() << u.what;
  }
  // 1.x: gravity inside the SimbodyEngine
  EXPECT_EQ(readOsimModel(corpus("osim/legacy_10901.osim")).gravity, Vec3(0, 0, -9.81));
}

TEST(FuzzSeeds, StorageSeedsRead) {
  struct Seed {
    const char* file;
    int rows, columns;
    bool degrees;
  };
  const Seed seeds[] = {
      {"storage/v1_degrees.mot", 3, 3, true},   {"storage/legacy_flow.sto", 3, 2, false},
      {"storage/simm_range.mot", 3, 2, true},   {"storage/v3_tabs.sto", 3, 3, false},
      {"storage/id_output.sto", 2, 2, false},   {"storage/grf_datacolumns.mot", 2, 6, true},
  };
  for (const auto& s : seeds) {
    SCOPED_TRACE(s.file);
    const Storage st = readStorage(corpus(s.file));
    EXPECT_EQ(st.numRows(), s.rows);
    EXPECT_EQ(st.numColumns(), s.columns);
    EXPECT_EQ(st.in_degrees, s.degrees);
  }
}

// the external-loads seeds carry their data file after a separator line (fuzz/external_loads_fuzz)
TEST(FuzzSeeds, ExternalLoadsSeedsReadWithTheirData) {
  const std::string sep = "\n#REDMAX-DATAFILE#\n";
  struct Seed {
    const char* file;
    int forces;
    bool torque;
  };
  for (const Seed s : {Seed{"external_loads/two_forces.xml", 2, true},
                       Seed{"external_loads/v30_force_only.xml", 1, false}}) {
    SCOPED_TRACE(s.file);
    const std::string text = slurp(corpus(s.file));
    const size_t cut = text.find(sep);
    ASSERT_NE(cut, std::string::npos);
    test::TempDir dir;
    const std::string xml = dir.write("loads.xml", text.substr(0, cut));
    dir.write("data.mot", text.substr(cut + sep.size()));
    const ExternalLoads l = readExternalLoads(xml, dir.str());
    ASSERT_EQ(static_cast<int>(l.forces.size()), s.forces);
    EXPECT_TRUE(l.forces[0].hasForce());
    EXPECT_EQ(l.forces[0].hasTorque(), s.torque);
    EXPECT_EQ(l.forces[0].applied_to_body, "a");
  }
}

TEST(FuzzSeeds, IdSetupSeedsResolve) {
  const InverseDynamicsSetup s = readInverseDynamicsSetup(corpus("id_setup/full_setup.xml"));
  const std::string dir = corpus("id_setup");
  EXPECT_EQ(s.model_file, resolveRelativeTo(dir, "model/subject01.osim"));
  EXPECT_EQ(s.coordinates_file, "/abs/path/subject01_ik.mot");  // absolute paths are kept
  EXPECT_EQ(s.time_start, 0.4);
  EXPECT_EQ(s.time_end, 1.6);
  EXPECT_EQ(s.lowpass_cutoff_frequency_for_coordinates, 6.0);
  for (const char* f : {"id_setup/legacy_setup.xml", "id_setup/minimal_setup.xml"}) {
    IdToolSettings settings;
    settings.setup_file = corpus(f);
    EXPECT_NO_THROW((void)resolveIdSettings(settings)) << f;
  }
}

// ---- fuzz-derived malformed inputs --------------------------------------------------------------

TEST(FuzzRegressions, OsimNumbersThatAreNotFiniteOrOverflow) {
  const std::string seed = slurp(corpus("osim/all_joints_40000.osim"));
  test::TempDir dir;
  auto read = [](const std::string& p) { (void)readOsimModel(p); };
  auto build = [](const std::string& p) { (void)buildCoreModel(readOsimModel(p)); };
  expectExactError(dir, "nan_mass.osim", replaced(seed, "<mass>1.5</mass>", "<mass>nan</mass>"), 11,
                   "body 'a' has an invalid mass nan", read);
  expectExactError(dir, "inf_mass.osim", replaced(seed, "<mass>1.5</mass>", "<mass>inf</mass>"), 11,
                   "body 'a' has an invalid mass inf", read);
  // strtod overflow (ERANGE) is not a number, not infinity
  expectExactError(dir, "big_mass.osim", replaced(seed, "<mass>1.5</mass>", "<mass>1e400</mass>"),
                   11, "<mass>: '1e400' is not a number", read);
  // a NaN inertia passes the reader (OpenSim reads it too) and is refused by the builder
  expectExactError(dir, "nan_inertia.osim",
                   replaced(seed, "<inertia>0.01 0.02 0.03", "<inertia>nan 0.02 0.03"), 11,
                   "body 'a': mass must be finite and >= 0, mass_center and inertia finite", build);
  expectExactError(dir, "gcv_nan.osim", replaced(seed, "<x>-2 -1 0 1 2 3</x>", "<x>-2 -1 0 nan 2 3</x>"),
                   77, "GCVSpline x must be strictly increasing", read);
  expectExactError(dir, "gcv_order.osim",
                   replaced(seed, "<half_order>3</half_order>", "<half_order>-1</half_order>"), 77,
                   "GCVSpline half_order must be 1..4, found -1", read);
  expectExactError(dir, "gcv_order_big.osim",
                   replaced(seed, "<half_order>3</half_order>", "<half_order>2147483648</half_order>"),
                   77, "<half_order>: '2147483648' is not an integer", read);
  expectExactError(dir, "zero_axis.osim",
                   replaced(seed, "<axis>0 0 1</axis><LinearFunction>", "<axis>0 0 0</axis><LinearFunction>"),
                   41, "TransformAxis 'rotation1' has a zero axis", read);
}

TEST(FuzzRegressions, StorageCountsOutOfRange) {
  test::TempDir dir;
  auto read = [](const std::string& p) { (void)readStorage(p); };
  const std::string body = "endheader\ntime\tq\n0\t1\n";
  expectExactError(dir, "neg.sto", "a\nversion=1\nnRows=-1\nnColumns=2\n" + body, 3,
                   "header 'nRows' needs a non-negative count, found '-1'", read);
  // counts beyond int, and counts whose product would not fit in memory, are refused up front
  expectExactError(dir, "huge.sto", "a\nversion=1\nnRows=99999999999\nnColumns=2\n" + body, 3,
                   "header 'nRows' needs a non-negative count, found '99999999999'", read);
  expectExactError(dir, "product.sto", "a\nversion=1\nnRows=2000000000\nnColumns=2000000000\n" + body,
                   3, "header 'nRows' needs a non-negative count, found '2000000000'", read);
  expectExactError(dir, "labels.sto", "version=3\nendheader\n", 2, "no column labels after endheader",
                   read);
  expectExactError(dir, "empty.sto", "", 0, "no 'endheader' line: not an OpenSim storage file", read);
}

}  // namespace
}  // namespace redmax::osim
