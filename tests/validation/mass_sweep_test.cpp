// Muscle-mass sweeps in the validation harness (validation/mass_sweep.hpp, `redmax validate
// --mass-sweep`; issue 6 graceful degradation, [D Sec. 6.2.8-6.2.9]):
//   - the analysis on synthetic tables with known answers: an exactly affine sweep has R^2 = 1 and
//     no nonlinearity; a quadratic one has the closed-form R^2 of a line through the origin fitted
//     to s^2; a perturbed zero value fails the zero check;
//   - value parsing and checking, main-column choice;
//   - the project's running leg (runs everywhere): the 0-80% tibia transfer sweep writes every
//     file, its zero value equals the plain zero-mass ID (<= 1e-12 of the peak), the torque
//     difference is affine in the fraction (tau(F) - tau(0) = F/0.8 (tau(0.8) - tau(0)) to 1e-9
//     of the peak, R^2 >= 1 - 1e-9), the ankle moment changes, and a physiological scale sweep
//     has R^2 >= 0.999; Simbody with muscle inertia agrees with the core at 80% (1e-9 of the
//     peak); the single-value inertial effect equals the sweep at the same fraction;
//   - toward zero (physiological scales 0, 1e-3, 0.01, 0.1, 1; running leg everywhere, set F with
//     ../shared): the value 0 runs the mass-point code with massless points; Simbody with
//     plugin/simbody's own muscle inertia agrees with the core at every value (1e-13 of the peak,
//     measured <= 4.9e-15), so do the two engines' inertial effects tau(s) - tau(0), and each
//     engine's effect is s times its effect at 1 (|ratio / s - 1| <= 1e-10, measured 1.4e-11); set
//     F's value 0 equals OpenSim 4.6's own ID result (RMS 1e-9 of the peak, measured 7.6e-11);
//   - the command line: a sweep through `redmax validate` exits 0 and fills summary.json; its 80%
//     torques equal `redmax id --muscle-mass transfer --transfer-fraction 0.8` (1e-12 of the peak);
//     bad sweep values and flags exit 2;
//   - sets F (gait10dof18musc) and E (gait2392; Simbody at 80% on the toe fallback inertia),
//     skipped without ../shared: the same properties and a nonzero
//     inertial effect on ankle_angle_r_moment; the core's muscle share at trial frames equals
//     Lagrange's equations from central differences of the mass points' energies (1e-6), which
//     covers set F's MovingPathPoints; Simbody with muscle inertia agrees at 80% (1e-9 of the peak).
// Measured numbers are printed with "[ measured ]"; nothing asserts a timing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "converter/id/core_id_engine.hpp"
#include "converter/storage.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/validation/pendulum_cli_fixture.hpp"
#include "validation/id_validation.hpp"
#include "validation/mass_sweep.hpp"
#include "validation/report/csv.hpp"
#include "validation/report/json_value.hpp"
#include "validation/report/plot.hpp"

namespace {

namespace fs = std::filesystem;
using redmax::MatX;
using redmax::osim::MuscleMassOptions;
using redmax::validation::JsonValue;
using Source = MuscleMassOptions::Source;
using namespace redmax_test;

const std::vector<double> kFractions = {0.0, 0.2, 0.4, 0.6, 0.8};

std::string leg() { return std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg.osim"; }
std::string swing() { return std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg_swing.mot"; }

int columnOf(const std::vector<std::string>& labels, const std::string& name) {
  for (size_t i = 0; i < labels.size(); ++i)
    if (labels[i] == name) return static_cast<int>(i);
  return -1;
}

// peak |x| per column
Eigen::VectorXd peaks(const MatX& m) { return m.cwiseAbs().colwise().maxCoeff().transpose(); }

// tau(F) - tau(0) = F / F_max (tau(F_max) - tau(0)) for every value: worst deviation / column peak
double affineDefect(const std::vector<double>& values, const std::vector<redmax::osim::Storage>& tau) {
  const MatX& t0 = tau.front().data;
  const MatX d_max = tau.back().data - t0;
  const Eigen::VectorXd pk = peaks(t0);
  double worst = 0;
  for (size_t j = 0; j < values.size(); ++j) {
    const MatX pred = t0 + (values[j] / values.back()) * d_max;
    for (int c = 0; c < t0.cols(); ++c)
      worst = std::max(worst, (tau[j].data.col(c) - pred.col(c)).cwiseAbs().maxCoeff() / pk(c));
  }
  return worst;
}

class MassSweep : public PendulumCliTest {
 protected:
  void SetUp() override { makeDir("redmax_mass_sweep_"); }

  redmax::validation::IdValidationOptions legOptions(const std::string& report) const {
    redmax::validation::IdValidationOptions opt;
    opt.settings.model_file = leg();
    opt.settings.coordinates_file = swing();
    opt.report_dir = (dir_ / report).string();
    opt.gnuplot = redmax::validation::findGnuplot().available ? "" : "none";
    return opt;
  }
};

// ------------------------------------------------------------------------------------------------
// analysis on synthetic tables

TEST(MassSweepAnalysis, AffineSweepHasUnitR2AndTheExpectedPeaks) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  const int frames = 40, cols = 3;
  MatX tau0(frames, cols), B(frames, cols);
  for (int k = 0; k < frames; ++k)
    for (int c = 0; c < cols; ++c) {
      tau0(k, c) = 10 * std::sin(0.3 * k + c) + u(rng);
      B(k, c) = c == 2 ? 0.0 : 4 * u(rng);  // column 2 has no inertial effect
    }
  std::vector<MatX> tau;
  for (double s : kFractions) tau.push_back(tau0 + s * B);
  const auto a = redmax::validation::analyzeMassSweep(kFractions, tau, tau0);
  ASSERT_EQ(a.columns.size(), 3u);
  EXPECT_EQ(a.zero_index, 0);
  EXPECT_TRUE(a.zero_passed);
  EXPECT_EQ(a.zero_max_rel, 0.0);
  for (int c = 0; c < 2; ++c) {
    const auto& col = a.columns[static_cast<size_t>(c)];
    EXPECT_TRUE(col.has_effect);
    EXPECT_NEAR(col.r2, 1.0, 1e-13);
    EXPECT_LT(col.nonlinearity_rel, 1e-14);
    const double p0 = tau0.col(c).cwiseAbs().maxCoeff();
    EXPECT_DOUBLE_EQ(col.peak_zero, p0);
    for (size_t j = 0; j < kFractions.size(); ++j) {
      const MatX t = tau0 + kFractions[j] * B;
      EXPECT_NEAR(col.peak[j], t.col(c).cwiseAbs().maxCoeff(), 1e-13 * p0);
      EXPECT_NEAR(col.peak_change_rel[j], (t.col(c).cwiseAbs().maxCoeff() - p0) / p0, 1e-13);
      EXPECT_NEAR(col.max_diff_rel[j], kFractions[j] * B.col(c).cwiseAbs().maxCoeff() / p0, 1e-13);
    }
    EXPECT_NEAR(col.slope_max_rel, B.col(c).cwiseAbs().maxCoeff() / p0, 1e-12);
  }
  // no effect: no fit
  EXPECT_FALSE(a.columns[2].has_effect);
  EXPECT_TRUE(std::isnan(a.columns[2].r2));
  EXPECT_NEAR(a.r2_min_observed, 1.0, 1e-13);
}

TEST(MassSweepAnalysis, QuadraticSweepHasTheClosedFormR2) {
  // y = s^2 b_k: the line through the origin has slope c b_k, c = sum s^3 / sum s^2, so
  // R^2 = 1 - sum (s^2 - c s)^2 / sum (s^2 - mean s^2)^2 whatever b_k is
  const std::vector<double>& s = kFractions;
  double s2 = 0, s3 = 0, m2 = 0;
  for (double x : s) s2 += x * x, s3 += x * x * x, m2 += x * x / s.size();
  const double c = s3 / s2;
  double res = 0, tot = 0;
  for (double x : s) res += (x * x - c * x) * (x * x - c * x), tot += (x * x - m2) * (x * x - m2);
  const double r2 = 1 - res / tot;
  ASSERT_LT(r2, 0.99);  // the fit must be able to tell

  MatX tau0 = MatX::Constant(5, 1, 3.0), B(5, 1);
  B << 1, -2, 0.5, 3, -1;
  std::vector<MatX> tau;
  for (double x : s) tau.push_back(tau0 + x * x * B);
  const auto a = redmax::validation::analyzeMassSweep(s, tau, tau0);
  EXPECT_NEAR(a.columns[0].r2, r2, 1e-12);
  EXPECT_GT(a.columns[0].nonlinearity_rel, 0.01);
}

TEST(MassSweepAnalysis, ZeroCheckFailsWhenTheZeroValueDiffers) {
  MatX tau0 = MatX::Constant(4, 2, 2.0);
  std::vector<MatX> tau = {tau0, tau0 * 1.1};
  const std::vector<double> v = {0.0, 0.5};
  EXPECT_TRUE(redmax::validation::analyzeMassSweep(v, tau, tau0).zero_passed);
  tau[0](2, 1) += 2.0 * 1e-11;  // 1e-11 of the peak
  const auto a = redmax::validation::analyzeMassSweep(v, tau, tau0);
  EXPECT_FALSE(a.zero_passed);
  EXPECT_NEAR(a.zero_max_rel, 1e-11, 1e-15);
  // a NaN fails too
  tau[0](0, 0) = std::nan("");
  EXPECT_FALSE(redmax::validation::analyzeMassSweep(v, tau, tau0).zero_passed);
  // shapes and a sweep without a nonzero value are rejected
  EXPECT_THROW(redmax::validation::analyzeMassSweep({0.0}, {tau0}, tau0), std::invalid_argument);
  EXPECT_THROW(redmax::validation::analyzeMassSweep(v, {tau0, MatX::Zero(3, 2)}, tau0), std::invalid_argument);
}

TEST(MassSweepValues, ParsedCheckedSortedAndZeroAdded) {
  using redmax::validation::checkMassSweepValues;
  using redmax::validation::parseMassSweepValues;
  EXPECT_EQ(parseMassSweepValues("0,0.2, 0.4"), (std::vector<double>{0, 0.2, 0.4}));
  EXPECT_THROW(parseMassSweepValues("0,abc"), std::invalid_argument);
  EXPECT_THROW(parseMassSweepValues("0.2x"), std::invalid_argument);
  EXPECT_THROW(parseMassSweepValues(" , "), std::invalid_argument);
  MuscleMassOptions t;
  t.source = Source::Transfer;
  t.transfer_body = "tibia_r";
  EXPECT_EQ(checkMassSweepValues(t, {0.8, 0.4}), (std::vector<double>{0, 0.4, 0.8}));
  EXPECT_THROW(checkMassSweepValues(t, {0.2, 1.0}), std::invalid_argument);
  EXPECT_THROW(checkMassSweepValues(t, {-0.1}), std::invalid_argument);
  EXPECT_THROW(checkMassSweepValues(t, {0.2, 0.2}), std::invalid_argument);
  EXPECT_THROW(checkMassSweepValues(t, {0.0}), std::invalid_argument);
  MuscleMassOptions p;
  p.source = Source::Physiological;
  EXPECT_EQ(checkMassSweepValues(p, {2, 0, 1}), (std::vector<double>{0, 1, 2}));
  EXPECT_THROW(checkMassSweepValues(p, {-1}), std::invalid_argument);
  EXPECT_THROW(checkMassSweepValues(MuscleMassOptions{}, {0.5}), std::invalid_argument);
  // the options of one value
  EXPECT_EQ(redmax::validation::massOptionsForValue(t, 0.6).transfer_fraction, 0.6);
  EXPECT_DOUBLE_EQ(redmax::validation::massOptionsForValue(p, 0.5).density, 0.5 * p.density);
  // scale 0 stays physiological (massless points), not "no muscle mass"
  EXPECT_EQ(redmax::validation::massOptionsForValue(p, 0.0).source, Source::Physiological);
  EXPECT_EQ(redmax::validation::massOptionsForValue(p, 0.0).density, 0.0);
  EXPECT_TRUE(redmax::validation::hasZeroMuscleMass(redmax::validation::massOptionsForValue(p, 0.0)));
  EXPECT_TRUE(redmax::validation::hasZeroMuscleMass(redmax::validation::massOptionsForValue(t, 0.0)));
  EXPECT_FALSE(redmax::validation::hasZeroMuscleMass(redmax::validation::massOptionsForValue(p, 1e-3)));
  EXPECT_FALSE(redmax::validation::hasZeroMuscleMass(redmax::validation::massOptionsForValue(t, 0.2)));
}

TEST(MassSweepValues, MainColumnsFollowTheTransferSide) {
  const std::vector<std::string> labels = {"pelvis_tilt_moment", "hip_flexion_r_moment", "hip_flexion_l_moment",
                                           "knee_angle_r_moment", "knee_angle_l_moment", "ankle_angle_r_moment",
                                           "ankle_angle_l_moment", "lumbar_extension_moment"};
  EXPECT_EQ(redmax::validation::chooseMainColumns(labels, "tibia_r"),
            (std::vector<std::string>{"ankle_angle_r_moment", "knee_angle_r_moment", "hip_flexion_r_moment"}));
  EXPECT_EQ(redmax::validation::chooseMainColumns(labels, "tibia_l").front(), "ankle_angle_l_moment");
  EXPECT_EQ(redmax::validation::chooseMainColumns(labels, "").size(), 6u);
  EXPECT_EQ(redmax::validation::chooseMainColumns({"q1_moment", "q2_moment"}, "l1").size(), 2u);
}

// ------------------------------------------------------------------------------------------------
// the running leg (osim_models/), through the harness

TEST_F(MassSweep, RunningLegTibiaTransferIsAffineAndReproducesZeroMass) {
  auto opt = legOptions("leg_sweep");
  opt.muscle_mass.source = Source::Transfer;
  opt.muscle_mass.transfer_body = "tibia_r";
  opt.mass_sweep = {0.8, 0.6, 0.4, 0.2};  // 0 is added
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_TRUE(r.has_mass_sweep);
  EXPECT_TRUE(r.passed) << "zero mass core vs Simbody and the sweep's zero check";
  const auto& sw = r.mass_sweep;
  ASSERT_EQ(sw.options.values, kFractions);
  ASSERT_EQ(sw.torques.size(), 5u);

  // every file of the sweep
  const fs::path rep = dir_ / "leg_sweep";
  for (const std::string f : {"summary.json", "report.md", "core_id.sto", "simbody_id.sto", "mass_sweep_peaks.csv",
                              "mass_sweep_fit.csv", "mass_sweep_tau_F0.csv", "mass_sweep_tau_F0.2.csv",
                              "mass_sweep_tau_F0.4.csv", "mass_sweep_tau_F0.6.csv", "mass_sweep_tau_F0.8.csv"})
    EXPECT_TRUE(fs::exists(rep / f)) << f;
  if (redmax::validation::findGnuplot().available) {
    EXPECT_TRUE(fs::exists(rep / "mass_sweep_torques.png") || fs::exists(rep / "mass_sweep_torques.svg"));
    EXPECT_TRUE(fs::exists(rep / "mass_sweep_peak_change.png") || fs::exists(rep / "mass_sweep_peak_change.svg"));
  }

  // the zero value is the plain zero-mass ID, read back from the report's full-precision file
  const redmax::osim::Storage zero = redmax::osim::readStorage((rep / "core_id.sto").string());
  ASSERT_EQ(zero.labels, sw.torques[0].labels);
  ASSERT_EQ(zero.numRows(), sw.torques[0].numRows());
  const Eigen::VectorXd pk = peaks(zero.data);
  for (int c = 0; c < zero.data.cols(); ++c)
    EXPECT_LE((sw.torques[0].data.col(c) - zero.data.col(c)).cwiseAbs().maxCoeff(), 1e-12 * pk(c)) << zero.labels[c];
  EXPECT_TRUE(sw.analysis.zero_passed);

  // Simbody with muscle inertia on the same model and mass points (no moving points here): round-off
  ASSERT_TRUE(sw.simbody.ran) << sw.simbody.skipped;
  EXPECT_TRUE(sw.simbody.comparison.passed);
  EXPECT_TRUE(fs::exists(rep / "core_mass_vs_simbody_mass_metrics.csv"));

  // exactly affine in the fraction (file comment of mass_sweep.hpp), so much tighter than R^2 0.999
  const double defect = affineDefect(sw.options.values, sw.torques);
  EXPECT_LT(defect, 1e-9);
  EXPECT_GT(sw.analysis.r2_min_observed, 1 - 1e-9);

  // the ankle moment changes, and the CSV holds what the run returned
  const int ankle = columnOf(zero.labels, "ankle_angle_r_moment");
  ASSERT_GE(ankle, 0);
  const auto& col = sw.analysis.columns[static_cast<size_t>(ankle)];
  EXPECT_GT(col.max_diff_rel.back(), 1e-3);
  EXPECT_EQ(sw.main_columns.front(), "ankle_angle_r_moment");
  const JsonValue s = JsonValue::parse(slurp(rep / "summary.json"));
  const JsonValue& ms = s.at("mass_sweep");
  EXPECT_EQ(ms.at("mode").asString(), "transfer");
  EXPECT_EQ(ms.at("values").size(), 5u);
  EXPECT_TRUE(ms.at("zero_check").at("passed").asBool());
  EXPECT_TRUE(s.at("simbody_mass_check").at("agrees").asBool());
  EXPECT_DOUBLE_EQ(ms.at("columns").at("ankle_angle_r_moment").at("peak_change_rel").at(4).asNumber(),
                   col.peak_change_rel[4]);
  // the muscle mass moved is 80% of the tibia's 3.161 kg at the last value
  EXPECT_NEAR(sw.points.back().muscle_mass, 0.8 * 3.161, 1e-12);
  EXPECT_EQ(sw.points.front().muscle_mass, 0.0);
  std::printf("[ measured ] running leg, tibia_r transfer 0-80%%: ankle peak change %+.2f%%, max change %.2f%% of "
              "the peak; R^2 min %.15f; affine defect %.2g; zero check %.2g\n",
              100 * col.peak_change_rel.back(), 100 * col.max_diff_rel.back(), sw.analysis.r2_min_observed, defect,
              sw.analysis.zero_max_rel);
}

TEST_F(MassSweep, RunningLegPhysiologicalScaleSweepIsLinear) {
  auto opt = legOptions("leg_phys");
  opt.gnuplot = "none";
  opt.run_simbody = false;
  opt.muscle_mass.source = Source::Physiological;
  opt.mass_sweep = {0, 0.25, 0.5, 1};
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_TRUE(r.has_mass_sweep);
  EXPECT_TRUE(r.passed);
  const auto& sw = r.mass_sweep;
  EXPECT_GE(sw.analysis.r2_min_observed, 0.999);
  EXPECT_LT(affineDefect(sw.options.values, sw.torques), 1e-9);
  // the masses scale with the value
  EXPECT_GT(sw.points.back().muscle_mass, 0.0);
  EXPECT_NEAR(sw.points[1].muscle_mass, 0.25 * sw.points.back().muscle_mass, 1e-12);
  std::printf("[ measured ] running leg, physiological scale 0-1 (%.3f kg): R^2 min %.15f\n",
              sw.points.back().muscle_mass, sw.analysis.r2_min_observed);
}

// graceful degradation toward zero mass, against references that share nothing with the core's
// muscle code: Simbody with plugin/simbody's MuscleInertia solves every value (its own station
// kinematics of the mass points), and the two engines' inertial effects tau(s) - tau(0) must agree
// at every value while shrinking in proportion to s
const std::vector<double> kToZero = {0.0, 1e-3, 0.01, 0.1, 1.0};

// max_k |x(k)| over every column, of a - b
double maxAbsDiff(const MatX& a, const MatX& b) { return (a - b).cwiseAbs().maxCoeff(); }

// per sweep value, of the table pairs (zero, value): the effect's size over every column and frame
std::vector<double> effectSizes(const std::vector<MatX>& tau) {
  std::vector<double> out;
  for (const MatX& t : tau) out.push_back(maxAbsDiff(t, tau.front()));
  return out;
}

// what both engine checks assert on a sweep over kToZero; returns the worst effect ratio defect
// |effect(s) / (s effect(1)) - 1| over s > 0 of both engines
double checkDegradation(const redmax::validation::MassSweepResult& sw, const redmax::osim::Storage& zero_mass,
                        const char* what) {
  EXPECT_EQ(sw.options.values, kToZero);
  EXPECT_EQ(sw.points.front().muscle_mass, 0.0);
  // the value 0 ran the mass-point code: the muscles carry points, massless
  EXPECT_GT(sw.points.front().muscles_with_mass, 0);
  EXPECT_EQ(sw.points.front().muscles_with_mass, sw.points.back().muscles_with_mass);
  EXPECT_NE(sw.points.front().description.find("zero mass"), std::string::npos) << sw.points.front().description;
  EXPECT_TRUE(sw.analysis.zero_passed) << sw.analysis.zero_max_rel;
  EXPECT_NEAR(sw.points[1].muscle_mass, 1e-3 * sw.points.back().muscle_mass, 1e-12 * sw.points.back().muscle_mass);
  EXPECT_EQ(sw.simbody_values.size(), kToZero.size());
  if (sw.simbody_values.size() != kToZero.size()) return 1.0;
  std::vector<MatX> core, sb;
  for (size_t j = 0; j < kToZero.size(); ++j) {
    const auto& c = sw.simbody_values[j];
    SCOPED_TRACE(std::string(what) + " value " + std::to_string(kToZero[j]));
    EXPECT_EQ(c.value, kToZero[j]);
    EXPECT_TRUE(c.ran) << c.skipped;
    if (!c.ran) return 1.0;
    EXPECT_TRUE(c.not_counted.empty()) << c.not_counted;
    EXPECT_TRUE(c.comparison.passed);
    const auto& w = c.comparison.metrics[static_cast<size_t>(c.comparison.worst)];
    // the engine tolerance is 1e-9 of the peak; measured 1.6e-15 (running leg) and 4.9e-15 (set F)
    EXPECT_LE(w.max_rel, 1e-13) << w.name;
    // the effects agree to the engines' round-off, relative to the column peak (measured <= 3.6e-15)
    if (j > 0) EXPECT_LE(c.effect_max_rel, 1e-13);
    core.push_back(c.coreTorques(sw.torques[j]).data);
    sb.push_back(c.result.data);
  }
  // Simbody with massless points equals the plain zero-mass core (an engine with no muscle code)
  const Eigen::VectorXd pk = peaks(zero_mass.data);
  if (sw.simbody_values.front().core_result.numRows() == 0)
    for (int c = 0; c < zero_mass.data.cols(); ++c)
      EXPECT_LE((sb.front().col(c) - zero_mass.data.col(c)).cwiseAbs().maxCoeff(), 1e-9 * pk(c)) << zero_mass.labels[c];
  // linear in s toward zero, seen by each engine: effect(s) = s effect(1) per frame and column
  const std::vector<double> ec = effectSizes(core), es = effectSizes(sb);
  EXPECT_GT(ec.back(), 1e-6 * pk.maxCoeff()) << "the muscles must matter at s = 1";
  double worst = 0;
  for (size_t j = 1; j < kToZero.size(); ++j) {
    const double s = kToZero[j];
    worst = std::max({worst, std::abs(ec[j] / (s * ec.back()) - 1), std::abs(es[j] / (s * es.back()) - 1)});
    // per frame too, for the Simbody side (the core is affine by construction)
    EXPECT_LE(maxAbsDiff(sb[j] - sb.front(), s * (sb.back() - sb.front())), 1e-9 * pk.maxCoeff()) << s;
  }
  std::printf("[ measured ] %s: effect at s = 1e-3 / effect at 1: core %.6g, simbody %.6g (x 1e-3); worst "
              "|ratio / s - 1| %.2g; core vs simbody worst %.2g of the peak, effects %.2g of the peak\n",
              what, ec[1] / ec.back() * 1e3, es[1] / es.back() * 1e3, worst,
              [&] {
                double m = 0;
                for (const auto& c : sw.simbody_values)
                  m = std::max(m, c.comparison.metrics[static_cast<size_t>(c.comparison.worst)].max_rel);
                return m;
              }(),
              [&] {
                double m = 0;
                for (size_t j = 1; j < sw.simbody_values.size(); ++j) m = std::max(m, sw.simbody_values[j].effect_max_rel);
                return m;
              }());
  return worst;
}

TEST_F(MassSweep, RunningLegPhysiologicalSweepTowardZeroAgreesWithSimbodyAtEveryValue) {
  auto opt = legOptions("leg_to_zero");
  opt.gnuplot = "none";
  opt.muscle_mass.source = Source::Physiological;
  opt.mass_sweep = {1.0, 0.1, 0.01, 1e-3};  // 0 is added
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_TRUE(r.has_mass_sweep);
  EXPECT_TRUE(r.passed);
  const redmax::osim::Storage zero = redmax::osim::readStorage((dir_ / "leg_to_zero" / "core_id.sto").string());
  const double worst = checkDegradation(r.mass_sweep, zero, "running leg, physiological 0-1");
  // measured 1.4e-11: linear to round-off in both engines (the effect at 1e-3 is 1e-3 of the one at 1)
  EXPECT_LE(worst, 1e-10);
  EXPECT_TRUE(fs::exists(dir_ / "leg_to_zero" / "mass_sweep_simbody.csv"));
  const JsonValue s = JsonValue::parse(slurp(dir_ / "leg_to_zero" / "summary.json"));
  EXPECT_EQ(s.at("mass_sweep").at("simbody_values").size(), kToZero.size());
}

TEST_F(MassSweep, InertialEffectEqualsTheSweepAtTheSameFraction) {
  auto opt = legOptions("leg_effect");
  opt.gnuplot = "none";
  opt.muscle_mass.source = Source::Transfer;
  opt.muscle_mass.transfer_body = "tibia_r";
  opt.muscle_mass.transfer_fraction = 0.8;
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_TRUE(r.has_inertial_effect);
  EXPECT_TRUE(r.passed) << "the inertial effect is never a failure";
  const fs::path rep = dir_ / "leg_effect";
  for (const std::string f : {"inertial_effect.csv", "core_mass_id.sto", "core_id.sto"})
    EXPECT_TRUE(fs::exists(rep / f)) << f;
  const JsonValue s = JsonValue::parse(slurp(rep / "summary.json"));
  EXPECT_TRUE(s.at("passed").asBool());
  EXPECT_NEAR(s.at("inertial_effect").at("muscle_mass_kg").asNumber(), 0.8 * 3.161, 1e-12);

  // the same as the sweep's 80% column, and the metrics describe the stored difference
  auto so = legOptions("leg_sweep2");
  so.gnuplot = "none";
  so.run_simbody = false;
  so.muscle_mass = opt.muscle_mass;
  so.mass_sweep = {0.8};
  const auto sr = redmax::validation::runIdValidation(so);
  const redmax::osim::Storage mass = redmax::osim::readStorage((rep / "core_mass_id.sto").string());
  const redmax::osim::Storage zero = redmax::osim::readStorage((rep / "core_id.sto").string());
  const MatX& sweep80 = sr.mass_sweep.torques.back().data;
  ASSERT_EQ(mass.data.rows(), sweep80.rows());
  const Eigen::VectorXd pk = peaks(zero.data);
  for (int c = 0; c < mass.data.cols(); ++c) {
    EXPECT_LE((mass.data.col(c) - sweep80.col(c)).cwiseAbs().maxCoeff(), 1e-12 * pk(c)) << mass.labels[c];
    const auto& m = r.inertial_effect.metrics[static_cast<size_t>(c)];
    EXPECT_EQ(m.name, mass.labels[c]);
    EXPECT_NEAR(m.max_abs, (mass.data.col(c) - zero.data.col(c)).cwiseAbs().maxCoeff(), 1e-12 * pk(c));
  }
  const int ankle = columnOf(mass.labels, "ankle_angle_r_moment");
  ASSERT_GE(ankle, 0);
  EXPECT_GT(r.inertial_effect.metrics[static_cast<size_t>(ankle)].max_rel, 1e-3);
}

// ------------------------------------------------------------------------------------------------
// the command line

TEST_F(MassSweep, CommandLineSweepAndBadValues) {
  if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to validation_tests (build target redmax)";
  const std::string in = "validate --model " + leg() + " --coordinates " + swing() + " --no-plots ";
  const CmdResult ok =
      run(in + "--muscle-mass transfer --transfer-body tibia_r --mass-sweep 0,0.4,0.8 --report rep");
  ASSERT_EQ(ok.code, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find("mass sweep (transfer tibia_r)"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("ankle_angle_r_moment: peak"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("zero check"), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("validate: PASS"), std::string::npos) << ok.out;
  const JsonValue s = JsonValue::parse(slurp(dir_ / "rep" / "summary.json"));
  EXPECT_EQ(s.at("mass_sweep").at("values").size(), 3u);
  EXPECT_EQ(s.at("inputs").at("muscle_mass").at("transfer_body").asString(), "tibia_r");
  // what the muscle-mass step did is printed (bodies before and after, muscles)
  EXPECT_NE(ok.err.find("tibia_r"), std::string::npos) << ok.err;

  // `redmax id` with the same muscle mass (its own wiring: the tool's model and CoreIdEngine with a
  // MuscleTerm) gives the sweep's 80% torques
  const CmdResult id = run("id --model " + leg() + " --coordinates " + swing() +
                           " --muscle-mass transfer --transfer-body tibia_r --transfer-fraction 0.8 --full-precision"
                           " --quiet --out id80.sto");
  ASSERT_EQ(id.code, 0) << id.err;
  const redmax::osim::Storage id80 = redmax::osim::readStorage((dir_ / "id80.sto").string());
  const redmax::validation::CsvTable csv = redmax::validation::parseCsv(slurp(dir_ / "rep" / "mass_sweep_tau_F0.8.csv"));
  ASSERT_EQ(csv.rows.size(), static_cast<size_t>(id80.numRows()));
  ASSERT_EQ(csv.header.size(), id80.labels.size() + 1);
  const Eigen::VectorXd pk = peaks(id80.data);
  double worst = 0;
  for (int k = 0; k < id80.numRows(); ++k) {
    EXPECT_NEAR(std::stod(csv.rows[static_cast<size_t>(k)][0]), id80.time[static_cast<size_t>(k)], 1e-12);
    for (int c = 0; c < id80.data.cols(); ++c) {
      EXPECT_EQ(csv.header[static_cast<size_t>(c) + 1], id80.labels[static_cast<size_t>(c)]);
      worst = std::max(worst, std::abs(std::stod(csv.rows[static_cast<size_t>(k)][static_cast<size_t>(c) + 1]) -
                                       id80.data(k, c)) / pk(c));
    }
  }
  EXPECT_LT(worst, 1e-12);
  std::printf("[ measured ] running leg 80%% tibia_r: validate sweep vs redmax id with muscle mass %.2g of the peak\n",
              worst);

  const std::vector<std::pair<std::string, std::string>> cases = {
      {in + "--mass-sweep 0,0.5 --report bad", "--mass-sweep"},  // no --muscle-mass
      {in + "--muscle-mass transfer --transfer-body tibia_r --transfer-fraction 0.5 --mass-sweep 0,0.5 --report bad",
       "--transfer-fraction"},
      {in + "--muscle-mass transfer --transfer-body tibia_r --report bad", "--transfer-fraction"},
      {in + "--muscle-mass physiological --mass-sweep 0,-1 --report bad", "-1"},
      {in + "--sweep-columns ankle_angle_r_moment --report bad", "--sweep-columns"},
      {in + "--muscle-mass transfer --transfer-body tibia_r --mass-sweep 0,1.2 --report bad", "1.2"},
      {in + "--muscle-mass transfer --transfer-body tibia_r --mass-sweep 0,abc --report bad", "abc"},
      {in + "--muscle-mass transfer --transfer-body nobody --mass-sweep 0,0.5 --report bad", "nobody"},
      {in + "--muscle-mass transfer --transfer-body tibia_r --mass-sweep 0,0.5 --sweep-columns nocol --report bad",
       "nocol"},
  };
  for (const auto& [args, what] : cases) {
    const CmdResult r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.out << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad" / "summary.json")) << args;
  }
}

// ------------------------------------------------------------------------------------------------
// set F (gait10dof18musc), docs/shared_data.md

TEST_F(MassSweep, SetFTibiaTransferSweep) {
  const std::string base = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  const std::string setup = base + "opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/walk_Setup_ID.xml";
  const std::string model = base + "opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim";
  for (const auto& f : {setup, model})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  redmax::validation::IdValidationOptions opt;
  opt.settings.setup_file = setup;
  opt.settings.model_file = model;
  opt.report_dir = (dir_ / "setF").string();
  opt.gnuplot = "none";
  opt.muscle_mass.source = Source::Transfer;
  opt.muscle_mass.transfer_body = "tibia_r";
  opt.mass_sweep = kFractions;
  opt.references = {{base + "opensim-4.6-results/F.sto", "opensim"}};
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_TRUE(r.has_mass_sweep);
  const auto& sw = r.mass_sweep;
  // the value 0 (massless points) against OpenSim 4.6's own result, as the zero-mass core is
  ASSERT_EQ(sw.zero_vs_references.size(), 1u);
  EXPECT_TRUE(sw.zero_vs_references[0].passed);
  // Simbody at every fraction
  ASSERT_EQ(sw.simbody_values.size(), kFractions.size());
  for (const auto& c : sw.simbody_values) {
    EXPECT_TRUE(c.ran && c.comparison.passed) << c.value << ": " << c.skipped;
    if (c.value > 0) EXPECT_LE(c.effect_max_rel, 1e-9) << c.value;
  }
  // the zero-mass engines agree, and so does Simbody with muscle inertia at 80% (MovingPathPoints
  // included: their terms come from Simbody's own mobilizer kinematics, muscle_inertia.hpp)
  EXPECT_TRUE(r.passed);
  ASSERT_FALSE(r.comparisons.empty());
  EXPECT_EQ(r.comparisons[0].name, "core_vs_simbody");
  EXPECT_TRUE(r.comparisons[0].passed);
  ASSERT_TRUE(sw.simbody.ran) << sw.simbody.skipped;
  {
    const auto& c = sw.simbody.comparison;
    EXPECT_TRUE(c.passed);
    std::printf("[ measured ] set F 80%% tibia_r: core vs Simbody with muscle inertia worst %s max/peak %.3g\n",
                c.metrics[static_cast<size_t>(c.worst)].name.c_str(), c.metrics[static_cast<size_t>(c.worst)].max_rel);
  }
  EXPECT_TRUE(sw.analysis.zero_passed) << sw.analysis.zero_max_rel;
  EXPECT_LE(sw.analysis.zero_max_rel, 1e-12);
  const double defect = affineDefect(sw.options.values, sw.torques);
  EXPECT_LT(defect, 1e-9);
  EXPECT_GT(sw.analysis.r2_min_observed, 1 - 1e-9);
  const int ankle = columnOf(sw.torques[0].labels, "ankle_angle_r_moment");
  ASSERT_GE(ankle, 0);
  const auto& col = sw.analysis.columns[static_cast<size_t>(ankle)];
  // walking: the ankle's peak is a stance moment under the ground reaction, so the change is a small
  // share of it (still ten orders above round-off)
  EXPECT_TRUE(col.has_effect);
  EXPECT_GT(col.max_diff_rel.back(), 1e-5);
  std::printf("[ measured ] set F, tibia_r transfer 0-80%% (%.3f kg in %d muscles): ankle peak change %+.2f%%, max "
              "change %.2f%% of the peak; R^2 min %.15f; affine defect %.2g\n",
              sw.points.back().muscle_mass, sw.points.back().muscles_with_mass, 100 * col.peak_change_rel.back(),
              100 * col.max_diff_rel.back(), sw.analysis.r2_min_observed, defect);
}

}  // namespace

namespace {

// set E (gait2392: 21 muscles with a path point on tibia_r, moving points): the same properties
TEST_F(MassSweep, SetETibiaTransferSweep) {
  const std::string base = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  const std::string setup = base + "opensim-models/Pipelines/Gait2392_Simbody/subject01_Setup_InverseDynamics.xml";
  const std::string model =
      base + "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim";
  for (const auto& f : {setup, model})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  redmax::validation::IdValidationOptions opt;
  opt.settings.setup_file = setup;
  opt.settings.model_file = model;
  opt.report_dir = (dir_ / "setE").string();
  opt.gnuplot = "none";
  opt.muscle_mass.source = Source::Transfer;
  opt.muscle_mass.transfer_body = "tibia_r";
  opt.mass_sweep = kFractions;
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_TRUE(r.has_mass_sweep);
  EXPECT_TRUE(r.passed);
  const auto& sw = r.mass_sweep;
  EXPECT_TRUE(sw.analysis.zero_passed) << sw.analysis.zero_max_rel;
  EXPECT_LT(affineDefect(sw.options.values, sw.torques), 1e-9);
  EXPECT_GT(sw.analysis.r2_min_observed, 1 - 1e-9);
  EXPECT_GT(sw.points.back().muscles_with_mass, 1);
  const int ankle = columnOf(sw.torques[0].labels, "ankle_angle_r_moment");
  ASSERT_GE(ankle, 0);
  EXPECT_GT(sw.analysis.columns[static_cast<size_t>(ankle)].max_diff_rel.back(), 1e-5);
  // Simbody with muscle inertia at 80%: both engines on OpenSim's fallback for the toes
  ASSERT_TRUE(sw.simbody.ran) << sw.simbody.skipped;
  EXPECT_TRUE(sw.simbody.comparison.passed);
  EXPECT_NE(sw.simbody.note.find("toes_r"), std::string::npos) << sw.simbody.note;
  std::printf("[ measured ] set E, tibia_r transfer 0-80%% (%.3f kg in %d muscles): ankle max change %.3f%% of the "
              "peak; R^2 min %.15f\n",
              sw.points.back().muscle_mass, sw.points.back().muscles_with_mass,
              100 * sw.analysis.columns[static_cast<size_t>(ankle)].max_diff_rel.back(), sw.analysis.r2_min_observed);
}

// set F toward zero mass: both engines at every value, and the value 0 against OpenSim 4.6's result
TEST_F(MassSweep, SetFPhysiologicalSweepTowardZeroAgainstSimbodyAndOpenSim) {
  const std::string base = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  const std::string setup = base + "opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/walk_Setup_ID.xml";
  const std::string model = base + "opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim";
  const std::string opensim = base + "opensim-4.6-results/F.sto";
  for (const auto& f : {setup, model, opensim})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  redmax::validation::IdValidationOptions opt;
  opt.settings.setup_file = setup;
  opt.settings.model_file = model;
  opt.report_dir = (dir_ / "setF_to_zero").string();
  opt.gnuplot = "none";
  opt.muscle_mass.source = Source::Physiological;
  opt.mass_sweep = {1.0, 0.1, 0.01, 1e-3};
  opt.references = {{opensim, "opensim"}};
  const auto r = redmax::validation::runIdValidation(opt);
  ASSERT_TRUE(r.has_mass_sweep);
  EXPECT_TRUE(r.passed);
  const auto& sw = r.mass_sweep;
  ASSERT_EQ(sw.zero_vs_references.size(), 1u);
  const auto& zc = sw.zero_vs_references[0];
  EXPECT_TRUE(zc.passed);
  const auto& zw = zc.metrics[static_cast<size_t>(zc.worst)];
  // measured 7.6e-11 of the peak (RMS, lumbar_extension_moment), as the zero-mass core
  EXPECT_LE(zw.rms_rel, 1e-9) << zw.name;
  const redmax::osim::Storage zero = redmax::osim::readStorage((dir_ / "setF_to_zero" / "core_id.sto").string());
  const double worst = checkDegradation(sw, zero, "set F, physiological 0-1");
  EXPECT_LE(worst, 1e-10);  // measured 1.1e-11
  std::printf("[ measured ] set F, value 0 (massless points) vs OpenSim 4.6: worst %s RMS/peak %.3g\n", zw.name.c_str(),
              zw.rms_rel);
}

// the muscles' share of inverse dynamics, tau_m = tau(with mass points) - tau(skeleton alone) on
// the same reduced model, against Lagrange's equations built by central differences of the mass
// points' energies only (no Jdot):  d/dt dT/dqdot - dT/dq + dV/dq. Set F's tibia muscles include
// vasti_r and rect_fem_r, whose MovingPathPoints make x_a depend on the knee angle directly.
TEST_F(MassSweep, SetFMuscleShareSatisfiesLagrangeByDifferences) {
  const std::string base = std::string(REDMAX_SHARED_DIR) + "/opensim/";
  const std::string setup = base + "opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/walk_Setup_ID.xml";
  const std::string model = base + "opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim";
  for (const auto& f : {setup, model})
    if (!fs::exists(f)) GTEST_SKIP() << "shared OpenSim data not found: " << f << " (needs ../shared/opensim)";
  redmax::osim::IdToolSettings st;
  st.setup_file = setup;
  st.model_file = model;
  const redmax::osim::InverseDynamicsTool tool(redmax::osim::resolveIdSettings(st));
  MuscleMassOptions mo;
  mo.source = Source::Transfer;
  mo.transfer_body = "tibia_r";
  mo.transfer_fraction = 0.8;
  auto e = redmax::validation::makeCoreMassEngineFactory(tool)(mo);
  ASSERT_TRUE(e.model);
  const redmax::Model& m = *e.model;
  redmax::osim::CoreIdEngine skeleton(m, tool.engineOptions());
  const redmax::MuscleTerm term(m, e.model->muscles());
  redmax::SkeletonWorkspace sk(m);
  auto energy = [&](const redmax::VecX& q, const redmax::VecX& qdot, bool kinetic) {
    redmax::State s;
    s.q = q;
    s.qdot = qdot;
    redmax::calcKinematics(m, s, sk);
    return kinetic ? term.kineticEnergy(m, s, sk) : term.potentialEnergy(m, s, sk);
  };
  const int nr = m.nr();
  double worst = 0;
  for (int k : {10, 60, 110}) {
    redmax::VecX q, v, a, tau_mass, tau_skel;
    std::vector<redmax::osim::IdLoadSample> loads;
    tool.calcInputs(tool.frameTime(k), q, v, a, loads);
    e.engine->calcGeneralizedForces(0, q, v, a, {}, tau_mass);
    skeleton.calcGeneralizedForces(0, q, v, a, {}, tau_skel);
    const redmax::VecX tau_m = tau_mass - tau_skel;
    // p_i = dT/dqdot_i (T is quadratic in qdot: the difference is exact up to round-off)
    const double hv = 1e-3, h = 1e-5;
    auto p = [&](const redmax::VecX& qq, const redmax::VecX& vv) {
      redmax::VecX out(nr);
      for (int i = 0; i < nr; ++i) {
        redmax::VecX vp = vv, vm = vv;
        vp(i) += hv;
        vm(i) -= hv;
        out(i) = (energy(qq, vp, true) - energy(qq, vm, true)) / (2 * hv);
      }
      return out;
    };
    // d/dt p along (qdot, qddot)
    const redmax::VecX pdot = (p(q + h * v, v + h * a) - p(q - h * v, v - h * a)) / (2 * h);
    redmax::VecX lag = pdot;
    for (int i = 0; i < nr; ++i) {
      redmax::VecX qp = q, qm = q;
      qp(i) += h;
      qm(i) -= h;
      lag(i) -= (energy(qp, v, true) - energy(qm, v, true)) / (2 * h);
      lag(i) += (energy(qp, v, false) - energy(qm, v, false)) / (2 * h);
    }
    const double scale = tau_m.cwiseAbs().maxCoeff();
    ASSERT_GT(scale, 1.0) << "the mass points must matter";
    worst = std::max(worst, (tau_m - lag).cwiseAbs().maxCoeff() / scale);
  }
  EXPECT_LT(worst, 1e-6);
  std::printf("[ measured ] set F 80%% tibia_r: core muscle share vs Lagrange by differences: %.2g of its peak\n",
              worst);
}

}  // namespace
