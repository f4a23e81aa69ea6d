// `redmax simulate --engine simbody` against `--engine core` end to end (validation/simulate/simulate_simbody.hpp):
// the same STATES.sto columns, and trajectories that agree to 1e-6 (rad, rad/s) at every output row
// with tight tolerances on both sides (core rk45 rtol 1e-11; Simbody Merson accuracy 1e-10,
// constraint tolerance 1e-11):
//   - osim_models/double_pendulum_via.osim, via_muscle with 0.5 kg added (5 fibre points), 1 s;
//   - osim_models/finger.osim, FDP and FDS with 0.2 kg each added (5 fibre points, [D 6.2.5]), 1 s:
//     the finger is sensitive (a 1e-10 rad change of q0 grows to 1.6e-6 rad in 1 s,
//     tests/plugin/particle_finger_test.cpp), so both sides run near 1e-12: core rk45 rtol 1e-12,
//     Simbody --simbody-method feldberg --simbody-norm inf --rtol 3e-12 --atol 3e-13; q to 1e-6
//     rad, speeds to 2e-5 rad/s (peak 80 rad/s). The fibre points stay between the same path points
//     in these runs, which constrained particles need (plugin/simbody/particle_muscles.hpp); with 20
//     points on the pendulum one crosses the via point at t = 0.69 s and Simbody stops there;
//   - osim_models/double_pendulum_wrap.osim, wrap_muscle (Type III) with 1 kg added (10 fibre
//     points), 0.3 s.
// The energies of the two engines agree to 1e-6 J, the muscle mass changes the trajectory by more
// than the tolerance, and each summary states its CPU time. Also: CPodes (--integrator cvode)
// runs inside the redmax executable (docs/build.md trap 2) and agrees to 1e-5; a core-only integrator,
// an unknown engine, --no-qvv, a bad --simbody-method or --simbody-norm, and either of those without
// --engine simbody exit 2 with a message and write nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "converter/storage.hpp"
#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;
using redmax::osim::readStorage;
using redmax::osim::Storage;

class SimulateEngineCli : public ::testing::Test {
 public:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_simulate_engine_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  CmdResult run(const std::string& args) const { return runRedmax(dir_, "simulate " + args); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// largest difference of the columns whose label ends with `suffix` (q: "/value", qdot: "/speed")
double maxColumnDifference(const Storage& a, const Storage& b, const std::string& suffix) {
  double worst = 0.0;
  int compared = 0;
  for (int c = 0; c < a.numColumns(); ++c) {
    const std::string& l = a.labels[c];
    if (l.size() < suffix.size() || l.compare(l.size() - suffix.size(), suffix.size(), suffix) != 0) continue;
    const int cb = b.findColumn(l);
    if (cb < 0) return 1e300;
    worst = std::max(worst, (a.data.col(c) - b.data.col(cb)).cwiseAbs().maxCoeff());
    ++compared;
  }
  // no such column (or no row) would make any bound pass
  if (compared == 0 || a.numRows() == 0) return 1e300;
  return worst;
}

// the CPU seconds of the summary line "... s wall, X s CPU; ..." (-1 when absent)
double summaryCpu(const std::string& out) {
  const size_t at = out.find(" s CPU");
  if (at == std::string::npos) return -1.0;
  size_t begin = out.rfind(' ', at - 1);
  return std::stod(out.substr(begin + 1, at - begin - 1));
}

struct EngineCase {
  const char* file;
  const char* masses;
  int points;
  double duration;
  const char* core_flags = "--rtol 1e-11 --atol 1e-12";
  const char* simbody_flags = "--rtol 1e-10 --atol 1e-11";
  double qdot_tol = 1e-6;  ///< rad/s
};

void compareEngines(const SimulateEngineCli& t, const EngineCase& c, const std::string& tag) {
  const std::string base = "--model " + scene(c.file) + " --duration " + std::to_string(c.duration) +
                           " --full-precision --mass-points " + std::to_string(c.points);
  const std::string common = base + " --quiet";
  const CmdResult core = runRedmax(t.dir_, "simulate " + common + " --muscle-mass-kg " + c.masses + " " +
                                                c.core_flags + " --out " + t.path(tag + "_core.sto"));
  ASSERT_EQ(core.code, 0) << core.err;
  const CmdResult sb = runRedmax(t.dir_, "simulate " + base + " --muscle-mass-kg " + c.masses + " --engine simbody " +
                                              c.simbody_flags + " --out " + t.path(tag + "_simbody.sto"));
  ASSERT_EQ(sb.code, 0) << sb.err;
  const CmdResult plain = runRedmax(t.dir_, "simulate --model " + scene(c.file) + " --duration " +
                                                 std::to_string(c.duration) + " --full-precision --quiet --rtol 1e-11 "
                                                 "--atol 1e-12 --out " + t.path(tag + "_plain.sto"));
  ASSERT_EQ(plain.code, 0) << plain.err;
  const Storage a = readStorage(t.path(tag + "_core.sto")), b = readStorage(t.path(tag + "_simbody.sto")),
                p = readStorage(t.path(tag + "_plain.sto"));
  ASSERT_EQ(a.labels, b.labels);
  ASSERT_EQ(a.numRows(), b.numRows());
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(a.time.data(), a.numRows()) -
             Eigen::Map<const Eigen::VectorXd>(b.time.data(), b.numRows()))
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  const double dq = maxColumnDifference(a, b, "/value"), du = maxColumnDifference(a, b, "/speed");
  EXPECT_LT(dq, 1e-6);
  EXPECT_LT(du, c.qdot_tol);
  double dE = 0.0;
  for (const char* e : {"kinetic_energy", "potential_energy", "total_energy"})
    dE = std::max(dE, (a.data.col(a.findColumn(e)) - b.data.col(b.findColumn(e))).cwiseAbs().maxCoeff());
  EXPECT_LT(dE, 1e-6);
  // the muscles' mass matters at this tolerance
  EXPECT_GT(maxColumnDifference(a, p, "/value"), 1e-4);
  // the summaries (without --quiet) state the CPU time: run once more for them
  const double cpu_core = summaryCpu(runRedmax(t.dir_, "simulate " + base + " --muscle-mass-kg " + c.masses + " " +
                                                           c.core_flags + " --out " + t.path("x.sto"))
                                         .out);
  EXPECT_GE(cpu_core, 0.0);
  const double cpu_simbody = summaryCpu(sb.out);
  EXPECT_GE(cpu_simbody, 0.0) << sb.out;
  std::printf("  [%s] %g s: max |dq| %.3e rad, |dqdot| %.3e rad/s, |dE| %.3e J; CPU core %.3f s, Simbody %.3f s "
              "(summaries), rows %d\n",
              c.file, c.duration, dq, du, dE, cpu_core, cpu_simbody, a.numRows());
}

TEST_F(SimulateEngineCli, DoublePendulumViaSimbodyMatchesCore) {
  compareEngines(*this, {"double_pendulum_via.osim", "via_muscle=0.5", 5, 1.0}, "via");
}

TEST_F(SimulateEngineCli, FingerSimbodyMatchesCore) {
  compareEngines(*this,
                 {"finger.osim", "FDP=0.2,FDS=0.2", 5, 1.0, "--rtol 1e-12 --atol 1e-14",
                  "--simbody-method feldberg --simbody-norm inf --rtol 3e-12 --atol 3e-13", 2e-5},
                 "finger");
}

// Type III: the wrapping pendulum's muscle (1 kg, 10 fibre points) wraps the joint cylinder from
// the default pose; Simbody's particles follow the smooth wrap model through calcWrapPathMap
TEST_F(SimulateEngineCli, WrappingDoublePendulumSimbodyMatchesCore) {
  compareEngines(*this, {"double_pendulum_wrap.osim", "wrap_muscle=1", 10, 0.3}, "wrap");
}

TEST_F(SimulateEngineCli, SummaryStatesEngineAndCpuAndCvodeRuns) {
  const std::string common = "--model " + scene("double_pendulum_via.osim") +
                             " --duration 0.3 --muscle-mass-kg via_muscle=0.5 --mass-points 5 --full-precision";
  const CmdResult sb = run(common + " --engine simbody --rtol 1e-10 --atol 1e-11 --out " + path("m.sto"));
  ASSERT_EQ(sb.code, 0) << sb.err;
  EXPECT_NE(sb.out.find("engine simbody"), std::string::npos) << sb.out;
  EXPECT_GE(summaryCpu(sb.out), 0.0) << sb.out;
  // CPodes inside the executable that also links SUNDIALS (docs/build.md trap 2)
  const CmdResult cv = run(common + " --engine simbody --integrator cvode --rtol 1e-9 --atol 1e-11 --out " +
                           path("c.sto"));
  ASSERT_EQ(cv.code, 0) << cv.err;
  EXPECT_GE(summaryCpu(cv.out), 0.0) << cv.out;
  const Storage a = readStorage(path("m.sto")), b = readStorage(path("c.sto"));
  ASSERT_EQ(a.numRows(), b.numRows());
  EXPECT_LT(maxColumnDifference(a, b, "/value"), 1e-5);
  std::printf("  simbody merson vs cpodes over 0.3 s: %.3e rad\n", maxColumnDifference(a, b, "/value"));
}

TEST_F(SimulateEngineCli, RefusedOptionsExitTwoAndWriteNothing) {
  const std::string common = "--model " + scene("double_pendulum_via.osim") + " --duration 0.1 --out " + path("n.sto");
  for (const auto& [flags, expect] :
       std::vector<std::pair<std::string, std::string>>{{"--engine simbody --integrator euler", "rk45"},
                                                        {"--engine bullet", "--engine must be core or simbody"},
                                                        {"--engine simbody --no-qvv", "--no-qvv"},
                                                        {"--engine simbody --simbody-method rk4", "--simbody-method must be"},
                                                        {"--engine simbody --simbody-norm max", "--simbody-norm must be"},
                                                        {"--simbody-method feldberg", "needs --engine simbody"},
                                                        {"--engine core --simbody-norm inf", "needs --engine simbody"}}) {
    SCOPED_TRACE(flags);
    const CmdResult r = run(common + " " + flags);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("n.sto")));
  }
}

}  // namespace
