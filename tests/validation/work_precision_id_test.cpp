// The inverse-dynamics studies of the work-precision report (validation/work_precision/id_studies.hpp),
// quick mode (the running leg): the files are written; the error against 500 points per muscle falls
// with N and by more than 2x from N = 10 to N = 20 (mass points at cell midpoints: a midpoint-rule
// quadrature, O(1/N^2) on smooth stretches); K = all reproduces all muscles with mass exactly and
// K = 0 the zero-mass torques exactly. The error metric is checked on a closed-form case. Timings are
// recorded, never asserted.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "validation/report/csv.hpp"
#include "validation/report/json_value.hpp"
#include "validation/work_precision/id_studies.hpp"
#include "validation/work_precision/work_precision.hpp"

namespace {

namespace fs = std::filesystem;
using namespace redmax::validation;
using redmax::MatX;

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class WorkPrecisionIdQuick : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("redmax_work_precision_id_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    WorkPrecisionOptions opt;
    opt.quick = true;
    opt.models_dir = std::string(REDMAX_SOURCE_DIR) + "/osim_models";
    opt.studies = {"masspoints", "reduction"};
    result_ = new WorkPrecisionResult(runWorkPrecision(dir_.string(), opt));
  }
  static void TearDownTestSuite() {
    delete result_;
    result_ = nullptr;
    fs::remove_all(dir_);
  }
  static const IdStudyRow& pointsRow(int n) {
    for (const auto& r : result_->id_studies.masspoints)
      if (r.value == n) return r;
    throw std::runtime_error("no row N = " + std::to_string(n));
  }
  static inline fs::path dir_;
  static inline WorkPrecisionResult* result_ = nullptr;
};

TEST_F(WorkPrecisionIdQuick, WritesTheFiles) {
  const auto& id = result_->id_studies;
  EXPECT_TRUE(result_->scenes.empty()) << "the integrators study was not asked for";
  ASSERT_TRUE(id.has_masspoints);
  ASSERT_TRUE(id.has_reduction);
  EXPECT_EQ(id.trial.name, "running leg");
  const CsvTable mp = parseCsv(readText(dir_ / "id_masspoints.csv"));
  EXPECT_EQ(mp.header.front(), "points_per_muscle");
  EXPECT_EQ(mp.rows.size(), id.masspoints.size() + 1);  // + the reference
  EXPECT_EQ(mp.rows.back().front(), "500");
  const CsvTable red = parseCsv(readText(dir_ / "id_reduction.csv"));
  EXPECT_EQ(red.rows.size(), id.reduction.size());
  EXPECT_EQ(red.rows.back().front(), "all");
  const CsvTable rank = parseCsv(readText(dir_ / "id_reduction_ranking.csv"));
  EXPECT_EQ(rank.rows.size(), id.ranking.size());
  EXPECT_GE(id.ranking.size(), 2u);  // soleus_r and tib_ant_r (the gastrocnemii wrap)
  if (!result_->files.plots_skipped) {
    for (const char* stem : {"id_masspoints", "id_reduction"})
      EXPECT_TRUE(fs::is_regular_file(dir_ / (std::string(stem) + ".png")) ||
                  fs::is_regular_file(dir_ / (std::string(stem) + ".svg")))
          << stem;
  }
  const std::string md = readText(dir_ / "report.md");
  EXPECT_NE(md.find("ID study: mass points per muscle"), std::string::npos);
  EXPECT_NE(md.find("Recommended points per muscle"), std::string::npos);
  EXPECT_NE(md.find("ID study: model reduction"), std::string::npos);
  const JsonValue summary = JsonValue::parse(readText(dir_ / "summary.json"));
  ASSERT_TRUE(summary.contains("id_studies"));
  EXPECT_TRUE(summary.at("id_studies").contains("masspoints"));
  EXPECT_TRUE(summary.at("id_studies").contains("reduction"));
}

TEST_F(WorkPrecisionIdQuick, ErrorFallsWithMassPoints) {
  const auto& id = result_->id_studies;
  ASSERT_GE(id.masspoints.size(), 4u);
  for (size_t i = 1; i < id.masspoints.size(); ++i) {
    EXPECT_LT(id.masspoints[i].error.err_effect, id.masspoints[i - 1].error.err_effect)
        << "N = " << id.masspoints[i].value;
    EXPECT_LT(id.masspoints[i].error.err_peak, id.masspoints[i - 1].error.err_peak) << "N = " << id.masspoints[i].value;
  }
  const double e10 = pointsRow(10).error.err_effect, e20 = pointsRow(20).error.err_effect;
  std::printf("[ measured ] running leg: error / inertial effect N=10 %.3e, N=20 %.3e, ratio %.2f\n", e10, e20,
              e10 / e20);
  // midpoint rule: about 4 on smooth stretches; 2 would be first order
  EXPECT_GT(e10 / e20, 2.0);
  // the mass is there: the reference differs from the zero-mass torques
  EXPECT_GT((id.reference.tau - id.tau_0).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(id.reference.error.err_effect, 0.0);
}

TEST_F(WorkPrecisionIdQuick, ReductionEndsExact) {
  const auto& id = result_->id_studies;
  ASSERT_GE(id.reduction.size(), 2u);
  const IdStudyRow& k0 = id.reduction.front();
  const IdStudyRow& kall = id.reduction.back();
  EXPECT_EQ(k0.value, 0);
  EXPECT_EQ(k0.muscles_with_mass, 0);
  // K = 0: exactly the zero-mass torques, so exactly 100% of the inertial effect
  EXPECT_EQ((k0.tau - id.tau_0).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(k0.error.err_effect, 1.0);
  // K = all: every candidate in ranking order gives exactly all muscles with mass
  EXPECT_EQ(kall.label, "all");
  EXPECT_EQ(kall.muscles_with_mass, id.all_muscles.muscles_with_mass);
  EXPECT_EQ((kall.tau - id.all_muscles.tau).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(kall.error.err_effect, 0.0);
  EXPECT_EQ(kall.error.err_peak, 0.0);
}

// closed form: reference = zero + effect, result = reference + delta
TEST(IdStudyError, ClosedForm) {
  MatX tau0(3, 2), effect(3, 2), delta(3, 2);
  tau0 << 10, 1, -20, 2, 5, 0;
  effect << 0.5, 0, -2, 0, 1, 0;  // column 1 has no inertial effect
  delta << 0.01, 0.3, -0.04, 0, 0, 0;
  const MatX ref = tau0 + effect;
  const IdStudyError e = calcIdStudyError(ref + delta, ref, tau0, {"a", "b"});
  EXPECT_NEAR(e.err_effect, 0.04 / 2.0, 1e-15);   // column b is left out
  EXPECT_EQ(e.worst_column, "a");
  EXPECT_NEAR(e.err_peak, 0.3 / 2.0, 1e-15);      // column b: 0.3 of its peak 2
  EXPECT_THROW(calcIdStudyError(ref, ref.topRows(2), tau0, {"a", "b"}), std::invalid_argument);
}

TEST(IdStudies, UnknownStudyIsRejected) {
  WorkPrecisionOptions opt;
  opt.models_dir = std::string(REDMAX_SOURCE_DIR) + "/osim_models";
  opt.studies = {"masspoint"};
  EXPECT_THROW(runWorkPrecision((fs::temp_directory_path() / "redmax_wp_id_never").string(), opt),
               std::invalid_argument);
  EXPECT_FALSE(fs::exists(fs::temp_directory_path() / "redmax_wp_id_never" / "summary.json"));
}

}  // namespace
