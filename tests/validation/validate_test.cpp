// `redmax validate` (validation/id_validation.hpp, cli/cmd_validate.cpp): a project-authored
// double pendulum with a closed-form motion and closed-form torques as the reference (runs
// everywhere): the report has every file and passes; a deliberately wrong reference fails with
// exit 1; bad inputs exit 2; Simbody disabled is recorded and core-only still passes; set F
// (gait10dof18musc) passes against OpenSim 4.6's own result when ../shared is present.
// Correctness only; timings are recorded, never asserted.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "converter/storage.hpp"
#include "tests/validation/pendulum_cli_fixture.hpp"
#include "validation/id_validation.hpp"
#include "validation/report/json_value.hpp"
#include "validation/report/plot.hpp"

namespace {

namespace fs = std::filesystem;
using redmax::validation::JsonValue;

using namespace redmax_test;

class Validate : public PendulumCliTest {
 protected:
  void SetUp() override { makeDir("redmax_validate_"); }

  // the closed-form torques as an OpenSim-style reference: every 5th frame of the data grid over
  // 0.4..1.6 s (wider than the trial window, so the overlap is what is compared), columns in
  // another order, an extra column the model lacks; q2 scaled by q2_scale (1 = the true torques)
  void writeReference(const std::string& name, double q2_scale) const {
    std::ostringstream os;
    os.precision(17);
    os << "Inverse Dynamics Generalized Forces\nversion=1\nnRows=121\nnColumns=4\ninDegrees=no\nendheader\n"
          "time\tq2_moment\textra_moment\tq1_moment\n";
    for (int i = 0; i <= 120; ++i) {
      const double t = 0.4 + 0.01 * i;
      const Eigen::Vector2d tau = closedFormTau(t);
      os << t << "\t" << q2_scale * tau(1) << "\t" << 1.0 << "\t" << tau(0) << "\n";
    }
    write(name, os.str());
  }

  JsonValue summary(const std::string& report) const {
    return JsonValue::parse(slurp(dir_ / report / "summary.json"));
  }

};

TEST_F(Validate, PendulumReportHasEveryFileAndPassesAgainstTheClosedForm) {
  if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to validation_tests (build target redmax)";
  writeReference("ref.sto", 1.0);
  const CmdResult r =
      run("validate --model dp.osim --coordinates dp.mot --t0 0.5 --t1 1.5 --reference ref.sto --report rep");
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  // the printed summary: both engines with their speed, each comparison, the verdict
  EXPECT_NE(r.out.find("engine core: 501 frames"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("engine simbody: 501 frames"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("core_vs_simbody: 2 columns"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("core_vs_reference: 2 columns"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("validate: PASS"), std::string::npos) << r.out;

  for (const std::string f : {"summary.json", "report.md", "core_vs_simbody_metrics.csv", "core_vs_simbody_series.csv",
                              "core_vs_reference_metrics.csv", "core_vs_reference_series.csv", "core_id.sto",
                              "simbody_id.sto"})
    EXPECT_TRUE(fs::exists(dir_ / "rep" / f)) << f;
  // plots when gnuplot can draw them (the report says why not otherwise)
  if (redmax::validation::findGnuplot().available) {
    int images = 0;
    for (const auto& e : fs::directory_iterator(dir_ / "rep"))
      if (e.path().extension() == ".png" || e.path().extension() == ".svg") ++images;
    EXPECT_GE(images, 5) << "overlay + difference per comparison, and overlay_all";
  }

  const JsonValue s = summary("rep");
  EXPECT_TRUE(s.at("passed").asBool());
  // speed: frames, seconds, frames per second of each engine
  for (const std::string e : {"core", "simbody"}) {
    const JsonValue& sp = s.at("speed").at(e);
    EXPECT_TRUE(sp.at("ran").asBool()) << e;
    EXPECT_EQ(sp.at("frames").asNumber(), 501) << e;
    EXPECT_GT(sp.at("seconds").asNumber(), 0) << e;
    EXPECT_GT(sp.at("frames_per_second").asNumber(), 0) << e;
  }
  // two comparisons; the reference's extra column is reported, not compared
  const JsonValue& cmps = s.at("comparisons");
  ASSERT_EQ(cmps.size(), 2u);
  EXPECT_EQ(cmps.at(size_t{0}).at("name").asString(), "core_vs_simbody");
  EXPECT_EQ(cmps.at(size_t{1}).at("name").asString(), "core_vs_reference");
  EXPECT_EQ(cmps.at(size_t{1}).at("columns_compared").asNumber(), 2);
  EXPECT_NE(cmps.at(size_t{1}).at("missing").dump().find("extra_moment"), std::string::npos);

  // the engines' results agree with the closed form to 1e-7 of the peak (as `redmax id`)
  const redmax::osim::Storage core = redmax::osim::readStorage((dir_ / "rep/core_id.sto").string());
  const redmax::osim::Storage sb = redmax::osim::readStorage((dir_ / "rep/simbody_id.sto").string());
  ASSERT_EQ(core.numRows(), 501);
  ASSERT_EQ(sb.numRows(), 501);
  double worst = 0, peak = 0;
  for (int k = 0; k < core.numRows(); ++k) {
    const Eigen::Vector2d ref = closedFormTau(core.time[k]);
    worst = std::max(worst, (core.data.row(k).transpose() - ref).cwiseAbs().maxCoeff());
    peak = std::max(peak, ref.cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-7 * peak);
  EXPECT_LE((core.data - sb.data).cwiseAbs().maxCoeff(), 1e-9 * peak);
}

TEST_F(Validate, WrongReferenceFailsWithExitOne) {
  if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to validation_tests (build target redmax)";
  // q2 1% too large: RMS/peak ~ 1e-2 >> 1e-6
  writeReference("wrong.sto", 1.01);
  const CmdResult r = run("validate --model dp.osim --coordinates dp.mot --t0 0.5 --t1 1.5 --reference wrong.sto "
                          "--no-plots --quiet --report rep");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;  // --quiet
  const JsonValue s = summary("rep");
  EXPECT_FALSE(s.at("passed").asBool());
  const JsonValue& cmps = s.at("comparisons");
  ASSERT_EQ(cmps.size(), 2u);
  EXPECT_TRUE(cmps.at(size_t{0}).at("passed").asBool());   // the engines still agree
  EXPECT_FALSE(cmps.at(size_t{1}).at("passed").asBool());  // the reference does not
  EXPECT_EQ(cmps.at(size_t{1}).at("worst_column").dump().find("q1_moment"), std::string::npos);
  EXPECT_NE(cmps.at(size_t{1}).at("worst_column").dump().find("q2_moment"), std::string::npos);

  // printed: the worst column and FAIL; a loose tolerance makes the same reference pass
  const CmdResult p = run("validate --model dp.osim --coordinates dp.mot --t0 0.5 --t1 1.5 --reference wrong.sto "
                          "--no-plots --report rep2");
  EXPECT_EQ(p.code, 1);
  EXPECT_NE(p.out.find("worst q2_moment"), std::string::npos) << p.out;
  EXPECT_NE(p.out.find("validate: FAIL"), std::string::npos) << p.out;
  const CmdResult loose = run("validate --model dp.osim --coordinates dp.mot --t0 0.5 --t1 1.5 --reference wrong.sto "
                              "--tolerance 0.05 --no-plots --quiet --report rep3");
  EXPECT_EQ(loose.code, 0) << loose.err;
}

TEST_F(Validate, BadInputExitsTwoWithAnError) {
  if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to validation_tests (build target redmax)";
  writeReference("ref.sto", 1.0);
  write("nocommon.sto", "x\nversion=1\nnRows=2\nnColumns=2\ninDegrees=no\nendheader\ntime\tfoo\n0\t1\n2\t1\n");
  write("late.sto", "x\nversion=1\nnRows=2\nnColumns=2\ninDegrees=no\nendheader\ntime\tq1_moment\n5\t1\n6\t1\n");
  const std::string in = "validate --model dp.osim --coordinates dp.mot --t0 0.5 --t1 1.5 --no-plots ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {in + "--reference ref.sto", "--report"},                                  // no report directory
      {"validate --model dp.osim --report rep", "needs --setup"},                // no coordinates
      {in + "--reference missing.sto --report rep", "missing.sto"},              // unreadable reference
      {in + "--reference nocommon.sto --report rep", "nocommon.sto"},            // no common column
      {in + "--reference late.sto --report rep", "late.sto"},                    // no overlapping time
      {in + "--reference ref.sto --tolerance -1 --report rep", "--tolerance"},   // negative tolerance
      {in + "--reference ref.sto --tolerance abc --report rep", "--tolerance"},  // not a number
      {in + "--interpolation quadratic --report rep", "--interpolation"},
      {in + "--bogus --report rep", "unknown option --bogus"},
      {"validate --model nomodel.osim --coordinates dp.mot --report rep", "nomodel.osim"},
      {"validate --model dp.osim --coordinates dp.mot --t0 2 --t1 1 --report rep", "--t0"},
  };
  for (const auto& [args, what] : cases) {
    const CmdResult r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "rep" / "summary.json")) << args;
  }
}

TEST_F(Validate, CoreOnlyIsRecordedAndStillPasses) {
  redmax::validation::IdValidationOptions opt;
  opt.settings.model_file = (dir_ / "dp.osim").string();
  opt.settings.coordinates_file = (dir_ / "dp.mot").string();
  opt.settings.t0 = 0.5;
  opt.settings.t1 = 1.0;
  writeReference("ref.sto", 1.0);
  opt.references = {{(dir_ / "ref.sto").string(), "closed_form"}};
  opt.report_dir = (dir_ / "core_only").string();
  opt.run_simbody = false;
  opt.gnuplot = "none";
  const auto r = redmax::validation::runIdValidation(opt);
  EXPECT_TRUE(r.passed);
  ASSERT_EQ(r.engines.size(), 2u);
  EXPECT_TRUE(r.engines[0].ran);
  EXPECT_EQ(r.engines[0].frames, 251);
  EXPECT_FALSE(r.engines[1].ran);
  EXPECT_FALSE(r.engines[1].skipped.empty());
  ASSERT_EQ(r.comparisons.size(), 1u);
  EXPECT_EQ(r.comparisons[0].name, "core_vs_closed_form");
  EXPECT_TRUE(r.files.plots_skipped);
  const JsonValue s = summary("core_only");
  EXPECT_TRUE(s.at("passed").asBool());
  EXPECT_FALSE(s.at("speed").at("simbody").at("ran").asBool());
  EXPECT_NE(s.at("engines").at("simbody").asString().find("disabled"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "core_only" / "simbody_id.sto"));
  // the printed summary names the skipped engine
  EXPECT_NE(redmax::validation::formatIdValidationSummary(r).find("engine simbody: skipped"), std::string::npos);
}

// set F (gait10dof18musc, docs/shared_data.md) through its setup file, the 2017 model
// given by flag, against OpenSim 4.6's own ID result
TEST_F(Validate, SetFPassesAgainstOpenSim46) {
  const std::string base = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  const std::string setup = base + "opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/walk_Setup_ID.xml";
  const std::string model = base + "opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim";
  const std::string ref = base + "opensim-4.6-results/F.sto";
  for (const auto& f : {setup, model, ref})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  redmax::validation::IdValidationOptions opt;
  opt.settings.setup_file = setup;
  opt.settings.model_file = model;
  opt.references = {{ref, "opensim46"}};
  opt.report_dir = (dir_ / "setF").string();
  opt.gnuplot = "none";
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_EQ(r.comparisons.size(), 2u) << (r.engines.size() > 1 ? r.engines[1].skipped : "");
  EXPECT_TRUE(r.comparisons[0].passed) << "core vs simbody";
  EXPECT_TRUE(r.comparisons[1].passed) << "core vs OpenSim 4.6";
  EXPECT_TRUE(r.passed);
  EXPECT_EQ(r.comparisons[1].metrics.size(), 10u);
  EXPECT_EQ(r.engines[0].frames, 151);
  const auto& worst = r.comparisons[1].metrics[static_cast<size_t>(r.comparisons[1].worst)];
  EXPECT_LT(worst.rms_rel, 1e-6);
  std::printf("[ measured ] set F: core vs simbody worst max/peak %.3g; core vs OpenSim 4.6 worst %s rms/peak %.3g\n",
              r.comparisons[0].metrics[static_cast<size_t>(r.comparisons[0].worst)].max_rel, worst.name.c_str(),
              worst.rms_rel);
  std::printf("[ measured ] set F speed: core %.0f frames/s, simbody %.0f frames/s\n", r.engines[0].framesPerSecond(),
              r.engines[1].framesPerSecond());
}

// set E (gait2392): Debian's Simbody rejects the toes' inertia (it breaks the triangle inequality),
// so the engines are cross-checked on OpenSim's isotropic fallback for those bodies, while the
// comparison with OpenSim 4.6 uses the inertia as given; both must pass
TEST_F(Validate, SetECrossChecksEnginesWithTheFallbackInertia) {
  const std::string base = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  const std::string setup = base + "opensim-models/Pipelines/Gait2392_Simbody/subject01_Setup_InverseDynamics.xml";
  const std::string model =
      base + "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim";
  const std::string ref = base + "opensim-4.6-results/E.sto";
  for (const auto& f : {setup, model, ref})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  redmax::validation::IdValidationOptions opt;
  opt.settings.setup_file = setup;
  opt.settings.model_file = model;
  opt.references = {{ref, "opensim46"}};
  opt.report_dir = (dir_ / "setE").string();
  opt.gnuplot = "none";
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_EQ(r.engines.size(), 2u);
  ASSERT_TRUE(r.engines[1].ran) << r.engines[1].skipped;
  ASSERT_EQ(r.comparisons.size(), 2u);
  EXPECT_EQ(r.comparisons[0].name, "core_vs_simbody");
  EXPECT_TRUE(r.comparisons[0].passed);
  EXPECT_TRUE(r.comparisons[1].passed);
  EXPECT_TRUE(r.passed);
  bool noted = false;
  for (const auto& w : r.warnings) noted = noted || (w.find("toes_r") != std::string::npos && w.find("fallback") != std::string::npos);
  EXPECT_TRUE(noted) << "the fallback must be reported";
  const JsonValue s = summary("setE");
  EXPECT_TRUE(s.at("passed").asBool());
  std::printf("[ measured ] set E: core vs simbody (fallback inertia) worst max/peak %.3g\n",
              r.comparisons[0].metrics[static_cast<size_t>(r.comparisons[0].worst)].max_rel);
}

}  // namespace
