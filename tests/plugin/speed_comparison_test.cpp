// The speed-comparison harness behind dynamics_bench and `redmax bench`: what it runs and writes,
// never how fast (no timing assertions). Also the benchmark scenes themselves.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <Eigen/Eigenvalues>

#include "core/integrators/integrator.hpp"
#include "plugin/simbody/speed_comparison.hpp"
#include "validation/scenes/humanoid.hpp"

namespace redmax {
namespace {

namespace fs = std::filesystem;
using simbody::SpeedComparison;
using simbody::SpeedOptions;
using simbody::SpeedRow;

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("redmax_speed_test_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(BenchScenes, HumanoidHasTheDocumentedShape) {
  const Model m = scenes::humanoid();
  EXPECT_EQ(m.nb(), 17);
  EXPECT_EQ(m.nr(), 37);
  double total = 0.0;
  for (const auto& b : m.bodies()) total += b.mass;
  EXPECT_NEAR(total, 77.3, 1e-9);
  // pelvis height default, and every spatial inertia positive definite
  EXPECT_EQ(m.coordinates()[4].name, "pelvis_ty");
  EXPECT_DOUBLE_EQ(m.defaultQ()[4], 0.94);
  for (const auto& b : m.bodies()) EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat6>(b.M).eigenvalues().minCoeff(), 0.0) << b.name;
  // left and right limbs mirror each other: same masses, coordinates named per side
  EXPECT_GE(m.findCoordinate("knee_angle_r"), 0);
  EXPECT_GE(m.findCoordinate("knee_angle_l"), 0);
}

TEST(BenchScenes, LimbChainRejectsEmpty) {
  EXPECT_EQ(scenes::limbChain(4).nr(), 4);
  EXPECT_THROW(scenes::limbChain(0), ModelError);
}

TEST(SpeedComparison, RunsEveryOperationOnBothSides) {
  SpeedOptions opt;
  opt.reset_every = 3;
  SpeedComparison cmp("humanoid", scenes::humanoid(), opt);
  EXPECT_EQ(cmp.dof(), 37);
  std::set<std::string> names;
  for (const auto& op : cmp.ops()) names.insert(op.name);
  for (const char* n : {"kinematics", "mass_matrix", "id_redmax", "id_recursive", "forward_dynamics"})
    EXPECT_TRUE(names.count(n)) << n;
  // every integrator makeIntegrator accepts is timed; the others are listed as skipped
  for (const auto& integ : opt.integrators) {
    bool available = true;
    try {
      (void)makeIntegrator(integ, IntegratorOptions{});
    } catch (const std::exception&) {
      available = false;
    }
    EXPECT_EQ(names.count("step_" + integ), available ? 1u : 0u) << integ;
  }
  EXPECT_EQ(cmp.ops().size(), 5 + opt.integrators.size() - cmp.skipped().size());

  // a few calls each (more than reset_every, so the restart path runs)
  const auto rows = simbody::timeSpeedComparison(cmp, 4, 2);
  ASSERT_EQ(rows.size(), cmp.ops().size());
  for (const SpeedRow& r : rows) {
    EXPECT_TRUE(std::isfinite(r.redmax_us) && r.redmax_us > 0.0) << r.op << ": " << r.note;
    EXPECT_TRUE(std::isfinite(r.simbody_us) && r.simbody_us > 0.0) << r.op << ": " << r.note;
    EXPECT_TRUE(std::isfinite(r.ratio())) << r.op;
    EXPECT_EQ(r.scene, "humanoid");
    EXPECT_EQ(r.dof, 37);
    if (r.op.rfind("step_", 0) == 0) {
      EXPECT_NE(r.note.find("internal steps per call"), std::string::npos);
    }
  }
}

TEST(SpeedComparison, UnknownIntegratorIsSkippedAndAFailingSideIsReported) {
  SpeedOptions opt;
  opt.integrators = {"euler", "no-such-method"};
  SpeedComparison cmp("chain3", scenes::limbChain(3), opt);
  ASSERT_EQ(cmp.skipped().size(), 1u);
  EXPECT_NE(cmp.skipped()[0].find("no-such-method"), std::string::npos);
  // an op whose core side throws: NaN and the message, the Simbody side still timed
  cmp.ops().push_back({"broken", "throws", "works", [] { throw std::runtime_error("boom"); }, [] {}, nullptr});
  const auto rows = simbody::timeSpeedComparison(cmp, 2, 1);
  const SpeedRow& bad = rows.back();
  EXPECT_EQ(bad.op, "broken");
  EXPECT_TRUE(std::isnan(bad.redmax_us));
  EXPECT_TRUE(std::isfinite(bad.simbody_us));
  EXPECT_TRUE(std::isnan(bad.ratio()));
  EXPECT_NE(bad.note.find("boom"), std::string::npos);
  const std::string table = simbody::formatSpeedTable(rows);
  EXPECT_NE(table.find("failed"), std::string::npos);
  EXPECT_NE(table.find("boom"), std::string::npos);
  EXPECT_THROW(simbody::timeSpeedComparison(cmp, 0, 1), std::invalid_argument);
  EXPECT_THROW(simbody::timeSpeedComparison(cmp, 1, 0), std::invalid_argument);
}

TEST(SpeedComparison, TableAndJsonHaveOneEntryPerRow) {
  std::vector<SpeedRow> rows = {{"chain5", 5, "mass_matrix", "a", "b \"quoted\"", 2.0, 4.0, ""},
                                {"chain5", 5, "step_rk45", "c", "d", NAN, 1.0, "redmax failed: x"}};
  EXPECT_DOUBLE_EQ(rows[0].ratio(), 0.5);
  const std::string table = simbody::formatSpeedTable(rows);
  EXPECT_NE(table.find("ratio"), std::string::npos);
  EXPECT_NE(table.find("0.500"), std::string::npos);
  EXPECT_NE(table.find("step_rk45"), std::string::npos);

  const fs::path dir = tempDir("json");
  const fs::path out = dir / "speed.json";
  simbody::writeSpeedJson(rows, out.string());
  const std::string js = readFile(out);
  EXPECT_NE(js.find("\"rows\""), std::string::npos);
  EXPECT_NE(js.find("\"ratio\": 0.5"), std::string::npos);
  EXPECT_NE(js.find("\"redmax_us\": null"), std::string::npos);  // NaN is not JSON
  EXPECT_NE(js.find("b \\\"quoted\\\""), std::string::npos);
  std::size_t count = 0;
  for (std::size_t p = js.find("\"operation\""); p != std::string::npos; p = js.find("\"operation\"", p + 1)) ++count;
  EXPECT_EQ(count, rows.size());
  // nothing but the output is left in the folder (the temporary file was renamed)
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  // an unwritable target fails with its path in the message and writes nothing
  const std::string bad = (dir / "missing" / "speed.json").string();
  try {
    simbody::writeSpeedJson(rows, bad);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "missing"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace redmax
