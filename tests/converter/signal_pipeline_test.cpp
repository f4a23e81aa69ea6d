// The InverseDynamicsTool's coordinate processing (converter/signal/coordinate_pipeline.hpp) on
// OpenSim's own inputs: the processed time grid and window must reproduce, as printed, the time
// column OpenSim 4.6 wrote for sets A (filtered and unfiltered), E and F
// (docs/shared_data.md). Filtered values are checked on a synthetic signal whose
// filtered form is known in closed form; unfiltered splines must pass through the raw data.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "converter/signal/coordinate_pipeline.hpp"

namespace redmax::signal {
namespace {

namespace fs = std::filesystem;

// a .mot/.sto file as text: labels, numeric rows, and the raw first-column tokens
struct Table {
  std::vector<std::string> labels;
  std::vector<std::string> time_text;
  std::vector<double> time;
  Eigen::MatrixXd data;  // rows x (labels - 1)
};

// minimal reader for OpenSim's version-1 files: header up to endheader, a label line, rows
Table readTable(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("endheader", 0) == 0) break;
  while (std::getline(in, line) && line.find_first_not_of(" \t\r") == std::string::npos) {
  }
  Table t;
  std::istringstream ls(line);
  for (std::string w; ls >> w;) t.labels.push_back(w);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::istringstream rs(line);
    std::vector<double> row;
    std::string tok;
    bool first = true;
    while (rs >> tok) {
      if (first) t.time_text.push_back(tok);
      first = false;
      row.push_back(std::strtod(tok.c_str(), nullptr));
    }
    if (!row.empty()) rows.push_back(row);
  }
  const int nc = static_cast<int>(t.labels.size()) - 1;
  t.data.resize(static_cast<Eigen::Index>(rows.size()), nc);
  for (size_t i = 0; i < rows.size(); ++i) {
    if (static_cast<int>(rows[i].size()) != nc + 1) throw std::runtime_error("ragged row in " + path.string());
    t.time.push_back(rows[i][0]);
    for (int c = 0; c < nc; ++c) t.data(static_cast<Eigen::Index>(i), c) = rows[i][c + 1];
  }
  return t;
}

fs::path opensimDir() { return fs::path(REDMAX_SHARED_DIR) / "opensim"; }

// OpenSim prints times with %16.8lf; compare our grid, printed the same way, token by token
std::string printed(double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.8f", t);
  return buf;
}

struct GridCase {
  const char* name;
  const char* coordinates;  // relative to shared/opensim
  const char* result;       // OpenSim 4.6 output
  double cutoff, t0, t1;
};

class OpenSimTimeGrid : public ::testing::TestWithParam<GridCase> {};

// padding + uniformity check + accumulated resampling + findIndex window = OpenSim's rows
TEST_P(OpenSimTimeGrid, ReproducesOutputTimesExactly) {
  const GridCase& c = GetParam();
  if (!fs::exists(opensimDir())) GTEST_SKIP() << "shared OpenSim data not found at " << opensimDir();
  const Table in = readTable(opensimDir() / c.coordinates);
  const Table ref = readTable(opensimDir() / "opensim-4.6-results" / c.result);
  CoordinateProcessingOptions opt;
  opt.lowpass_cutoff_hz = c.cutoff;
  const ProcessedCoordinates pc = processCoordinates(in.time, in.data, opt);
  const TimeWindow w = pc.selectWindow(c.t0, c.t1);
  ASSERT_EQ(w.numRows(), static_cast<int>(ref.time.size())) << c.name;
  int mismatches = 0;
  for (int i = 0; i < w.numRows(); ++i) {
    const double t = pc.time[w.first_row + i];
    if (printed(t) != ref.time_text[i]) ++mismatches;
    EXPECT_EQ(printed(t), ref.time_text[i]) << c.name << " row " << i;
    EXPECT_NEAR(t, ref.time[i], 5.000001e-9) << c.name << " row " << i;
  }
  EXPECT_EQ(mismatches, 0);
  if (c.cutoff >= 0) {
    EXPECT_EQ(pc.pad, static_cast<int>(in.time.size()) / 2);
    EXPECT_TRUE(pc.resampled) << "8-decimal times are never uniform to 2.2e-16";
    EXPECT_TRUE(pc.filtered);
    EXPECT_EQ(pc.cutoff_hz, c.cutoff);
  } else {
    EXPECT_EQ(pc.time, in.time);
    EXPECT_FALSE(pc.filtered);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Sets, OpenSimTimeGrid,
    ::testing::Values(
        GridCase{"E", "opensim-models/Pipelines/Gait2392_Simbody/subject01_walk1_ik.mot", "E.sto", 6.0, 0.4, 1.6},
        GridCase{"F", "opensim-models/Pipelines/Gait10dof18musc/OutputReference/IK/subject01_walk_IK.mot", "F.sto",
                 6.0, 0.0, 2.5},
        GridCase{"A_filtered",
                 "opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/InverseKinematics/"
                 "arm26_InverseKinematics.mot",
                 "A-filtered.sto", 6.0, 0.0, 1.0},
        GridCase{"A_unfiltered",
                 "opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/InverseKinematics/"
                 "arm26_InverseKinematics.mot",
                 "A-unfiltered.sto", -1.0, 0.0, 1.0}),
    [](const ::testing::TestParamInfo<GridCase>& i) { return std::string(i.param.name); });

// E in detail: the first output row lies before t0 = 0.4 (the padded grid starts before the data)
TEST(SignalPipeline, SetEStartsBeforeTheDataAndTheWindow) {
  if (!fs::exists(opensimDir())) GTEST_SKIP() << "shared OpenSim data not found at " << opensimDir();
  const Table in = readTable(opensimDir() / "opensim-models/Pipelines/Gait2392_Simbody/subject01_walk1_ik.mot");
  ASSERT_EQ(in.time.size(), 211u);
  CoordinateProcessingOptions opt;
  opt.lowpass_cutoff_hz = 6.0;
  const ProcessedCoordinates pc = processCoordinates(in.time, in.data, opt);
  // padded by 105 rows each side of [0.5, 4]: about [-1.25, 5.75], step = min padded step
  EXPECT_NEAR(pc.time.front(), 0.5 - 105.0 / 60, 1e-6);
  EXPECT_LE(pc.time.back(), 4.0 + 105.0 / 60 + 1e-6);
  EXPECT_NEAR(pc.sample_period, 1.0 / 60, 1e-7);
  const TimeWindow w = pc.selectWindow(0.4, 1.6);
  EXPECT_LT(pc.time[w.first_row], 0.4);
  EXPECT_GT(pc.time[w.first_row + 1], 0.4);
  EXPECT_EQ(printed(pc.time[w.first_row]), "0.39999934");
  // filtered gait coordinates stay close to the raw ones (6 Hz keeps the gait harmonics and
  // removes IK noise): RMS difference at the raw samples well inside the data, per column
  double worst = 0;
  for (int c = 0; c < in.data.cols(); ++c) {
    const double range = in.data.col(c).maxCoeff() - in.data.col(c).minCoeff();
    double ss = 0;
    int count = 0;
    for (size_t i = 0; i < in.time.size(); ++i) {
      if (in.time[i] < 0.6 || in.time[i] > 3.9) continue;
      const double d = pc.splines[c].calcValue(in.time[i]) - in.data(static_cast<Eigen::Index>(i), c);
      ss += d * d;
      ++count;
    }
    const double rms = std::sqrt(ss / count);
    if (range > 0) worst = std::max(worst, rms / range);
    // measured: 0.25%..3% of the range (pelvis_tilt, the noisiest); constant columns stay exact
    EXPECT_LE(rms, 0.05 * range) << in.labels[c + 1];
  }
  EXPECT_GT(worst, 0.01) << "the filter should visibly smooth IK noise";
}

// no filter: no padding, the raw grid, and splines through the (scaled) raw data
TEST(SignalPipeline, UnfilteredSplinesPassThroughTheData) {
  if (!fs::exists(opensimDir())) GTEST_SKIP() << "shared OpenSim data not found at " << opensimDir();
  const Table in = readTable(opensimDir() /
                             "opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/InverseKinematics/"
                             "arm26_InverseKinematics.mot");
  CoordinateProcessingOptions opt;  // cutoff -1
  const double deg = static_cast<double>(1.745329251994329576923690768488612713442871888541725456097191440e-2L);
  opt.column_scale.assign(in.data.cols(), deg);
  const ProcessedCoordinates pc = processCoordinates(in.time, in.data, opt);
  EXPECT_EQ(pc.pad, 0);
  EXPECT_FALSE(pc.resampled);
  ASSERT_EQ(pc.numColumns(), 2);
  for (int c = 0; c < 2; ++c) {
    const double scale = in.data.col(c).cwiseAbs().maxCoeff() * deg;
    for (size_t i = 0; i < in.time.size(); ++i) {
      const double y = in.data(static_cast<Eigen::Index>(i), c) * deg;
      EXPECT_EQ(pc.values(static_cast<Eigen::Index>(i), c), y);  // step 4 is a plain product
      EXPECT_NEAR(pc.splines[c].calcValue(in.time[i]), y, 1e-12 * scale);
    }
    EXPECT_EQ(pc.splines[c].degree(), 5);
  }
}

// filtered values against a closed form: a sum of sinusoids sampled like an IK file (8-decimal
// times at 120 Hz) comes out of pad + resample + zero-phase filter scaled by the filter's |H|^2
// at each frequency, so q, qdot and qddot are known analytically away from the ends
TEST(SignalPipeline, FilteredSinusoidsAreScaledByTheSquaredGain) {
  const int n = 481;  // 4 s at 120 Hz
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.8f", 0.25 + i / 120.0);
    t[i] = std::strtod(buf, nullptr);
  }
  const double A[2] = {0.7, 0.2}, f[2] = {0.8, 2.5}, phi[2] = {0.3, -1.1};
  Eigen::MatrixXd q(n, 1);
  for (int i = 0; i < n; ++i)
    q(i, 0) = A[0] * std::sin(2 * std::numbers::pi * f[0] * t[i] + phi[0]) +
              A[1] * std::sin(2 * std::numbers::pi * f[1] * t[i] + phi[1]);
  CoordinateProcessingOptions opt;
  opt.lowpass_cutoff_hz = 6.0;
  const ProcessedCoordinates pc = processCoordinates(t, q, opt);
  ASSERT_TRUE(pc.filtered);
  ASSERT_TRUE(pc.resampled);
  const Butterworth3 bw = makeButterworth3(pc.sample_period, 6.0);
  double gain[2];
  for (int k = 0; k < 2; ++k) {
    const double theta = 2 * std::numbers::pi * f[k] * pc.sample_period;
    std::complex<double> num = 0, den = 0;
    for (int j = 0; j < 4; ++j) {
      num += bw.a[j] * std::polar(1.0, -j * theta);
      den += bw.b[j] * std::polar(1.0, -j * theta);
    }
    gain[k] = std::norm(num / den);
  }
  double err[3] = {0, 0, 0}, scale[3] = {0, 0, 0};
  for (double tt = 1.25; tt <= 3.25; tt += 0.0037) {
    double ref[3] = {0, 0, 0};
    for (int k = 0; k < 2; ++k) {
      const double w = 2 * std::numbers::pi * f[k], arg = w * tt + phi[k];
      ref[0] += gain[k] * A[k] * std::sin(arg);
      ref[1] += gain[k] * A[k] * w * std::cos(arg);
      ref[2] -= gain[k] * A[k] * w * w * std::sin(arg);
    }
    double got[3];
    pc.splines[0].calcDerivatives(tt, got);
    for (int d = 0; d < 3; ++d) {
      err[d] = std::max(err[d], std::abs(got[d] - ref[d]));
      scale[d] = std::max(scale[d], std::abs(ref[d]));
    }
  }
  // the odd-reflection padding is not the sinusoids' true continuation: it flips the curvature at
  // the ends, and the filter's response to that decays as exp(-0.5 * 2 pi fc * t) (the complex
  // poles), i.e. to ~1e-8 one second in. Left: the quintic interpolation error
  printf("filtered sinusoids: relative errors q %.3g qdot %.3g qddot %.3g\n", err[0] / scale[0], err[1] / scale[1],
         err[2] / scale[2]);
  // measured 1.4e-10, 3.7e-9, 3.2e-7
  EXPECT_LT(err[0] / scale[0], 1e-9) << err[0];
  EXPECT_LT(err[1] / scale[1], 3e-8) << err[1];
  EXPECT_LT(err[2] / scale[2], 3e-6) << err[2];
}

TEST(SignalPipeline, RejectsBadInput) {
  const std::vector<double> t = {0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  Eigen::MatrixXd v = Eigen::MatrixXd::Random(7, 2);
  EXPECT_THROW(processCoordinates(t, Eigen::MatrixXd::Zero(6, 2)), SignalError);  // rows mismatch
  EXPECT_THROW(processCoordinates(std::vector<double>{}, Eigen::MatrixXd::Zero(0, 2)), SignalError);
  CoordinateProcessingOptions opt;
  opt.column_scale = {1.0};  // 1 factor for 2 columns
  EXPECT_THROW(processCoordinates(t, v, opt), SignalError);
  Eigen::MatrixXd bad = v;
  bad(3, 1) = NAN;
  EXPECT_THROW(processCoordinates(t, bad), SignalError);
  // too few rows for quintic splines without padding (5 < 6)
  EXPECT_THROW(processCoordinates(std::vector<double>{0, 0.1, 0.2, 0.3, 0.4}, Eigen::MatrixXd::Zero(5, 1)),
               SignalError);
  // repeated time without filtering: the spline cannot pass through it
  std::vector<double> dup = t;
  dup[4] = dup[3];
  try {
    processCoordinates(dup, v);
    FAIL();
  } catch (const SignalError& e) {
    EXPECT_NE(std::string(e.what()).find("strictly increasing"), std::string::npos) << e.what();
  }
  // with filtering the repeated time gives dtmin = 0 < 2.2e-16: OpenSim logs and skips the
  // filter, and the final spline then fails on the repeated time
  opt.column_scale.clear();
  opt.lowpass_cutoff_hz = 6.0;
  EXPECT_THROW(processCoordinates(dup, v, opt), SignalError);
}

// a uniform grid (steps equal to 2.2e-16) is filtered without resampling; a cutoff above
// Nyquist is clamped and noted
TEST(SignalPipeline, UniformGridIsNotResampledAndCutoffIsClamped) {
  const int n = 40;
  std::vector<double> t(n);
  for (int i = 0; i < n; ++i) t[i] = i * 0.125;  // exact binary steps
  Eigen::MatrixXd v(n, 1);
  for (int i = 0; i < n; ++i) v(i, 0) = std::cos(0.3 * i);
  CoordinateProcessingOptions opt;
  opt.lowpass_cutoff_hz = 100.0;
  const ProcessedCoordinates pc = processCoordinates(t, v, opt);
  EXPECT_FALSE(pc.resampled);
  EXPECT_TRUE(pc.filtered);
  EXPECT_EQ(pc.pad, n / 2);
  ASSERT_EQ(pc.time.size(), static_cast<size_t>(n + 2 * (n / 2)));
  EXPECT_EQ(pc.time.front(), -20 * 0.125);
  EXPECT_EQ(pc.cutoff_hz, 0.49 * 8.0);
  EXPECT_FALSE(pc.notes.empty());
  EXPECT_EQ(pc.sample_period, 0.125);
}

}  // namespace
}  // namespace redmax::signal
