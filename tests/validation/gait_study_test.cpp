// The gait study (validation/gait_study.hpp) on the running leg, a few frames: the generated
// reserves and residuals, the runs (zero, physiological, a transfer sweep), the transfer of
// fraction 0 equal to zero mass exactly, muscle mass changing the forces, and the report's files.
#include "validation/gait_study.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <unistd.h>

#include "converter/build/muscle_mass.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;

TEST(GaitStudy, RunningLegFewFrames) {
  const fs::path dir = fs::temp_directory_path() / ("redmax_gait_study_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  GaitStudyOptions opt;
  opt.trial.model_file = std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg.osim";
  opt.trial.coordinates_file = std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg_swing.mot";
  opt.trial.t0 = 0.1;
  opt.trial.t1 = 0.125;  // 6 rows of the 200 Hz swing
  opt.transfer_body = "tibia_r";
  opt.transfer_values = {0.5};
  const GaitStudyResult res = runGaitStudy(opt, (dir / "setup").string());
  EXPECT_TRUE(fs::exists(res.setup_file));
  EXPECT_TRUE(fs::exists(res.reserves_file));
  ASSERT_EQ(res.reserves.size(), 11u);
  EXPECT_EQ(res.reserves[0], "pelvis_tilt_residual");
  EXPECT_EQ(res.reserves[6], "hip_flexion_r_reserve");
  ASSERT_EQ(res.runs.size(), 4u);  // zero, physiological, transfer 0, transfer 0.5
  EXPECT_EQ(res.runs[2].label, "transfer 0");
  EXPECT_EQ(res.runs[0].muscle_mass, 0.0);
  // the library default keeps wrapping muscles lumped (wrap_mass off; the command line turns it on):
  // the physiological run carries density * F_max / specific tension * l_opt of the others only
  // (measured 0.470 kg of the four muscles' 0.712 kg)
  double expected = 0.0;
  for (const osim::PathForceDesc& m : osim::readOsimModel(opt.trial.model_file).muscles)
    if (m.is_muscle && m.wraps.empty())
      expected += osim::kDefaultMuscleDensity * m.max_isometric_force / osim::kDefaultSpecificTension *
                  m.optimal_fiber_length;
  EXPECT_NEAR(res.runs[1].muscle_mass, expected, 1e-12 * expected);
  EXPECT_EQ(res.frames, 6);
  for (const auto& r : res.runs) EXPECT_EQ(r.so.failed, 0) << r.label;
  ASSERT_EQ(res.muscles.size(), 4u);
  double changed = 0.0;
  for (const auto& m : res.muscles) {
    EXPECT_EQ(m.force_integral[2], m.force_integral[0]) << m.name;  // fraction 0: no mass moved
    changed = std::max(changed, std::abs(relativeChange(m.force_integral[3], m.force_integral[0])));
  }
  EXPECT_GT(changed, 1e-3);  // half the tibia moved into the muscles changes some muscle's force

  ReportOptions ro;
  ro.gnuplot = "none";
  Report report((dir / "report").string(), ro);
  addGaitStudy(res, opt, report);
  report.write();
  EXPECT_TRUE(report.passed());
  EXPECT_TRUE(fs::exists(dir / "report" / "summary.json"));
  EXPECT_TRUE(fs::exists(dir / "report" / "muscles.csv"));
  EXPECT_TRUE(fs::exists(dir / "report" / "runs.csv"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace redmax::validation
