// The ForwardTool library (validation/forward/forward_tool.hpp):
//   - CoordinateActuators driven by a ControlSet add optimal_force * u to f (the double pendulum);
//   - OpenSim 3 state names in a states file, closest earlier row;
//   - OpenSim's own ForwardTool standard for arm26 (Applications/Forward/tests: Thelen2003Muscle_
//     Deprecated via --muscle-class, SO controls, initial states, std_arm26_states.sto): every state
//     at the first and last rows within OpenSim's 5e-3 (testForward.cpp), and the RMS of every
//     state over the run within a bound near the measured one (docs/forward.md).
#include "validation/forward/forward_tool.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "core/dynamics/muscle_force_term.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;

std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }

struct TempDir {
  TempDir() : path(fs::temp_directory_path() / ("redmax_forward_tool_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path / name) << text;
    return (path / name).string();
  }
  fs::path path;
};

// OpenSim's CorrectionController (testForward's subject01_Setup_Forward_Controller): a corrector of
// optimal force 1 on every unconstrained coordinate, -(kp (q - q_d) + kv (u - u_d)) with the desired
// states the tool's states_file linearly interpolated at t. Closed form at a state between rows.
TEST(ForwardTool, CorrectionControllerPullsTowardTheStatesFile) {
  const std::string model = shared("opensim-models/Models/DoublePendulum/double_pendulum.osim");
  if (!fs::exists(model)) GTEST_SKIP() << "shared OpenSim data not found: " << model;
  TempDir dir;
  dir.write("states.sto", "s\nversion=1\nnRows=2\nnColumns=5\ninDegrees=no\nendheader\n"
                          "time\tq1\tq1_u\tq2\tq2_u\n0\t0.1\t0.5\t0.2\t-0.5\n1\t0.3\t1.5\t-0.2\t0.5\n");
  ForwardToolSettings s;
  s.setup_file = dir.write("setup.xml", "<OpenSimDocument Version=\"40000\"><ForwardTool name=\"p\"><model_file>" + model +
                                            "</model_file><initial_time>0</initial_time><final_time>0.5</final_time>"
                                            "<ControllerSet><objects><CorrectionController name=\"cc\"><kp>16</kp><kv>8</kv>"
                                            "</CorrectionController></objects></ControllerSet>"
                                            "<states_file>states.sto</states_file></ForwardTool></OpenSimDocument>");
  const ForwardTool tool(s);
  const System& sys = tool.system();
  State st = tool.initialState();
  st.t = 0.25;
  st.q << 0.4, -0.1;
  st.qdot << 0.2, 0.3;
  DynamicsWorkspace ws(sys);
  sys.calcMassAndForce(st, ws);
  System bare(sys.model());
  DynamicsWorkspace wb(bare);
  bare.calcMassAndForce(st, wb);
  // desired at t = 0.25: q1 0.15, u1 0.75, q2 0.1, u2 -0.25
  EXPECT_NEAR(ws.f[0] - wb.f[0], -(16 * (0.4 - 0.15) + 8 * (0.2 - 0.75)), 1e-12);
  EXPECT_NEAR(ws.f[1] - wb.f[1], -(16 * (-0.1 - 0.1) + 8 * (0.3 + 0.25)), 1e-12);
  // without a states_file the controller has nothing to correct toward: an error at its line
  s.setup_file = dir.write("nostates.xml", "<OpenSimDocument Version=\"40000\"><ForwardTool name=\"p\"><model_file>" + model +
                                               "</model_file>\n<ControllerSet><objects>\n<CorrectionController name=\"cc\"/>"
                                               "</objects></ControllerSet></ForwardTool></OpenSimDocument>");
  try {
    ForwardTool bad(s);
    ADD_FAILURE() << "a CorrectionController without a states_file was accepted";
  } catch (const osim::ConvertError& e) {
    EXPECT_EQ(e.line(), 3) << e.what();
    EXPECT_NE(std::string(e.what()).find("states_file"), std::string::npos) << e.what();
  }
}

TEST(ForwardTool, CoordinateActuatorsAddOptimalForceTimesControl) {
  const std::string model = shared("opensim-models/Models/DoublePendulum/double_pendulum.osim");
  if (!fs::exists(model)) GTEST_SKIP() << "shared OpenSim data not found: " << model;
  TempDir dir;
  dir.write("c.xml", "<ControlSet><objects><ControlLinear name=\"Torq2.excitation\"><x_nodes>"
                     "<ControlLinearNode><t>0</t><value>3</value></ControlLinearNode>"
                     "</x_nodes></ControlLinear></objects></ControlSet>");
  dir.write("states.sto", "s\nversion=1\nnRows=2\nnColumns=3\ninDegrees=no\nendheader\n"
                          "time\tq1\tq2_u\n0\t0.1\t0.5\n0.5\t0.2\t-0.5\n");
  ForwardToolSettings s;
  s.setup_file = dir.write("setup.xml", "<ForwardTool name=\"p\"><model_file>" + model +
                                            "</model_file><initial_time>0.4</initial_time>"
                                            "<final_time>0.5</final_time><controls_file>c.xml</controls_file>"
                                            "<states_file>states.sto</states_file></ForwardTool>");
  const ForwardTool tool(s);
  const System& sys = tool.system();
  ASSERT_EQ(sys.controlNames(), (std::vector<std::string>{"Torq1", "Torq2"}));
  // the closest earlier row (t = 0), OpenSim 3 names
  const State& s0 = tool.initialState();
  EXPECT_DOUBLE_EQ(s0.t, 0.4);
  EXPECT_DOUBLE_EQ(s0.q[0], 0.1);
  EXPECT_DOUBLE_EQ(s0.qdot[1], 0.5);
  // f with the controls minus f without: optimal_force (1) * 3 on q2
  DynamicsWorkspace ws(sys);
  sys.calcMassAndForce(s0, ws);
  const VecX f = ws.f;
  ASSERT_EQ(ws.controls.size(), 2);
  EXPECT_DOUBLE_EQ(ws.controls[1], 3.0);
  System bare(sys.model());
  DynamicsWorkspace wb(bare);
  bare.calcMassAndForce(s0, wb);
  EXPECT_NEAR(f[1] - wb.f[1], 3.0, 1e-12);
  EXPECT_NEAR(f[0] - wb.f[0], 0.0, 1e-12);
  // the same tool-level controls_file in a version-40000 document: OpenSim 4.6 ignores it (it reads
  // one only before version 10904; measured with OpenSim 4.6: every control 0), and so does redmax,
  // naming it
  s.setup_file = dir.write("setup40000.xml", "<OpenSimDocument Version=\"40000\"><ForwardTool name=\"p\"><model_file>" +
                                                 model + "</model_file><initial_time>0.4</initial_time>"
                                                 "<final_time>0.5</final_time><controls_file>c.xml</controls_file>"
                                                 "<states_file>states.sto</states_file></ForwardTool></OpenSimDocument>");
  const ForwardTool modern(s);
  bool named = false;
  for (const auto& w : modern.setup().warnings) named = named || w.find("controls_file 'c.xml' is ignored") != std::string::npos;
  EXPECT_TRUE(named);
  DynamicsWorkspace wm(modern.system());
  modern.system().calcMassAndForce(modern.initialState(), wm);
  for (int k = 0; k < wm.controls.size(); ++k) EXPECT_EQ(wm.controls[k], 0.0);
  const ForwardResult r = tool.run();
  ASSERT_FALSE(r.failed) << r.failure;
  EXPECT_EQ(r.states.numRows(), 11);
}

// a wrapped (Type III) path: the generalized force direction is the polyline through the points
// held in their bodies (OpenSim's); over a cylinder (a geodesic wrap) it equals d(length)/dq
TEST(ForwardTool, WrappedPathForceDirectionIsTheLengthGradientOverACylinder) {
  const std::string scene = std::string(REDMAX_SOURCE_DIR) + "/osim_models/double_pendulum_wrap.osim";
  SimulationModel m = loadSimulationModel(scene, SimulationModelOptions{});
  const MusculoskeletalModel& mm = m.build.model;
  ASSERT_EQ(mm.numMuscles(), 1);
  ASSERT_TRUE(mm.muscleModels()[0]) << "no force model for " << mm.muscleClasses()[0];
  const Model& sk = mm.skeleton();
  const MuscleForceTerm term(sk, mm.muscles(), mm.muscleModels());
  int checked = 0;
  for (double a : {0.3, 0.9, 1.6, 2.2}) {
    State s;
    s.q = VecX::Constant(sk.nr(), a);
    s.q[0] = -0.4 * a;
    s.qdot = VecX::LinSpaced(sk.nr(), 0.5, -1.0);
    SkeletonWorkspace ws(sk);
    calcKinematics(sk, s, ws);
    double len, speed;
    VecX dl;
    term.calcPath(sk, s, ws, 0, len, speed, dl);
    VecX fd(sk.nr());
    std::vector<Mat4> E;
    for (int j = 0; j < sk.nr(); ++j) {
      VecX qp = s.q, qm = s.q;
      qp[j] += 1e-6;
      qm[j] -= 1e-6;
      calcBodyPoses(sk, qp, E);
      const double lp = calcPathLength(sk, mm.muscles()[0].path, qp, E);
      calcBodyPoses(sk, qm, E);
      fd[j] = (lp - calcPathLength(sk, mm.muscles()[0].path, qm, E)) / 2e-6;
    }
    EXPECT_LE((dl - fd).norm(), 1e-6 * (1 + fd.norm())) << "q = " << s.q.transpose();
    EXPECT_NEAR(speed, fd.dot(s.qdot), 1e-6 * (1 + std::abs(speed)));
    ++checked;
  }
  EXPECT_EQ(checked, 4);
}

// OpenSim 3 label of std_arm26_states.sto -> our column
int ourColumn(const osim::Storage& ours, const std::string& label) {
  std::string key;
  if (label.find('.') != std::string::npos) {
    key = "/forceset/" + label.substr(0, label.find('.')) + "/" + label.substr(label.find('.') + 1);
    return ours.findColumn(key);
  }
  const bool speed = label.size() > 2 && label.compare(label.size() - 2, 2, "_u") == 0;
  const std::string coord = speed ? label.substr(0, label.size() - 2) : label;
  const std::string tail = "/" + coord + (speed ? "/speed" : "/value");
  for (int j = 0; j < ours.numColumns(); ++j) {
    const std::string& l = ours.labels[j];
    if (l.size() >= tail.size() && l.compare(l.size() - tail.size(), tail.size(), tail) == 0) return j;
  }
  return -1;
}

TEST(ForwardTool, Arm26MatchesOpenSimsForwardStandard) {
  const std::string dir = shared("opensim-core/Applications/Forward/tests/resources");
  if (!fs::exists(dir + "/arm26_Setup_Forward.xml")) GTEST_SKIP() << "shared OpenSim data not found: " << dir;
  const osim::Storage std_states = osim::readStorage(dir + "/std_arm26_states.sto");
  ForwardToolSettings s;
  s.setup_file = dir + "/arm26_Setup_Forward.xml";
  s.muscle_class = "Thelen2003Muscle_Deprecated";
  s.output_times = std_states.time;
  std::unique_ptr<ForwardTool> tool;
  try {
    tool = std::make_unique<ForwardTool>(s);
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
  if (tool->system().numStates() == 0)
    GTEST_SKIP() << "no Hill muscle model for Thelen2003Muscle_Deprecated in this build: the arm26 standard needs one";
  const ForwardResult r = tool->run();
  ASSERT_FALSE(r.failed) << r.failure;
  ASSERT_EQ(r.states.numRows(), std_states.numRows());
  // OpenSim's 5e-3 at the first and last rows (testForward.cpp) for every state; the RMS over the
  // run within 1.5 times the measured value (docs/forward.md §5: measured in the comment), except
  // the activations: their differences (1e-9 to 2e-6) lie below the run's rk45 tolerance 1e-5 and
  // follow its step sequence, which round-off in qddot changes (BIClong's went from 1.1e-6 to
  // 1.6e-6 when the articulated-body pass was re-associated, 2026-12-07), so they are held to
  // that tolerance
  struct Bound {
    double end, rms;
  };
  static const std::map<std::string, double> rms_bound = {
      {"r_shoulder_elev", 1.1e-3},        // 7.4e-4
      {"r_elbow_flex", 3.3e-3},           // 2.2e-3
      {"r_shoulder_elev_u", 6.2e-3},      // 4.1e-3
      {"r_elbow_flex_u", 1.8e-2},         // 1.2e-2
      {"TRIlong.activation", 1e-5},       // 6.8e-9
      {"TRIlong.fiber_length", 4.7e-5},   // 3.1e-5
      {"TRIlat.activation", 1e-5},      // 8.4e-7
      {"TRIlat.fiber_length", 6.3e-5},    // 4.2e-5
      {"TRImed.activation", 1e-5},      // 8.1e-7
      {"TRImed.fiber_length", 5.7e-5},    // 3.8e-5
      {"BIClong.activation", 1e-5},     // 1.1e-6
      {"BIClong.fiber_length", 9.3e-5},   // 6.2e-5
      {"BICshort.activation", 1e-5},    // 1.1e-6
      {"BICshort.fiber_length", 9.6e-5},  // 6.4e-5
      // 2.6e-7 on the articulated forward route (Auto), 1.3e-7 on the dense one: rk45 at 1e-5
      // takes other steps when qddot differs by round-off
      {"BRA.activation", 1e-5},
      {"BRA.fiber_length", 5.1e-5},       // 3.4e-5
  };
  auto bound = [](const std::string& label) {
    const auto it = rms_bound.find(label);
    return Bound{5e-3, it == rms_bound.end() ? 0.0 : it->second};
  };
  double worst_end = 0.0;
  for (int j = 0; j < std_states.numColumns(); ++j) {
    const std::string& label = std_states.labels[j];
    const int c = ourColumn(r.states, label);
    ASSERT_GE(c, 0) << label;
    const int last = std_states.numRows() - 1;
    const double d0 = std::abs(r.states.data(0, c) - std_states.data(0, j));
    const double d1 = std::abs(r.states.data(last, c) - std_states.data(last, j));
    const Bound b = bound(label);
    EXPECT_LE(d0, 5e-3) << label;
    EXPECT_LE(d1, b.end) << label;
    worst_end = std::max(worst_end, d1);
    double ss = 0.0;
    for (int k = 0; k <= last; ++k) ss += std::pow(r.states.data(k, c) - std_states.data(k, j), 2);
    const double rms = std::sqrt(ss / (last + 1));
    std::printf("[ measured ] arm26 forward %-22s first %.1e  last %.3e  rms %.3e\n", label.c_str(), d0, d1, rms);
    EXPECT_LE(rms, b.rms) << label;
  }
  std::printf("[ measured ] arm26 forward: worst last-row difference %.3e, %ld steps, %ld rhs, %.3f s wall\n",
              worst_end, r.stats.steps, r.stats.rhs_evals, r.wall_s);
}

}  // namespace
}  // namespace redmax::validation
