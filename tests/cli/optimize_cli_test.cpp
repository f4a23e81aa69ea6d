// `redmax optimize --task reach` end to end (docs/gradients.md §7): the report folder (report.md
// with every method, one CSV per method whose rows are the simulations the table counts, the plot
// when gnuplot exists, no temporary folder left), and bad input exiting 2 with `error: ...`.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "converter/storage.hpp"
#include "tests/cli/cli_test_util.hpp"
#include "validation/gradient/gradient.hpp"

namespace {

using namespace redmax::cli_test;
namespace fs = std::filesystem;

class OptimizeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_optimize_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  CmdResult run(const std::string& args) const {
    return runRedmax(dir_, "optimize --task reach --model " + scene("reach_arm.osim") + " " + args);
  }
  fs::path dir_;
};

const std::string kReach = "--point 0,-0.08,0 --target 0.25,-0.55,0.05 --duration 0.3 --dt 0.01";

TEST_F(OptimizeCli, WritesTheReport) {
  const fs::path report = dir_ / "reach";
  const CmdResult r = run(kReach + " --method lbfgs,nelder-mead --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("lbfgs: simulation 1, J = "), std::string::npos) << r.err;  // progress
  const std::string md = slurp(report / "report.md");
  for (const std::string m : {"lbfgs", "nelder-mead"}) {
    EXPECT_NE(md.find("| " + m + " | "), std::string::npos) << md;
    // one CSV row per simulation the summary counts
    const std::string csv = slurp(report / (m + "_iterations.csv"));
    long rows = -1;  // the header
    for (char c : csv) rows += c == '\n';
    const auto at = r.out.find("\n" + m + " ");
    ASSERT_NE(at, std::string::npos) << r.out;
    EXPECT_EQ(std::stol(r.out.substr(at + 1 + m.size())), rows) << r.out;
    EXPECT_EQ(csv.rfind("evaluation,simulations,step_evaluations,seconds,objective,best_objective,error_m\n", 0), 0u);
  }
  EXPECT_NE(md.find("torque elbow_flexion"), std::string::npos) << md;
  // the lumped arm's gradients take the analytic route (docs/gradients.md §2.1), said in both places
  EXPECT_NE(r.out.find("lbfgs step Jacobians: analytic (derivatives of inverse dynamics"), std::string::npos) << r.out;
  EXPECT_NE(md.find("- lbfgs step Jacobians: analytic (derivatives of inverse dynamics"), std::string::npos) << md;
  EXPECT_EQ(md.find("- nelder-mead step Jacobians"), std::string::npos) << md;
  if (md.find("plot skipped") == std::string::npos) {
    EXPECT_TRUE(fs::exists(report / "objective.png") || fs::exists(report / "objective.svg")) << md;
  }
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST_F(OptimizeCli, BadInputExitsTwo) {
  CmdResult r = run(kReach + " --body foot");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("error: --body 'foot': no body named so in ", 0), 0u) << r.err;
  r = run("--target 0.2,-0.5 --duration 0.3");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: --target '0.2,-0.5': must be three numbers X,Y,Z (m, ground)\n");
  r = run("--target 0.2,nan,0 --duration 0.3");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("error: --target", 0), 0u) << r.err;
  r = run(kReach + " --method gradient-descent");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err.rfind("error: --method 'gradient-descent': unknown", 0), 0u) << r.err;
  r = run("--duration 0.3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("optimize needs --target"), std::string::npos) << r.err;
}

// --drive excitations: the muscles' excitation nodes drive the block of tug_of_war_step.osim; the
// report adds the best run (CSV with the excitations and tendon forces, and its plot); the
// excitation flags without --drive excitations exit 2
TEST_F(OptimizeCli, ExcitationDriveWritesTheBestRun) {
  const fs::path report = dir_ / "excite";
  const CmdResult r = runRedmax(dir_, "optimize --task reach --model " + scene("tug_of_war_step.osim") +
                                          " --body block --target 0.03,0,0 --duration 0.2 --dt 0.001 --drive "
                                          "excitations --nodes 3 --initial-excitation 0.5 --method lbfgs "
                                          "--muscle-mass-kg left_muscle=0.5 --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("6 excitation nodes"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("lbfgs excitations: excitation left_muscle node 1/3="), std::string::npos) << r.out;
  // Hill-type muscles take the analytic route, their term differenced alone, and the output says so
  EXPECT_NE(r.out.find("lbfgs step Jacobians: analytic (derivatives of inverse dynamics, docs/gradients.md §2.1); the "
                       "forces and states of 2 Hill-type muscles ('left_muscle', ...) by central differences of their "
                       "term"),
            std::string::npos)
      << r.out;
  const std::string csv = slurp(report / "best_run.csv");
  EXPECT_EQ(csv.rfind("time,hand_x,hand_y,hand_z,lumped_hand_x,lumped_hand_y,lumped_hand_z,excitation_left_muscle,"
                      "excitation_right_muscle,tendon_force_left_muscle,tendon_force_right_muscle\n", 0), 0u) << csv;
  long rows = -1;
  for (char c : csv) rows += c == '\n';
  EXPECT_EQ(rows, 201);  // t = 0 .. 0.2 s at 1 ms
  const std::string md = slurp(report / "report.md");
  EXPECT_NE(md.find("the same excitations on the lumped model"), std::string::npos) << md;
  if (md.find("plot skipped") == std::string::npos) {
    EXPECT_TRUE(fs::exists(report / "best_run.png") || fs::exists(report / "best_run.svg")) << md;
  }
  const CmdResult bad = run(kReach + " --nodes 3");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("error: --nodes: needs --drive excitations"), std::string::npos) << bad.err;
}

// --task track: a motion made here by a run of reach_arm.osim with constant shoulder and elbow
// flexion torques (written in degrees); L-BFGS finds the torques again, prints progress, and the
// report has the tracked coordinates against the motion (CSV and plot); bad input exits 2
TEST_F(OptimizeCli, TrackTaskRecoversTheTorquesOfAMotion) {
  using namespace redmax;
  validation::GradientSetup g =
      validation::makeGradientSetup(scene("reach_arm.osim"), validation::SimulationModelOptions{}, "euler", 0.2, 0.01,
                                    "torques:shoulder_flexion,elbow_flexion", "speed");
  const adjoint::Trajectory tr = adjoint::simulateTrajectory(g.problem, (VecX(2) << 1.5, 0.8).finished());
  osim::Storage st;
  st.name = "made";
  st.in_degrees = true;
  st.labels = g.model.coordinate_names;
  st.data.resize(static_cast<Eigen::Index>(tr.states.size()), static_cast<Eigen::Index>(st.labels.size()));
  for (size_t k = 0; k < tr.states.size(); ++k) {
    st.time.push_back(tr.states[k].t);
    for (size_t c = 0; c < st.labels.size(); ++c)
      st.data(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(c)) =
          tr.states[k].q[static_cast<Eigen::Index>(c)] * 180.0 / M_PI;
  }
  osim::StorageWriteOptions wo;
  wo.scientific = true;
  wo.decimals = 17;
  const fs::path motion = dir_ / "made.mot";
  osim::writeStorage(motion.string(), st, wo);

  const fs::path report = dir_ / "track";
  const std::string base = "optimize --task track --model " + scene("reach_arm.osim") + " --duration 0.2 --dt 0.01 ";
  const CmdResult r = runRedmax(dir_, base + "--motion " + motion.string() +
                                          " --coordinates shoulder_flexion,elbow_flexion --method lbfgs --tolerance "
                                          "1e-6 --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("track: reach_arm, 2 torques, 4 tracked coordinates"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("lbfgs: simulation 1, J = "), std::string::npos) << r.err;
  for (const auto& [name, value] : {std::pair<std::string, double>{"shoulder_flexion", 1.5}, {"elbow_flexion", 0.8}}) {
    const auto at = r.out.find("torque " + name + "=");
    ASSERT_NE(at, std::string::npos) << r.out;
    // measured 1.2e-5 and 3.2e-6 N m off at the RMS tolerance 1e-6 rad
    EXPECT_NEAR(std::stod(r.out.substr(at + 8 + name.size())), value, 1e-4) << r.out;
  }
  const std::string md = slurp(report / "report.md");
  EXPECT_NE(md.find("# Tracking task"), std::string::npos) << md;
  EXPECT_NE(md.find("| lbfgs | "), std::string::npos) << md;
  const std::string csv = slurp(report / "best_run.csv");
  EXPECT_EQ(csv.rfind("time,shoulder_flexion,shoulder_flexion_motion,", 0), 0u) << csv;
  long rows = -1;
  for (char c : csv) rows += c == '\n';
  EXPECT_EQ(rows, 21);  // t = 0 .. 0.2 s at 10 ms
  EXPECT_TRUE(fs::exists(report / "lbfgs_iterations.csv"));
  if (md.find("plot skipped") == std::string::npos) {
    EXPECT_TRUE(fs::exists(report / "tracking.png") || fs::exists(report / "tracking.svg")) << md;
  }

  CmdResult bad = runRedmax(dir_, base);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("needs --motion and/or --objective"), std::string::npos) << bad.err;
  bad = runRedmax(dir_, base + "--motion " + motion.string() + " --target 0,0,0");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("error: --target: not used by --task track"), std::string::npos) << bad.err;
  bad = run(kReach + " --motion " + motion.string());
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("error: --motion: needs --task track"), std::string::npos) << bad.err;
  bad = run(kReach + " --initial-speeds motion");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("error: --initial-speeds: needs --task track"), std::string::npos) << bad.err;
  bad = runRedmax(dir_, base + "--motion " + motion.string() + " --initial-speeds sideways");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--initial-speeds"), std::string::npos) << bad.err;
  bad = runRedmax(dir_, "optimize --task track --model " + scene("reach_arm.osim") + " --duration 0.3 --motion " +
                            motion.string());
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("error: --motion '" + motion.string() + "': '" + motion.string() + "' does not cover the run"),
            std::string::npos) << bad.err;
}

}  // namespace
