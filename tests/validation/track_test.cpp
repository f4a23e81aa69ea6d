// Tracking a motion's coordinates (the gradient's coords: term, docs/gradients.md §3) and the
// tracking task of `redmax optimize --task track` (validation/optimize/reach.hpp, docs/gradients.md
// §7) on osim_models/reach_arm.osim: the objective against a sum computed here from the run's
// states and the file's values (degrees converted, linear between rows, right-endpoint rule), the
// adjoint gradient against central differences of whole runs, bad input named, and L-BFGS
// recovering the constant torques that made a motion.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "converter/coordinates_file.hpp"
#include "converter/storage.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/gradient/gradient.hpp"
#include "validation/optimize/reach.hpp"

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;

const std::string kArm = std::string(REDMAX_SOURCE_DIR) + "/osim_models/reach_arm.osim";
const std::vector<std::string> kArmCoordinates{"shoulder_flexion", "shoulder_adduction", "shoulder_rotation",
                                               "elbow_flexion"};

class TrackTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("redmax_track_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// a motion of the named coordinates: value(c, t) in radians, written in degrees or radians with
// full precision at the given times
void writeMotion(const std::string& file, const std::vector<std::string>& names, const std::vector<double>& times,
                 const std::function<double(size_t, double)>& value, bool in_degrees) {
  osim::Storage st;
  st.name = "motion";
  st.in_degrees = in_degrees;
  st.labels = names;
  st.time = times;
  st.data.resize(static_cast<Eigen::Index>(times.size()), static_cast<Eigen::Index>(names.size()));
  for (size_t r = 0; r < times.size(); ++r)
    for (size_t c = 0; c < names.size(); ++c)
      st.data(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) =
          value(c, times[r]) / (in_degrees ? osim::degreesToRadians() : 1.0);
  osim::StorageWriteOptions o;
  o.scientific = true;
  o.decimals = 17;
  osim::writeStorage(file, st, o);
}

// a smooth path per coordinate (rad), away from the elbow's limit
double pathValue(size_t c, double t) {
  return 0.1 * static_cast<double>(c + 1) * std::sin(3.0 * t + static_cast<double>(c)) + (c == 3 ? 0.4 : 0.0);
}

std::vector<double> rowTimes(double t1, double dt) {
  std::vector<double> t;
  for (int r = 0; r * dt <= t1 + 1e-12; ++r) t.push_back(r * dt);
  return t;
}

// rows every 12.5 ms, so that the 5 ms steps fall between them
const char* kParams = "torques:shoulder_flexion@2,elbow_flexion=0.5;qdot0:shoulder_adduction=0.2";

TEST_F(TrackTest, ObjectiveIsTheSumOverTheStepsOfTheConvertedInterpolatedFile) {
  const std::string deg = path("path_deg.mot"), rad = path("path_rad.mot");
  const std::vector<double> times = rowTimes(0.1, 0.0125);
  writeMotion(deg, kArmCoordinates, times, pathValue, true);
  writeMotion(rad, kArmCoordinates, times, pathValue, false);
  GradientSetup g = makeGradientSetup(kArm, SimulationModelOptions{}, "euler", 0.1, 0.005, kParams, "2*coords:" + deg);
  ASSERT_EQ(g.objective.coordinate_tracks.size(), 4u);
  const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, g.p0, false);
  // here: the run's states against the file's values, linear between rows, h sum over k = 1..N
  const adjoint::Trajectory tr = adjoint::simulateTrajectory(g.problem, g.p0);
  const double h = 0.005;
  double expected = 0.0;
  for (size_t k = 1; k < tr.states.size(); ++k) {
    const double t = tr.states[k].t;
    size_t i = 0;
    while (i + 2 < times.size() && times[i + 1] <= t) ++i;
    const double w = (t - times[i]) / (times[i + 1] - times[i]);
    for (size_t c = 0; c < kArmCoordinates.size(); ++c) {
      const int q = g.model.system->model().findCoordinate(kArmCoordinates[c]);
      const double target = (1.0 - w) * pathValue(c, times[i]) + w * pathValue(c, times[i + 1]);
      const double e = tr.states[k].q[q] - target;
      expected += 0.5 * 2.0 * h * e * e;
    }
  }
  EXPECT_GT(expected, 1e-4);
  EXPECT_NEAR(r.objective, expected, 1e-12 * expected);
  // the same motion in radians: the same objective up to the degree factor's round-off
  GradientSetup gr = makeGradientSetup(kArm, SimulationModelOptions{}, "euler", 0.1, 0.005, kParams, "2*coords:" + rad);
  EXPECT_NEAR(adjoint::evaluate(gr.problem, gr.objective, gr.p0, false).objective, expected, 1e-12 * expected);
  // chosen coordinates: only those
  GradientSetup ge = makeGradientSetup(kArm, SimulationModelOptions{}, "euler", 0.1, 0.005, kParams,
                                       "coords:" + deg + "@elbow_flexion");
  ASSERT_EQ(ge.objective.coordinate_tracks.size(), 1u);
  EXPECT_EQ(ge.objective.coordinate_tracks[0].coordinate, g.model.system->model().findCoordinate("elbow_flexion"));
}

// osim_models/running_leg_swing.mot (inDegrees=yes, 11 coordinates of running_leg.osim): the
// Rotational coordinates are converted from degrees, the pelvis translations (m) are not, and only
// the rows that bracket the run are kept
TEST_F(TrackTest, DegreesConvertOnlyRotationalCoordinates) {
  GradientSetup g = makeGradientSetup(std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg.osim",
                                      SimulationModelOptions{}, "euler", 0.05, 0.001, "torques:knee_angle_r",
                                      "coords:" + std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg_swing.mot");
  ASSERT_EQ(g.objective.coordinate_tracks.size(), 11u);
  const Model& model = g.model.system->model();
  int seen = 0;
  for (const auto& ct : g.objective.coordinate_tracks) {
    EXPECT_EQ(ct.t.size(), 11u);  // 0 .. 0.05 s at 200 Hz
    EXPECT_EQ(ct.t.front(), 0.0);
    if (ct.coordinate == model.findCoordinate("pelvis_ty")) {
      EXPECT_EQ(ct.value.front(), 1.02);  // m, as written
      ++seen;
    }
    if (ct.coordinate == model.findCoordinate("hip_flexion_r")) {
      EXPECT_EQ(ct.value.front(), -10.0 * osim::degreesToRadians());
      EXPECT_NEAR(ct.at(0.0025), 0.5 * (-10.0 - 9.66664738) * osim::degreesToRadians(), 1e-15);  // between rows
      ++seen;
    }
  }
  EXPECT_EQ(seen, 2);
}

TEST_F(TrackTest, AdjointMatchesCentralDifferences) {
  const std::string file = path("path.mot");
  writeMotion(file, kArmCoordinates, rowTimes(0.1, 0.0125), pathValue, true);
  for (const std::string objective :
       {"coords:" + file, "3*coords:" + file + "@elbow_flexion,shoulder_flexion;0.1*speed;coords:" + file}) {
    GradientSetup g = makeGradientSetup(kArm, SimulationModelOptions{}, "euler", 0.1, 0.005, kParams, objective);
    const adjoint::Result r = adjoint::evaluate(g.problem, g.objective, g.p0, true);
    const VecX fd = adjoint::finiteDifferenceGradient(g.problem, g.objective, g.p0);
    // measured 9.7e-11 and 8.1e-11 (the differences' own error, as for the marker terms)
    EXPECT_LE(adjoint::worstRelativeError(r.gradient, fd), 1e-9)
        << objective << "\nadjoint " << r.gradient.transpose() << "\ndifferences " << fd.transpose();
    EXPECT_GT(r.gradient.norm(), 1e-3);
  }
}

TEST_F(TrackTest, BadInputIsNamed) {
  const std::string file = path("path.mot");
  writeMotion(file, {"elbow_flexion", "pelvis_tilt"}, rowTimes(0.1, 0.01), pathValue, true);
  auto message = [&](const std::string& objective, double duration = 0.1) -> std::string {
    try {
      makeGradientSetup(kArm, SimulationModelOptions{}, "euler", duration, 0.005, "torques:elbow_flexion", objective);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "no error";
  };
  std::string m = message("coords:" + file + "@elbow_flexion,knee,hip");
  EXPECT_NE(m.find("the model has no coordinate named knee, hip"), std::string::npos) << m;
  m = message("coords:" + file + "@shoulder_flexion");
  EXPECT_NE(m.find("has no column for shoulder_flexion"), std::string::npos) << m;
  m = message("coords:" + file, 0.2);
  EXPECT_NE(m.find("does not cover the run [0.000000, 0.200000] s"), std::string::npos) << m;
  m = message("coords:" + file + "@elbow_flexion,elbow_flexion");
  EXPECT_NE(m.find("named twice"), std::string::npos) << m;
  m = message("coords:" + file + "@");
  EXPECT_NE(m.find("expected coordinate names after '@'"), std::string::npos) << m;
  // no coordinate of the model in the file
  const std::string other = path("other.mot");
  writeMotion(other, {"pelvis_tilt"}, rowTimes(0.1, 0.01), pathValue, true);
  m = message("coords:" + other);
  EXPECT_NE(m.find("has no column for any coordinate of the model"), std::string::npos) << m;
  // a malformed file: the reader's FILE:LINE
  const std::string broken = path("broken.mot");
  {
    std::ofstream f(broken);
    f << "broken\nversion=1\nnRows=2\nnColumns=2\ninDegrees=yes\nendheader\ntime\telbow_flexion\n0\t1\n0.1\tx\n";
  }
  m = message("coords:" + broken);
  EXPECT_EQ(m.rfind(broken + ":", 0), 0u) << m;
  m = message("coords:" + path("missing.mot"));
  EXPECT_EQ(m.rfind(path("missing.mot") + ":", 0), 0u) << m;
}

// a run of reach_arm with the given gradient parameters (params SPEC) at `truth`, its four
// coordinates written to `file` in degrees at every step
struct MadeMotion {
  adjoint::Trajectory tr;
  std::vector<int> q;  // kArmCoordinates' indices
};
MadeMotion makeMotion(const std::string& params, const VecX& truth, double duration, double dt, const std::string& file) {
  GradientSetup g = makeGradientSetup(kArm, SimulationModelOptions{}, "euler", duration, dt, params, "speed");
  MadeMotion m;
  m.tr = adjoint::simulateTrajectory(g.problem, truth);
  std::vector<double> times;
  for (const State& s : m.tr.states) times.push_back(s.t);
  for (const auto& c : kArmCoordinates) m.q.push_back(g.model.system->model().findCoordinate(c));
  writeMotion(
      file, kArmCoordinates, times,
      [&](size_t c, double t) { return m.tr.states[static_cast<size_t>(std::lround(t / dt))].q[m.q[c]]; }, true);
  return m;
}

// the tracking task on reach_arm: all four coordinates torqued and tracked from `file`
ReachOptions armTrack(const std::string& file, double duration, double dt) {
  ReachOptions o;
  o.task = "track";
  o.model_path = kArm;
  o.motion = file;
  o.coordinates = kArmCoordinates;
  o.duration = duration;
  o.dt = dt;
  return o;
}

const char* kArmTorques = "torques:shoulder_flexion,shoulder_adduction,shoulder_rotation,elbow_flexion";

// A motion made by a run with known constant torques (written in degrees at every step): tracking
// it from zero torques, L-BFGS on the adjoint gradient recovers them.
TEST_F(TrackTest, LbfgsRecoversTheTorquesThatMadeTheMotion) {
  const double duration = 0.3, dt = 0.01;
  const VecX truth = (VecX(4) << 2.0, -1.5, 0.3, 1.0).finished();  // N m, kArmCoordinates' order
  const std::string file = path("made.mot");
  const adjoint::Trajectory tr = makeMotion(kArmTorques, truth, duration, dt, file).tr;
  ReachOptions o = armTrack(file, duration, dt);
  o.tolerance = 1e-7;  // rad, RMS over the run
  o.max_simulations = 400;
  const ReachSetup s = makeReachSetup(o);
  ASSERT_EQ(s.gradient.objective.coordinate_tracks.size(), 4u);
  // at the true torques the objective is zero up to the file's round-off
  EXPECT_LT(adjoint::evaluate(s.gradient.problem, s.gradient.objective, truth, false).objective, 1e-24);
  const double j0 = adjoint::evaluate(s.gradient.problem, s.gradient.objective, VecX::Zero(4), false).objective;
  EXPECT_GT(j0, 1e-4);
  const ReachResult r = optimizeReach(s, "lbfgs");
  // measured: 36 simulations, objective 1.6e-16 from 0.52, RMS error 3.3e-8 rad, torques within
  // 3.7e-7 N m of the truth
  EXPECT_TRUE(r.reached) << r.stop << ", error " << r.error;
  EXPECT_LE(r.objective, stopObjective(o)) << r.stop;  // 1.5e-15, 3e-15 of the start
  EXPECT_LE((r.torques - truth).cwiseAbs().maxCoeff(), 2e-6) << r.torques.transpose();
  EXPECT_LT(r.simulations, 100) << r.stop;
  EXPECT_NEAR(r.error, trackingError(o, r.objective), 1e-15);
  // the replay: the tracked coordinates of the best run against the file
  const TrackReplay rp = replayTrack(s, r.torques);
  ASSERT_EQ(rp.coordinates.size(), 4u);
  EXPECT_EQ(rp.t.size(), tr.states.size());
  EXPECT_NEAR(rp.rms, r.error, 1e-9 * std::max(r.error, 1e-12) + 1e-15);
}

// A motion that starts moving: made by a run with known torques from known initial speeds. From
// the model's default speeds (rest) constant torques cannot follow it; with --initial-speeds free
// the speeds are parameters too and L-BFGS recovers both; --initial-speeds motion starts from the
// file's rates (second-order differences of a first-order run: off by about h a / 2).
TEST_F(TrackTest, InitialSpeedsFromTheMotionOrOptimized) {
  const double duration = 0.3, dt = 0.01;
  const VecX truth = (VecX(8) << 2.0, -1.5, 0.3, 1.0, 0.6, -0.4, 0.3, 0.8).finished();  // N m, then rad/s
  const std::string file = path("moving.mot");
  const MadeMotion made = makeMotion(
      std::string(kArmTorques) + ";qdot0:shoulder_flexion,shoulder_adduction,shoulder_rotation,elbow_flexion", truth,
      duration, dt, file);
  const adjoint::Trajectory& tr = made.tr;
  const std::vector<int>& q = made.q;
  ReachOptions o = armTrack(file, duration, dt);
  o.tolerance = 1e-6;
  o.max_simulations = 300;
  double error[3] = {0, 0, 0};
  const char* modes[3] = {"default", "motion", "free"};
  for (int m = 0; m < 3; ++m) {
    o.initial_speeds = modes[m];
    const ReachSetup s = makeReachSetup(o);
    const ReachResult r = optimizeReach(s, "lbfgs");
    error[m] = r.error;
    std::cout << "[ measured ] --initial-speeds " << modes[m] << ": RMS error " << r.error << " rad, " << r.simulations
              << " simulations; parameters " << r.torques.transpose() << "\n";
    if (m == 1) {
      // the start rates: the quadratic through the first three rows of the run's q_k gives
      // qdot_0 + h (qddot_0 - qddot_1 / 2), about h qddot / 2 off
      for (size_t c = 0; c < 4; ++c) {
        const double a0 = (tr.states[1].qdot[q[c]] - tr.states[0].qdot[q[c]]) / dt;
        const double a1 = (tr.states[2].qdot[q[c]] - tr.states[1].qdot[q[c]]) / dt;
        EXPECT_NEAR(s.gradient.problem.initial.qdot[q[c]], truth[4 + static_cast<Eigen::Index>(c)] + dt * (a0 - a1 / 2),
                    1e-9)
            << c;
      }
    }
    if (m == 2) {
      ASSERT_EQ(r.torques.size(), 8);
      EXPECT_EQ(s.gradient.param_names[4], "qdot0 shoulder_flexion");
      EXPECT_TRUE(r.reached) << r.stop;
      // measured: 117 simulations, RMS 9.0e-7 rad, parameters within 1.3e-5 of the truth
      EXPECT_LE((r.torques - truth).cwiseAbs().maxCoeff(), 1e-4) << r.torques.transpose();
      EXPECT_LT(r.simulations, 200) << r.stop;
    }
  }
  EXPECT_GT(error[0], 1e3 * o.tolerance) << "rest at the start should not track a moving start";
  EXPECT_LT(error[1], error[0]);
  EXPECT_LT(error[2], error[1]);
  o.initial_speeds = "sideways";
  EXPECT_THROW(makeReachSetup(o), std::invalid_argument);
}

// The tracking task on markers alone: reach_arm.osim's hand_point along the path a run with known
// elbow and shoulder flexion torques gave it, written as a TRC in mm; L-BFGS from zero torques
// brings the tracking objective (`--objective 'track:hand_point=FILE.trc'`) to the stop objective
TEST_F(TrackTest, TheTrackTaskTakesMarkersFromATrc) {
  const double duration = 0.2, dt = 0.01;
  GradientSetup g = makeGradientSetup(kArm, SimulationModelOptions{}, "euler", duration, dt,
                                      "torques:shoulder_flexion,elbow_flexion", "speed");
  const VecX truth = (VecX(2) << 1.5, 0.8).finished();
  const adjoint::Trajectory tr = adjoint::simulateTrajectory(g.problem, truth);
  const CoreMarker cm = findCoreMarker(g.model, "hand_point");
  ASSERT_GE(cm.body, 0);
  const std::string trc = path("hand.trc");
  {
    std::ofstream f(trc);
    f.precision(17);
    f << "PathFileType\t4\t(X/Y/Z)\thand.trc\n"
         "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n"
         "100\t100\t" << tr.states.size() << "\t1\tmm\t100\t1\t" << tr.states.size() << "\n"
         "Frame#\tTime\thand_point\t\t\n\t\tX1\tY1\tZ1\n";
    const Model& model = tr.system->model();
    SkeletonWorkspace sk(model);
    for (size_t k = 0; k < tr.states.size(); ++k) {
      calcKinematics(model, tr.states[k], sk);
      const Vec3 p = 1000.0 * transformPoint(sk.E_wi[cm.body], cm.point);
      f << k + 1 << "\t" << tr.states[k].t << "\t" << p[0] << "\t" << p[1] << "\t" << p[2] << "\n";
    }
  }
  ReachOptions o;
  o.task = "track";
  o.model_path = kArm;
  o.objective = "track:hand_point=" + trc;
  o.coordinates = {"shoulder_flexion", "elbow_flexion"};
  o.duration = duration;
  o.dt = dt;
  o.tolerance = 1e-6;  // m, RMS over the run
  o.max_simulations = 200;
  const ReachSetup s = makeReachSetup(o);
  ASSERT_EQ(s.gradient.objective.tracks.size(), 1u);
  EXPECT_TRUE(s.gradient.objective.coordinate_tracks.empty());
  const ReachResult r = optimizeReach(s, "lbfgs");
  // measured: 19 simulations, RMS error 7.5e-9 m, torques within 2.2e-6 N m of the truth
  EXPECT_TRUE(r.reached) << r.stop << ", error " << r.error;
  EXPECT_LE((r.torques - truth).cwiseAbs().maxCoeff(), 1e-5) << r.torques.transpose();
  EXPECT_LT(r.simulations, 60) << r.stop;
}

TEST_F(TrackTest, TheTrackTaskNamesItsInput) {
  ReachOptions o;
  o.task = "track";
  o.model_path = kArm;
  o.duration = 0.1;
  auto message = [&](const ReachOptions& x) -> std::string {
    try {
      makeReachSetup(x);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(message(o).find("needs --motion FILE.mot and/or --objective"), std::string::npos) << message(o);
  o.objective = "speed";
  EXPECT_NE(message(o).find("needs a tracking term"), std::string::npos) << message(o);
  o.objective.clear();
  const std::string file = path("path.mot");
  writeMotion(file, kArmCoordinates, rowTimes(0.1, 0.01), pathValue, true);
  o.motion = file + "@elbow";
  EXPECT_EQ(message(o), "--motion '" + file + "@elbow': the model has no coordinate named elbow") << message(o);
}

}  // namespace
}  // namespace redmax::validation
