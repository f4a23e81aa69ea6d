// `redmax lengths --wrap smooth|neural` end to end (issue 7). The smooth model's length is the
// exact wrapped length wherever no wrapped segment lies in the transition band (blend weight 0 or
// 1), and inside the band it differs from it by at most |L_wrapped - L_straight| of the segments
// in the band (L = L_straight + w (L_wrapped - L_straight), smooth.hpp). The band is found here
// from the library (calcSegmentWraps and the smooth model's blend weight at the test's own
// configurations), not from the command. Models: subject_walk_armless_18musc (OpenSim's test
// motion, 40 WrapCylinders; skipped without ../shared, docs/shared_data.md), the wrapping double pendulum of
// osim_models/ over a q2 sweep written here; neural with cylinder_6x256 on a pendulum whose
// cylinder is scaled so the end points lie inside the network's training box; bad values.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/geometry/wrap_surface.hpp"
#include "core/muscles/wrap_composite.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax;
using namespace redmax::cli_test;
using redmax::osim::readStorage;
using redmax::osim::Storage;

const std::string kShared = REDMAX_SHARED_DIR;
const std::string kMoco = kShared + "/opensim/opensim-core/OpenSim/Moco/Test/";

// Per frame and reported muscle: whether a wrapped segment of the smooth model lies in the band
// (0 < w < 1), and the sum of |L_wrapped - L_straight| over those segments (m): the most the
// smooth length can differ from the exact one there.
struct BandInfo {
  Eigen::MatrixXi in_band;  // rows x muscles
  Eigen::MatrixXd bound;    // rows x muscles
  std::vector<std::string> names;
  std::vector<char> smooth_taken;  // per muscle: the smooth model takes its path
  std::vector<char> composed;      // per muscle: two wraps can share a segment (the composition)
};

BandInfo calcBand(const std::string& model_file, const std::string& coords_file, double width) {
  const osim::ModelDescription d = osim::readOsimModel(model_file);
  osim::BuildOptions opt;
  opt.constraints = false;
  const osim::BuildResult b = osim::buildCoreModel(d, opt);
  const Storage coords = readStorage(coords_file);
  const Model& model = b.model;
  VecX q0 = VecX::Zero(model.nr());
  std::vector<std::pair<int, int>> cols;
  std::vector<double> scale;
  for (size_t ci = 0; ci < d.coordinates.size(); ++ci) {
    const int k = b.coordinate_index[ci];
    if (k < 0) continue;
    q0[k] = d.coordinates[ci].default_value;
    const int c = coords.findColumn(d.coordinates[ci].name);
    if (c < 0) continue;
    cols.emplace_back(k, c);
    scale.push_back(coords.in_degrees && d.coordinates[ci].motion_type == osim::MotionType::Rotational ? M_PI / 180.0
                                                                                                      : 1.0);
  }
  std::vector<Muscle> muscles;
  BandInfo info;
  for (size_t k = 0; k < b.model.muscles().size(); ++k) {
    if (!d.muscles[b.muscle_source[k]].is_muscle) continue;
    Muscle m = b.model.muscles()[k];
    m.wrap = WrapMassOptions{};
    m.wrap.model = WrapModel::Smooth;
    m.wrap.width = width;
    info.names.push_back(m.name);
    info.smooth_taken.push_back(!m.path.wraps.empty() && wrapMassPointsUnsupportedReason(m).empty());
    info.composed.push_back(hasSharedWrapSegments(m));
    muscles.push_back(std::move(m));
  }
  const int M = static_cast<int>(muscles.size());
  info.in_band.setZero(coords.numRows(), M);
  info.bound.setZero(coords.numRows(), M);
  SmoothWrapOptions so;
  so.width = width;
  std::vector<Mat4> E_wi;
  for (int row = 0; row < coords.numRows(); ++row) {
    VecX q = q0;
    for (size_t j = 0; j < cols.size(); ++j) q[cols[j].first] = coords.data(row, cols[j].second) * scale[j];
    calcBodyPoses(model, q, E_wi);
    for (int m = 0; m < M; ++m) {
      if (!info.smooth_taken[m] || info.composed[m]) continue;
      const MusclePath& path = muscles[m].path;
      std::vector<int> active;
      std::vector<Vec3> x_w;
      for (size_t i = 0; i < path.points.size(); ++i) {
        if (!isPathPointActive(path.points[i], q)) continue;
        Vec3 x_b, dx, ddx;
        calcPointLocation(path.points[i], q, x_b, dx, ddx);
        active.push_back(static_cast<int>(i));
        x_w.push_back(path.points[i].body >= 0 ? transformPoint(E_wi[path.points[i].body], x_b) : x_b);
      }
      const std::vector<int> seg = calcSegmentWraps(muscles[m], active, x_w, E_wi);
      for (size_t i = 0; i < seg.size(); ++i) {
        if (seg[i] < 0) continue;
        const PathWrap& w = path.wraps[seg[i]];
        const Mat4 E_ws = w.body >= 0 ? Mat4(E_wi[w.body] * w.E_bs) : w.E_bs;
        const Mat3 R = E_ws.topLeftCorner<3, 3>();
        const Vec3 p = E_ws.topRightCorner<3, 1>();
        const Vec3 p1 = R.transpose() * (x_w[i] - p), p2 = R.transpose() * (x_w[i + 1] - p);
        double weight = 0.0;
        try {
          weight = calcSmoothWrapPointDerivatives(w.surface, p1, p2, 0.5, Vec3::Zero(), Vec3::Zero(), so).weight;
        } catch (const std::invalid_argument&) {
          continue;  // an end inside the surface: straight in both
        }
        if (weight > 0.0 && weight < 1.0) {
          info.in_band(row, m) = 1;
          const double wrapped = calcWrappedPathLength(calcWrap(w.surface, p1, p2), p1, p2);
          info.bound(row, m) += std::abs(wrapped - (p2 - p1).norm());
        }
      }
    }
  }
  return info;
}

class LengthsWrapCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_lengths_wrap_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }
  CmdResult run(const std::string& args) const { return runRedmax(dir_, args, true); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  // the pendulum's q2 sweep (q1 at its default), radians
  void writeSweep(const std::string& name, double from, double to, int rows) const {
    std::ostringstream s;
    s << "sweep\nversion=1\nnRows=" << rows << "\nnColumns=2\ninDegrees=no\nendheader\ntime\tq2\n";
    s.precision(17);
    for (int k = 0; k < rows; ++k) s << 0.01 * k << "\t" << from + (to - from) * k / (rows - 1) << "\n";
    std::ofstream(dir_ / name) << s.str();
  }

  // smooth vs exact on one model and motion: = to 1e-9 m outside the band, within the band's own
  // bound inside it; returns the largest in-band difference and counts the frames
  double checkSmoothAgainstExact(const std::string& model, const std::string& coords, double width,
                                 const std::string& tag, int* clean_frames, int* band_frames) {
    const std::string width_flag = width > 0.0 ? " --wrap-width " + std::to_string(width) : std::string();
    const CmdResult re = run("lengths --model " + model + " --coordinates " + coords +
                             " --full-precision --quiet --out " + tag + "_exact.sto");
    EXPECT_EQ(re.code, 0) << re.err;
    const CmdResult rs = run("lengths --model " + model + " --coordinates " + coords + " --wrap smooth" + width_flag +
                             " --full-precision --out " + tag + "_smooth.sto");
    EXPECT_EQ(rs.code, 0) << rs.err;
    EXPECT_NE(rs.out.find("wrap smooth"), std::string::npos) << rs.out;
    const Storage ex = readStorage(path(tag + "_exact.sto")), sm = readStorage(path(tag + "_smooth.sto"));
    const BandInfo band = calcBand(model, coords, width);  // model and coords: absolute paths
    EXPECT_EQ(ex.numRows(), sm.numRows());
    EXPECT_EQ(band.in_band.rows(), sm.numRows());
    *clean_frames = 0;
    *band_frames = 0;
    double worst_band = 0.0, worst_clean = 0.0, worst_composed = 0.0;
    for (int r = 0; r < sm.numRows(); ++r) {
      const bool any = band.in_band.row(r).maxCoeff() > 0;
      ++*(any ? band_frames : clean_frames);
      for (size_t m = 0; m < band.names.size(); ++m) {
        const int ce = ex.findColumn(band.names[m]), cs = sm.findColumn(band.names[m]);
        if (ce < 0 || cs < 0) {
          ADD_FAILURE() << "no column " << band.names[m];
          continue;
        }
        const double diff = std::abs(sm.data(r, cs) - ex.data(r, ce));
        if (!band.smooth_taken[m]) {
          EXPECT_EQ(sm.data(r, cs), ex.data(r, ce)) << band.names[m] << " keeps the exact length";
          continue;
        }
        if (band.composed[m]) {
          // two cylinders on one segment: the composition equals the converged library path
          // (tests/validation/wrap_composite_models_test.cpp), OpenSim's truncated passes differ
          worst_composed = std::max(worst_composed, diff);
          continue;
        }
        if (!any) {
          worst_clean = std::max(worst_clean, diff);
          EXPECT_LT(diff, 1e-9) << band.names[m] << " at row " << r << " (no muscle in the band)";
        } else {
          // a muscle not in the band at a band frame is still the exact length; one in it is
          // within its segments' wrapped - straight difference
          const double allowed = band.in_band(r, m) ? band.bound(r, m) + 1e-9 : 1e-9;
          EXPECT_LE(diff, allowed) << band.names[m] << " at row " << r;
          worst_band = std::max(worst_band, diff);
        }
      }
    }
    std::printf("[ measured ] %s: smooth vs exact lengths: %d frames with no muscle in the band (max |diff| %.3g m), "
                "%d with one (max |diff| %.3g m); composed muscles against OpenSim's passes max |diff| %.3g m\n",
                tag.c_str(), *clean_frames, worst_clean, *band_frames, worst_band, worst_composed);
    return worst_band;
  }

  fs::path dir_;
};

TEST_F(LengthsWrapCli, SubjectWalkSmoothEqualsExactOutsideTheBand) {
  if (!fs::exists(kMoco + "subject_walk_armless_18musc.osim"))
    GTEST_SKIP() << "../shared/opensim is absent: subject_walk_armless_18musc is not available";
  const std::string model = kMoco + "subject_walk_armless_18musc.osim";
  const std::string coords = kMoco + "subject_walk_armless_coordinates.mot";
  int clean = 0, banded = 0;
  const double worst = checkSmoothAgainstExact(model, coords, 0.0, "subject_walk", &clean, &banded);
  EXPECT_GT(clean, 50);  // the equality really is exercised
  // the band's effect on a walk: below a tenth of a millimetre (measured 2.7e-5 m, psoas)
  EXPECT_LT(worst, 1e-4);
  // med_gas_r/l, two cylinders that can act on one segment: composed since issue 22, none refused
  const CmdResult r = run("lengths --model " + model + " --coordinates " + coords + " --wrap smooth --out s.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("keep OpenSim's exact length"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("(14 wrapping, wrap smooth)"), std::string::npos) << r.out;
  std::printf("[ measured ] subject_walk_armless --wrap smooth: %s", r.out.c_str());
}

TEST_F(LengthsWrapCli, PendulumSmoothMatchesExactAwayFromTheContactChange) {
  // q2 from -0.5 to 1.2 rad: the muscle leaves the cylinder near q2 = 0.1 (osim header)
  writeSweep("q.mot", -0.5, 1.2, 1701);
  const std::string model = scene("double_pendulum_wrap.osim");
  int clean = 0, banded = 0;
  const double worst_default = checkSmoothAgainstExact(model, path("q.mot"), 0.0, "pendulum", &clean, &banded);
  EXPECT_GT(clean, 1000);
  EXPECT_GT(banded, 0);  // the sweep crosses the band
  EXPECT_GT(worst_default, 0.0);
  // a wider band (2 cm on the 8 cm cylinder) moves the length further from the exact one
  const double worst_wide = checkSmoothAgainstExact(model, path("q.mot"), 0.02, "pendulum_wide", &clean, &banded);
  EXPECT_GT(worst_wide, worst_default);
}

TEST_F(LengthsWrapCli, NeuralIsWithinTheNetworksErrorInsideItsBoxAndSmoothOutside) {
  const std::string net = scene("networks/cylinder_6x256.txt");
  // the pendulum's attachments lie 0.41 m from the cylinder axis, 5 radii of 0.08 m: outside the
  // network's box (coordinates within 3 radii). With a 0.2 m radius they lie at 2.05 radii.
  std::string text = slurp(scene("double_pendulum_wrap.osim"));
  const std::string from = "<radius>0.08</radius>";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "<radius>0.2</radius>");
  std::ofstream(dir_ / "big_cylinder.osim") << text;
  // q2 in [-1, 0.25]: beyond 0.25 the line passes the quadrant plane and OpenSim forces the wrap
  // round the active side, where the network (trained without quadrants) falls back
  writeSweep("q.mot", -1.0, 0.25, 61);
  const CmdResult re = run("lengths --model big_cylinder.osim --coordinates q.mot --full-precision --quiet --out e.sto");
  ASSERT_EQ(re.code, 0) << re.err;
  const CmdResult rn = run("lengths --model big_cylinder.osim --coordinates q.mot --wrap neural --wrap-network " + net +
                           " --full-precision --out n.sto");
  ASSERT_EQ(rn.code, 0) << rn.err;
  EXPECT_NE(rn.out.find("network: 0 of 61 wrapped-segment evaluations fell back"), std::string::npos) << rn.out;
  const Storage ex = readStorage(path("e.sto")), ne = readStorage(path("n.sto"));
  ASSERT_EQ(ex.numRows(), 61);
  const double worst = (ne.data - ex.data).cwiseAbs().maxCoeff();
  // the network's points are off by 0.058 radii RMS (osim_models/networks/README.md); its
  // path length is held to a tenth of the radius here (measured value in the output)
  EXPECT_LT(worst, 0.1 * 0.2);
  EXPECT_TRUE(ne.data.allFinite());
  std::printf("[ measured ] neural cylinder_6x256 vs exact, radius 0.2 m pendulum sweep: max |diff| %.4g m (%.3g radii), "
              "mean length %.4f m\n",
              worst, worst / 0.2, ex.data.mean());

  // the original pendulum: every evaluation falls back (ends at 5 radii, outside the box), and the
  // fallback is the smooth model's length
  const std::string model = scene("double_pendulum_wrap.osim");
  const CmdResult rs = run("lengths --model " + model + " --coordinates q.mot --wrap smooth --full-precision --quiet "
                           "--out s.sto");
  ASSERT_EQ(rs.code, 0) << rs.err;
  const CmdResult rf = run("lengths --model " + model + " --coordinates q.mot --wrap neural --wrap-network " + net +
                           " --full-precision --out f.sto");
  ASSERT_EQ(rf.code, 0) << rf.err;
  EXPECT_NE(rf.out.find("network: 61 of 61 wrapped-segment evaluations fell back"), std::string::npos) << rf.out;
  EXPECT_NE(rf.err.find("fell back to the smooth model"), std::string::npos) << rf.err;
  const Storage sm = readStorage(path("s.sto")), fb = readStorage(path("f.sto"));
  EXPECT_LT((sm.data - fb.data).cwiseAbs().maxCoeff(), 1e-15);
}

TEST_F(LengthsWrapCli, BadWrapValuesExitTwoAndWriteNothing) {
  writeSweep("q.mot", 0.0, 1.0, 3);
  const std::string model = scene("double_pendulum_wrap.osim");
  const std::string base = "lengths --model " + model + " --coordinates q.mot --out x.sto ";
  struct Case {
    std::string flags, message;
  };
  const std::vector<Case> cases = {
      {"--wrap lumped", "--wrap must be exact, smooth, neural or none"},
      {"--wrap neural --wrap-network missing.txt", "--wrap-network"},
      {"--wrap smooth --wrap-width -0.01", "--wrap-width must be a positive number"},
      {"--wrap smooth --wrap-width abc", "wrap-width"},
      {"--wrap exact --wrap-width 0.01", "--wrap-width needs --wrap smooth or neural"},
      {"--wrap none --wrap-width 0.01", "--wrap-width needs --wrap smooth or neural"},
      {"--wrap smooth --wrap-network " + scene("networks/cylinder_3x64.txt"), "--wrap-network needs --wrap neural"},
  };
  for (const Case& c : cases) {
    const CmdResult r = run(base + c.flags);
    EXPECT_EQ(r.code, 2) << c.flags << ": " << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << c.flags << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.flags << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "x.sto")) << c.flags;
  }
}

}  // namespace
