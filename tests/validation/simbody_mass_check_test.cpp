// The engine cross-check with muscle mass in the verdict (validation/mass_sweep.hpp
// addSimbodyMassCheck): a disagreement of core and Simbody with muscle mass fails the report; the
// one case it is only recorded (wrapping muscles with mass over the exact wrap model, whose
// finite-difference Jacobians the engines take in different variables) says why in summary.json.
// End to end on the project's running leg: with the smooth wrap model the check counts and passes;
// with --wrap exact it is recorded, with its reason, and the run still passes.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/validation/pendulum_cli_fixture.hpp"
#include "validation/id_validation.hpp"
#include "validation/mass_sweep.hpp"
#include "validation/report/json_value.hpp"
#include "validation/report/report.hpp"

namespace {

namespace fs = std::filesystem;
using redmax::osim::MuscleMassOptions;
using redmax::validation::JsonValue;
using namespace redmax_test;

redmax::osim::Storage table(double scale) {
  redmax::osim::Storage s;
  s.labels = {"q_moment"};
  s.time = {0.0, 0.5, 1.0};
  s.data.resize(3, 1);
  s.data << 1.0, 2.0 * scale, 3.0;
  return s;
}

class SimbodyMassCheck : public PendulumCliTest {
 protected:
  void SetUp() override { makeDir("redmax_simbody_mass_check_"); }
};

TEST_F(SimbodyMassCheck, ADisagreementFailsTheVerdictUnlessItIsNotCounted) {
  const auto core = table(1.0), simbody = table(1.0 + 1e-6);  // differs by 2e-6 of the peak 3
  redmax::validation::CompareOptions co;
  co.tolerance = {1e-10, 1e-9, 1e-10, 1e-9};
  const auto c = redmax::validation::compareTables("core_mass_vs_simbody_mass", core, "core_mass", simbody,
                                                   "simbody_mass", co);
  ASSERT_FALSE(c.passed);
  {
    redmax::validation::Report counted((dir_ / "counted").string());
    redmax::validation::addSimbodyMassCheck(c, core, simbody, counted);
    EXPECT_FALSE(counted.passed());
  }
  {
    redmax::validation::Report recorded((dir_ / "recorded").string());
    redmax::validation::addSimbodyMassCheck(c, core, simbody, recorded, "a stated reason");
    EXPECT_TRUE(recorded.passed());
  }
  // agreeing engines pass
  const auto same = redmax::validation::compareTables("core_mass_vs_simbody_mass", core, "core_mass", core,
                                                      "simbody_mass", co);
  redmax::validation::Report agree((dir_ / "agree").string());
  redmax::validation::addSimbodyMassCheck(same, core, core, agree);
  EXPECT_TRUE(agree.passed());
  // the reason: the exact wrap model with wrapping muscles carrying mass, nothing else
  MuscleMassOptions o;
  redmax::osim::WrapMassCount w;
  w.wrapping = 2;
  w.with_mass = 2;
  EXPECT_TRUE(redmax::validation::simbodyMassCheckNotCountedReason(o, w).empty());  // smooth by default
  o.wrap.model = redmax::WrapModel::Exact;
  EXPECT_FALSE(redmax::validation::simbodyMassCheckNotCountedReason(o, w).empty());
  w.with_mass = 0;
  EXPECT_TRUE(redmax::validation::simbodyMassCheckNotCountedReason(o, w).empty());
}

TEST_F(SimbodyMassCheck, RunningLegCountsWithTheSmoothModelAndRecordsTheExactOne) {
  const std::string src = std::string(REDMAX_SOURCE_DIR) + "/osim_models/";
  for (const auto model : {redmax::WrapModel::Smooth, redmax::WrapModel::Exact}) {
    const bool exact = model == redmax::WrapModel::Exact;
    SCOPED_TRACE(exact ? "exact" : "smooth");
    redmax::validation::IdValidationOptions opt;
    opt.settings.model_file = src + "running_leg.osim";
    opt.settings.coordinates_file = src + "running_leg_swing.mot";
    opt.report_dir = (dir_ / (exact ? "exact" : "smooth")).string();
    opt.gnuplot = "none";
    opt.muscle_mass.source = MuscleMassOptions::Source::Physiological;
    opt.muscle_mass.wrap_mass = true;  // the gastrocnemii wrap over the condyle
    opt.muscle_mass.wrap.model = model;
    const auto r = redmax::validation::runIdValidation(opt);
    ASSERT_TRUE(r.inertial_effect.simbody_ran) << r.inertial_effect.simbody_skipped;
    EXPECT_TRUE(r.passed);
    const JsonValue s = JsonValue::parse(slurp(fs::path(opt.report_dir) / "summary.json"));
    const JsonValue& check = s.at("simbody_mass_check");
    EXPECT_EQ(check.at("counted_in_verdict").asBool(), !exact);
    EXPECT_EQ(r.inertial_effect.simbody_not_counted.empty(), !exact);
    if (exact) {
      EXPECT_NE(check.at("not_counted_because").asString().find("exact wrap model"), std::string::npos);
    } else {
      EXPECT_TRUE(check.at("agrees").asBool());
    }
    const double worst =
        r.inertial_effect.simbody_check.metrics[static_cast<size_t>(r.inertial_effect.simbody_check.worst)].max_rel;
    std::printf("[ measured ] running leg, physiological, %s wrap model: core vs Simbody with muscle mass max/peak %.3g\n",
                exact ? "exact" : "smooth", worst);
  }
}

}  // namespace
