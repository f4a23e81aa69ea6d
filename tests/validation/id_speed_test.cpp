// validation/id_speed: both engines are timed on the same frames of a real trial; where Debian's
// Simbody rejects an inertia (set E) both engines get OpenSim's fallback, and the note says so.
// No timing is asserted, only that the measurement covers what it claims.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "converter/storage.hpp"
#include "validation/id_speed.hpp"

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;
std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }

TEST(IdSpeed, SetEBothEnginesWithTheFallbackInertia) {
  const std::string setup = shared("opensim-models/Pipelines/Gait2392_Simbody/subject01_Setup_InverseDynamics.xml");
  const std::string model = shared("opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim");
  const std::string ref = shared("opensim-4.6-results/E.sto");
  for (const auto& f : {setup, model, ref})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  IdSpeedOptions o;
  o.settings.setup_file = setup;
  o.settings.model_file = model;
  o.batches = 1;
  const IdSpeedResult r = timeIdEngines(o);
  // the frames timed are the frames OpenSim 4.6 wrote
  EXPECT_EQ(r.frames, osim::readStorage(ref).numRows());
  EXPECT_EQ(r.dofs, 23);
  EXPECT_GT(r.core_us_per_frame, 0.0);
  EXPECT_GT(r.simbody_us_per_frame, 0.0) << r.simbody_note;
  EXPECT_NE(r.simbody_note.find("toes_r"), std::string::npos) << r.simbody_note;
  EXPECT_GE(r.whole_run_seconds, r.setup_seconds);
  const std::string table = formatIdSpeed(r);
  EXPECT_NE(table.find("ratio core/Simbody"), std::string::npos) << table;
  std::printf("[ measured ] %s", table.c_str());
}

TEST(IdSpeed, BadSetupIsAConvertError) {
  IdSpeedOptions o;
  o.settings.setup_file = "/nonexistent/setup.xml";
  EXPECT_THROW(timeIdEngines(o), osim::ConvertError);
}

}  // namespace
}  // namespace redmax::validation
