// Work-precision report (validation/work_precision/work_precision.hpp), quick mode: every file is
// written; on the pendulum with a straight (Type I, smooth) muscle each fixed-step integrator's error falls with its step at
// about its order (euler, symplectic, bdf1: 1; sdirk2: 2), the adaptive ones' error falls with the
// tolerance, and rk45 at rtol 1e-8 is within 1e-6 of the reference. Timings are recorded, never
// asserted.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "validation/report/csv.hpp"
#include "validation/report/json_value.hpp"
#include "validation/work_precision/work_precision.hpp"

namespace {

namespace fs = std::filesystem;
using namespace redmax::validation;

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class WorkPrecisionQuick : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("redmax_work_precision_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    WorkPrecisionOptions opt;
    opt.quick = true;
    opt.models_dir = std::string(REDMAX_SOURCE_DIR) + "/osim_models";
    result_ = new WorkPrecisionResult(runWorkPrecision(dir_.string(), opt));
  }
  static void TearDownTestSuite() {
    delete result_;
    result_ = nullptr;
    fs::remove_all(dir_);
  }
  static const WorkPrecisionSceneResult& scene(const std::string& name) {
    for (const auto& s : result_->scenes)
      if (s.name == name) return s;
    throw std::runtime_error("no scene " + name);
  }
  // (value, error) of one integrator's ok runs, ladder order
  static std::map<double, double> errors(const WorkPrecisionSceneResult& s, const std::string& integrator) {
    std::map<double, double> out;
    for (const auto& r : s.runs)
      if (r.integrator == integrator && r.ok) out[r.value] = r.error;
    return out;
  }
  static inline fs::path dir_;
  static inline WorkPrecisionResult* result_ = nullptr;
};

TEST_F(WorkPrecisionQuick, WritesEveryFile) {
  ASSERT_EQ(result_->scenes.size(), workPrecisionSceneNames().size());
  EXPECT_EQ(result_->scenes.size(), 5u);
  for (const auto& name : workPrecisionSceneNames()) {
    const fs::path csv = dir_ / (name + ".csv");
    ASSERT_TRUE(fs::is_regular_file(csv)) << csv;
    const CsvTable t = parseCsv(readText(csv));
    // 6 integrators x 3 rungs
    EXPECT_EQ(t.rows.size(), 18u) << name;
    EXPECT_EQ(t.header.front(), "integrator");
    if (!result_->files.plots_skipped) {
      EXPECT_TRUE(fs::is_regular_file(dir_ / (name + ".png")) || fs::is_regular_file(dir_ / (name + ".svg"))) << name;
    }
  }
  const std::string md = readText(dir_ / "report.md");
  EXPECT_NE(md.find("Recommended for error <= 0.001"), std::string::npos);
  EXPECT_NE(md.find("Scene running_leg"), std::string::npos);
  EXPECT_NE(md.find("Scene pendulum_wrap"), std::string::npos);
  // the cross-scene summary comes before the scenes
  EXPECT_LT(md.find("Recommended defaults"), md.find("Scene pendulum_straight"));
  // the hard study's tables: the flick (quick: euler at 1 ms, lumped and inertial) and one row per
  // wrap contact change of each path model
  ASSERT_TRUE(fs::is_regular_file(dir_ / "hard_flick.csv"));
  EXPECT_EQ(parseCsv(readText(dir_ / "hard_flick.csv")).rows.size(), 2u);
  ASSERT_TRUE(fs::is_regular_file(dir_ / "hard_wrap_jumps.csv"));
  EXPECT_GE(parseCsv(readText(dir_ / "hard_wrap_jumps.csv")).rows.size(), 8u);
  const JsonValue summary = JsonValue::parse(readText(dir_ / "summary.json"));
  ASSERT_TRUE(summary.contains("work_precision"));
  EXPECT_TRUE(summary.at("work_precision").contains("finger"));
  if (result_->files.plots_skipped) std::printf("plots skipped: %s\n", result_->files.plots_note.c_str());
}

TEST_F(WorkPrecisionQuick, FixedStepErrorsFallAtTheirOrderOnTheStraightMusclePendulum) {
  const auto& s = scene("pendulum_straight");
  for (const auto& [integrator, order] : std::map<std::string, double>{{"euler", 1}, {"symplectic", 1}, {"bdf1", 1}, {"sdirk2", 2}}) {
    const auto e = errors(s, integrator);
    ASSERT_EQ(e.size(), 3u) << integrator << " diverged on the pendulum";
    const double e_small = e.begin()->second, e_large = e.rbegin()->second;
    const double slope = std::log(e_large / e_small) / std::log(e.rbegin()->first / e.begin()->first);
    std::printf("[work-precision] pendulum %s: observed order %.3f (errors %.3e .. %.3e)\n", integrator.c_str(), slope,
                e_large, e_small);
    EXPECT_GT(slope, 0.75 * order) << integrator;
    EXPECT_LT(slope, 1.5 * order) << integrator;
  }
}

TEST_F(WorkPrecisionQuick, AdaptiveErrorsFallWithTheTolerance) {
  const auto& s = scene("pendulum_straight");
  for (const std::string integrator : {"rk45", "cvode"}) {
    const auto e = errors(s, integrator);
    ASSERT_EQ(e.size(), 3u) << integrator;
    // tighter by 1e4 in rtol: at least 100x smaller error
    EXPECT_LT(e.at(1e-8), 1e-2 * e.at(1e-4)) << integrator;
  }
  EXPECT_LT(errors(s, "rk45").at(1e-8), 1e-6);
}

TEST_F(WorkPrecisionQuick, RecommendationsMeetTheirTargets) {
  for (const auto& s : result_->scenes) {
    ASSERT_EQ(s.recommended.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
      const double target = k == 0 ? 1e-3 : 1e-6;
      // 1e-3 is within reach of the quick ladders on every scene; 1e-6 may not be (then -1)
      if (k == 0) {
        ASSERT_GE(s.recommended[k], 0) << s.name << " target " << target;
      }
      if (s.recommended[k] < 0) {
        for (const auto& other : s.runs) {
          EXPECT_FALSE(other.ok && other.error <= target) << s.name;
        }
        continue;
      }
      const auto& r = s.runs[s.recommended[k]];
      EXPECT_TRUE(r.ok);
      EXPECT_LE(r.error, target);
      for (const auto& other : s.runs) {
        if (other.ok && other.error <= target) {
          EXPECT_LE(r.cpu_s, other.cpu_s);
        }
      }
    }
  }
}

TEST_F(WorkPrecisionQuick, EnergyDriftOnTheConservativePendulum) {
  const auto& s = scene("pendulum_straight");
  // the reference (rk45, rtol 1e-12) conserves energy; first-order methods drift about in
  // proportion to the step, sdirk2 about with its square
  EXPECT_LT(s.reference_energy_drift, 1e-9);
  for (const auto& [integrator, order] : std::map<std::string, double>{{"euler", 1}, {"sdirk2", 2}}) {
    std::map<double, double> drift;
    for (const auto& r : s.runs)
      if (r.integrator == integrator && r.ok) drift[r.value] = r.energy_drift;
    ASSERT_EQ(drift.size(), 3u);
    const double slope = std::log(drift.rbegin()->second / drift.begin()->second) /
                         std::log(drift.rbegin()->first / drift.begin()->first);
    EXPECT_GT(slope, 0.75 * order) << integrator;
    EXPECT_LT(slope, 1.5 * order) << integrator;
  }
}

TEST_F(WorkPrecisionQuick, FailedRunsAreMarkedWithWhereTheyStopped) {
  for (const auto& name : workPrecisionSceneNames()) {
    const CsvTable t = parseCsv(readText(dir_ / (name + ".csv")));
    const auto& s = scene(name);
    ASSERT_EQ(t.rows.size(), s.runs.size());
    for (std::size_t i = 0; i < s.runs.size(); ++i) {
      EXPECT_EQ(t.rows[i][3], s.runs[i].ok ? "ok" : "diverged") << name << " row " << i;
      if (!s.runs[i].ok) {
        EXPECT_NE(s.runs[i].failure.find("t = "), std::string::npos) << s.runs[i].failure;
      }
    }
  }
}

TEST(WorkPrecision, UnknownNamesAreRejected) {
  WorkPrecisionOptions opt;
  opt.models_dir = std::string(REDMAX_SOURCE_DIR) + "/osim_models";
  opt.scenes = {"nope"};
  EXPECT_THROW(runWorkPrecision((fs::temp_directory_path() / "redmax_wp_unused").string(), opt), std::invalid_argument);
  opt.scenes = {};
  opt.integrators = {"rk4"};
  EXPECT_THROW(runWorkPrecision((fs::temp_directory_path() / "redmax_wp_unused").string(), opt), std::invalid_argument);
  EXPECT_FALSE(fs::exists(fs::temp_directory_path() / "redmax_wp_unused"));
}

}  // namespace
