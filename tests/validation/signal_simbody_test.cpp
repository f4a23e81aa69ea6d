// Our natural interpolating splines (converter/signal/natural_spline.hpp) against Simbody's own
// SimTK::SplineFitter<double>::fitFromErrorVariance(degree, x, y, 0) (GCVSPL, mode 3), which is
// what OpenSim's GCVSpline evaluates: on random data and on the real coordinate and
// ground-reaction data of set E, at the stages where OpenSim fits splines (the padded raw data it
// resamples, the filtered data it differentiates, the loads it interpolates). GCVSPL stops at a
// tiny but nonzero smoothing parameter, so agreement is to round-off-amplified ~1e-13, not bits.
#include <gtest/gtest.h>

#include "plugin/simbody/simbody_include.hpp"  // <Simbody.h> (SimTK::SplineFitter) under C++20

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "converter/signal/coordinate_pipeline.hpp"
#include "converter/signal/natural_spline.hpp"

namespace redmax::signal {
namespace {

namespace fs = std::filesystem;

// the largest relative difference of orders 0..2 over a set of sample points. Order d is
// normalized by max|s^(d)| + max|y| / span^d: the second term keeps a column that is constant to
// 1e-6 (set E's subtalar angles, locked in IK) from being judged by its noise-level derivatives
struct Agreement {
  double rel[3] = {0, 0, 0};
  void merge(const Agreement& o) {
    for (int d = 0; d < 3; ++d) rel[d] = std::max(rel[d], o.rel[d]);
  }
};

Agreement compareWithSimbody(int degree, const std::vector<double>& x, const std::vector<double>& y) {
  SimTK::Vector sx(static_cast<int>(x.size())), sy(static_cast<int>(y.size()));
  for (size_t i = 0; i < x.size(); ++i) {
    sx[static_cast<int>(i)] = x[i];
    sy[static_cast<int>(i)] = y[i];
  }
  const SimTK::Spline simtk = SimTK::SplineFitter<double>::fitFromErrorVariance(degree, sx, sy, 0.0).getSpline();
  const NaturalSpline ours(degree, x, y);
  // the knots and the midpoints between them (Simbody's splder only evaluates inside the data);
  // orders >= degree jump at the knots, where the two codes may pick different sides
  double err[3] = {0, 0, 0}, scale[3] = {0, 0, 0};
  auto sample = [&](double t, bool knot) {
    double o[3];
    ours.calcDerivatives(t, o);
    const double s[3] = {simtk.calcValue(t), simtk.calcDerivative(1, t), simtk.calcDerivative(2, t)};
    for (int d = 0; d < 3; ++d) {
      scale[d] = std::max(scale[d], std::abs(s[d]));
      if (!(knot && d >= degree)) err[d] = std::max(err[d], std::abs(o[d] - s[d]));
    }
  };
  for (size_t i = 0; i < x.size(); ++i) {
    sample(x[i], true);
    if (i + 1 < x.size()) sample(0.5 * (x[i] + x[i + 1]), false);
  }
  double ymax = 0;
  for (double v : y) ymax = std::max(ymax, std::abs(v));
  const double span = x.back() - x.front();
  Agreement a;
  for (int d = 0; d < 3; ++d) a.rel[d] = err[d] / (scale[d] + ymax / std::pow(span, d));
  return a;
}

struct Table {
  std::vector<std::string> labels;
  std::vector<double> time;
  Eigen::MatrixXd data;
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
    for (double v; rs >> v;) row.push_back(v);
    if (!row.empty()) rows.push_back(row);
  }
  const int nc = static_cast<int>(t.labels.size()) - 1;
  t.data.resize(static_cast<Eigen::Index>(rows.size()), nc);
  for (size_t i = 0; i < rows.size(); ++i) {
    t.time.push_back(rows[i][0]);
    for (int c = 0; c < nc; ++c) t.data(static_cast<Eigen::Index>(i), c) = rows[i][c + 1];
  }
  return t;
}

std::vector<double> column(const Eigen::MatrixXd& m, int c) { return {m.col(c).data(), m.col(c).data() + m.rows()}; }

fs::path gaitDir() { return fs::path(REDMAX_SHARED_DIR) / "opensim/opensim-models/Pipelines/Gait2392_Simbody"; }

// random, mildly non-uniform data: cubic and quintic (OpenSim's two uses), also linear and septic
TEST(SignalSimbody, RandomDataMatchesSplineFitter) {
  std::mt19937 rng(31);
  std::normal_distribution<double> nd;
  std::uniform_real_distribution<double> step(0.5 / 120, 1.5 / 120);
  for (int degree : {1, 3, 5, 7}) {
    Agreement worst;
    for (int n : {2 * ((degree + 1) / 2), 30, 250}) {
      std::vector<double> x(n), y(n);
      x[0] = 0.4;
      for (int i = 1; i < n; ++i) x[i] = x[i - 1] + step(rng);
      for (double& v : y) v = 30 * nd(rng);
      worst.merge(compareWithSimbody(degree, x, y));
    }
    std::printf("random data, degree %d: max relative difference value %.2e, first %.2e, second %.2e\n", degree,
                worst.rel[0], worst.rel[1], worst.rel[2]);
    // measured (degree 1/3/5/7): value <= 9.3e-14, first <= 3.2e-13, second <= 5.2e-13 (septic;
    // <= 2.4e-14 for the cubic and quintic OpenSim uses)
    const double tol[3] = {1e-12, 5e-12, 5e-12};
    for (int d = 0; d < 3; ++d) EXPECT_LT(worst.rel[d], tol[d]) << "degree " << degree << " order " << d;
  }
}

// set E's coordinates as OpenSim fits them: quintics through the raw IK columns (no filter),
// through the padded raw columns (the resampling fit), and through the padded, resampled and
// filtered columns (the final GCVSplineSet(5) that gives q, qdot, qddot)
TEST(SignalSimbody, GaitCoordinatesMatchSplineFitter) {
  const fs::path path = gaitDir() / "subject01_walk1_ik.mot";
  if (!fs::exists(path)) GTEST_SKIP() << "shared OpenSim data not found: " << path;
  const Table in = readTable(path);
  ASSERT_EQ(in.data.cols(), 23);
  const int pad = static_cast<int>(in.time.size()) / 2;
  const std::vector<double> t_pad = padOddReflection(in.time, pad);
  CoordinateProcessingOptions opt;
  opt.lowpass_cutoff_hz = 6.0;
  const ProcessedCoordinates pc = processCoordinates(in.time, in.data, opt);
  const char* names[3] = {"raw", "padded", "filtered"};
  Agreement worst[3], worst_regular[3];
  for (int c = 0; c < in.data.cols(); ++c) {
    const std::vector<double> y = column(in.data, c);
    const double lo = *std::min_element(y.begin(), y.end()), hi = *std::max_element(y.begin(), y.end());
    if (hi == lo) continue;  // mtp angles: constant, both fits exact
    // subtalar angles vary in their 6th digit (locked in IK, 5.04337-5.04339 degrees): there, GCVSPL's
    // own round-off (it misses the data by ~1.6 ulp at the knots) dominates the second derivative
    const bool near_constant = hi - lo < 1e-4 * std::max(std::abs(lo), std::abs(hi));
    const Agreement stage[3] = {compareWithSimbody(5, in.time, y),
                                compareWithSimbody(5, t_pad, padOddReflection(y, pad)),
                                compareWithSimbody(5, pc.time, column(pc.values, c))};
    for (int s = 0; s < 3; ++s) {
      worst[s].merge(stage[s]);
      if (!near_constant) worst_regular[s].merge(stage[s]);
      // measured: value <= 2.7e-16; first <= 4.8e-13; second <= 1.0e-12 for regular columns and
      // <= 3.4e-10 for the near-constant subtalar columns
      const double tol[3] = {1e-14, 5e-12, near_constant ? 3e-9 : 2e-11};
      for (int d = 0; d < 3; ++d)
        EXPECT_LT(stage[s].rel[d], tol[d]) << in.labels[c + 1] << " " << names[s] << " order " << d;
    }
  }
  for (int s = 0; s < 3; ++s)
    std::printf("set E coordinates, %s: max relative difference value %.2e, first %.2e, second %.2e "
                "(second %.2e without the near-constant subtalar columns)\n",
                names[s], worst[s].rel[0], worst[s].rel[1], worst[s].rel[2], worst_regular[s].rel[2]);
}

// end to end on set E: OpenSim's coordinate pipeline rebuilt on Simbody's splines (pad, fit
// SplineFitter quintics, evaluate on the accumulated grid, filter, fit again) against ours:
// q, qdot, qddot at the 73 output times of E.sto
TEST(SignalSimbody, GaitPipelineMatchesOneBuiltOnSplineFitter) {
  const fs::path path = gaitDir() / "subject01_walk1_ik.mot";
  if (!fs::exists(path)) GTEST_SKIP() << "shared OpenSim data not found: " << path;
  const Table in = readTable(path);
  CoordinateProcessingOptions opt;
  opt.lowpass_cutoff_hz = 6.0;
  const ProcessedCoordinates pc = processCoordinates(in.time, in.data, opt);
  const TimeWindow w = pc.selectWindow(0.4, 1.6);
  ASSERT_EQ(w.numRows(), 73);

  const int pad = static_cast<int>(in.time.size()) / 2;
  const std::vector<double> t_pad = padOddReflection(in.time, pad);
  double dt = calcMinTimeStep(t_pad);
  const std::vector<double> grid = makeResampleGrid(t_pad, dt, &dt);
  auto toVector = [](const std::vector<double>& v) {
    SimTK::Vector s(static_cast<int>(v.size()));
    for (size_t i = 0; i < v.size(); ++i) s[static_cast<int>(i)] = v[i];
    return s;
  };
  double worst[3] = {0, 0, 0};
  for (int c = 0; c < in.data.cols(); ++c) {
    // OpenSim's steps with SimTK splines
    const SimTK::Spline fit1 = SimTK::SplineFitter<double>::fitFromErrorVariance(
                                   5, toVector(t_pad), toVector(padOddReflection(column(in.data, c), pad)), 0.0)
                                   .getSpline();
    std::vector<double> resampled(grid.size());
    for (size_t i = 0; i < grid.size(); ++i) resampled[i] = fit1.calcValue(grid[i]);
    const std::vector<double> filtered = lowpassIIR(dt, 6.0, resampled);
    const SimTK::Spline fit2 =
        SimTK::SplineFitter<double>::fitFromErrorVariance(5, toVector(grid), toVector(filtered), 0.0).getSpline();
    // compare at the output rows, each order against its range there plus max|q| / span^d
    double err[3] = {0, 0, 0}, scale[3] = {0, 0, 0}, qmax = 0;
    for (int r = w.first_row; r <= w.last_row; ++r) {
      const double t = pc.time[r];
      double o[3];
      pc.splines[c].calcDerivatives(t, o);
      const double s[3] = {fit2.calcValue(t), fit2.calcDerivative(1, t), fit2.calcDerivative(2, t)};
      for (int d = 0; d < 3; ++d) {
        err[d] = std::max(err[d], std::abs(o[d] - s[d]));
        scale[d] = std::max(scale[d], std::abs(s[d]));
      }
      qmax = std::max(qmax, std::abs(s[0]));
    }
    const double span = pc.time[w.last_row] - pc.time[w.first_row];
    for (int d = 0; d < 3; ++d) {
      const double ref = scale[d] + qmax / std::pow(span, d);
      const double rel = ref > 0 ? err[d] / ref : err[d];  // mtp angles are 0 throughout
      worst[d] = std::max(worst[d], rel);
      // measured: 1.3e-15, 8.1e-14, 6.3e-12
      const double tol[3] = {1e-13, 1e-12, 1e-10};
      EXPECT_LT(rel, tol[d]) << in.labels[c + 1] << " order " << d;
    }
  }
  std::printf("set E pipeline vs SplineFitter-based pipeline at the output rows: q %.2e, qdot %.2e, qddot %.2e\n",
              worst[0], worst[1], worst[2]);
}

// set E's ground reactions through natural cubics, as ExternalForce interpolates them
TEST(SignalSimbody, GroundReactionsMatchSplineFitter) {
  const fs::path path = gaitDir() / "subject01_walk1_grf.mot";
  if (!fs::exists(path)) GTEST_SKIP() << "shared OpenSim data not found: " << path;
  const Table in = readTable(path);
  Agreement worst;
  for (int c = 0; c < in.data.cols(); ++c) {
    const std::vector<double> y = column(in.data, c);
    if (*std::max_element(y.begin(), y.end()) == *std::min_element(y.begin(), y.end())) continue;
    worst.merge(compareWithSimbody(3, in.time, y));
  }
  std::printf("set E ground reactions, cubic: max relative difference value %.2e, first %.2e, second %.2e\n",
              worst.rel[0], worst.rel[1], worst.rel[2]);
  // measured: value 2.2e-16, first 1.6e-13, second 2.3e-12
  const double tol[3] = {1e-14, 2e-12, 2e-11};
  for (int d = 0; d < 3; ++d) EXPECT_LT(worst.rel[d], tol[d]) << "order " << d;
}

}  // namespace
}  // namespace redmax::signal
