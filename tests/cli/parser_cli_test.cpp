// The parser contract of every `redmax` command (CLI11, cli/flags.hpp): parse errors (an unknown
// flag, a flag without its value, a value that is not a number, an unknown choice) exit 2 with
// `error: ...` on stderr and write nothing; `redmax COMMAND --help` exits 0 and lists every flag of
// the command; `redmax --help` lists the commands and `redmax --version` prints the version.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;

class ParserCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_parser_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    std::ofstream(dir_ / "q.mot") << "";  // exists: the parse errors below come before reading it
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  CmdResult run(const std::string& args) const { return runRedmax(dir_, args, true); }
  fs::path dir_;
};

TEST_F(ParserCli, ParseErrorsExitTwoWithErrorAndWriteNothing) {
  const std::string model = scene("double_pendulum_via.osim");
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      // unknown flags, in both spellings
      {"simulate --model " + model + " --duration 1 --out s.sto --bogus", "unknown option --bogus"},
      {"simulate --model " + model + " --duration 1 --out s.sto --bogus=3", "unknown option --bogus"},
      {"lengths --model " + model + " --coordinates q.mot --out s.sto --nope", "unknown option --nope"},
      {"convert " + model + " --jsn x.json", "unknown option --jsn"},
      {"demo --steps 3", "unknown option --steps"},
      {"bench --scenes chain2", "unknown option --scenes"},
      {"id --model " + model + " --coordinates q.mot --out s.sto --engines core", "unknown option --engines"},
      // a flag at the end without its value
      {"simulate --model " + model + " --out s.sto --duration", "--duration"},
      {"demo --dt", "--dt"},
      {"train-wrap --out n.txt --epochs", "--epochs"},
      // values that are not numbers
      {"simulate --model " + model + " --duration 1x --out s.sto", "--duration expects a number, got '1x'"},
      {"demo --dt abc", "--dt expects a number, got 'abc'"},
      {"bench --scene chain2 --repeats 2.5", "--repeats expects an integer, got '2.5'"},
      {"train-wrap --epochs many --out n.txt", "--epochs expects an integer, got 'many'"},
      {"flick --model " + model + " --mass heavy", "--mass expects a number, got 'heavy'"},
      {"simulate --model " + model + " --duration 1 --mass-points 0 --muscle-mass physiological --out s.sto",
       "--mass-points must be between 1 and 100000, got 0"},
      // choices
      {"demo --integrator rk4", "--integrator must be euler, symplectic, bdf1, sdirk2, rk45 or cvode, got 'rk4'"},
      {"bench --spherical cube", "--spherical must be gimbal or ball, got 'cube'"},
      {"id --model " + model + " --coordinates q.mot --out s.sto --muscle-mass heavy",
       "--muscle-mass must be none, physiological or transfer, got 'heavy'"},
      // positionals where a command takes none, and too many for convert
      {"simulate stray --model " + model + " --duration 1 --out s.sto", "simulate takes no positional arguments (got 'stray')"},
      {"convert " + model + " " + model, "convert takes one MODEL.osim"},
      {"nosuchcommand", "unknown command 'nosuchcommand'"},
      // a file that must exist, named first
      {"id --model " + model + " --coordinates missing.mot --out s.sto", "missing.mot: no such file (--coordinates)"},
  };
  for (const Case& c : cases) {
    const CmdResult r = run(c.args);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(r.out, "") << c.args;
  }
  for (const char* f : {"s.sto", "n.txt", "x.json"}) EXPECT_FALSE(fs::exists(dir_ / f)) << f;
}

TEST_F(ParserCli, EveryCommandsHelpExitsZeroAndListsItsFlags) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> commands = {
      {"convert", {"MODEL", "--json", "--strict", "--quiet"}},
      {"demo", {"--integrator", "--dt", "--duration", "--rtol", "--atol"}},
      {"flick",
       {"--model", "--integrators", "--gravity", "--mass", "--dt", "--dts", "--duration", "--impulse-time", "--target",
        "--energy-growth", "--csv"}},
      {"id",
       {"--setup", "--model", "--coordinates", "--external-loads", "--lowpass", "--t0", "--t1", "--forces-to-exclude",
        "--exact", "--opensim-compat", "--engine", "--inertia-fallback", "--out", "--full-precision", "--quiet",
        "--muscle-mass", "--muscles", "--mass-points", "--mass-region", "--specific-tension", "--muscle-density",
        "--transfer-body", "--transfer-fraction", "--wrap", "--wrap-width", "--wrap-network"}},
      {"lengths",
       {"--model", "--coordinates", "--out", "--wrap", "--wrap-width", "--wrap-network", "--wrap-lengths", "--all-paths",
        "--full-precision", "--quiet"}},
      {"simulate",
       {"--model", "--duration", "--out", "--integrator", "--dt", "--rtol", "--atol", "--max-step", "--output-dt",
        "--initial", "--initial-time", "--muscle-mass-kg", "--no-qvv", "--impulse", "--engine", "--simbody-method",
        "--simbody-norm", "--progress", "--quiet", "--full-precision", "--muscle-mass", "--mass-points", "--wrap"}},
      {"validate",
       {"--setup", "--model", "--coordinates", "--reference", "--published", "--tolerance", "--max-tolerance",
        "--engine-tolerance", "--interpolation", "--no-simbody", "--mass-sweep", "--sweep-columns", "--report",
        "--no-plots", "--gnuplot", "--quiet", "--muscle-mass", "--wrap"}},
      {"bench",
       {"--scene", "--repeats", "--batches", "--json", "--integrators", "--spherical", "--dt", "--id-setup",
        "--id-model"}},
      {"work-precision",
       {"--report", "--quick", "--models", "--scenes", "--integrators", "--studies", "--shared", "--gnuplot",
        "--no-plots"}},
      {"train-wrap",
       {"--surface", "--hidden", "--samples", "--epochs", "--batch", "--lr", "--seed", "--threshold", "--time-limit",
        "--threads", "--shards", "--init", "--out", "--report", "--compare", "--nets", "--untrained", "--muscles",
        "--mass-points", "--width", "--study", "--thresholds", "--architectures", "--pendulums", "--count",
        "--duration", "--tol", "--fd-jdot"}},
  };
  for (const auto& [name, flags] : commands) {
    const CmdResult r = run(name + " --help");
    EXPECT_EQ(r.code, 0) << name << "\n" << r.err;
    EXPECT_EQ(r.err, "") << name;
    for (const std::string& f : flags) EXPECT_NE(r.out.find(f), std::string::npos) << name << ": " << f << "\n" << r.out;
    EXPECT_NE(r.out.find("--help"), std::string::npos) << name;
    // --help wins over the other flags, valid or not
    EXPECT_EQ(run(name + " --quiet --help").code, 0) << name;
  }
  // the top level lists every command with its summary
  const CmdResult top = run("--help");
  EXPECT_EQ(top.code, 0) << top.err;
  for (const auto& [name, flags] : commands) EXPECT_NE(top.out.find(name), std::string::npos) << name << "\n" << top.out;
  EXPECT_NE(top.out.find("exit codes: 0 success, 1 the run failed"), std::string::npos) << top.out;
  EXPECT_EQ(run("help").code, 0);
  EXPECT_EQ(run("").code, 2);  // no command: the help, as a usage error
}

TEST_F(ParserCli, VersionPrintsTheVersion) {
  const CmdResult r = run("--version");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("redmax ", 0), 0u) << r.out;
  EXPECT_EQ(r.out.back(), '\n');
}

TEST_F(ParserCli, ValuesTakeBothSpellingsAndTheLastRepeatWins) {
  // --name=value and --name value; a repeated flag takes its last value (as before CLI11)
  const std::string model = scene("double_pendulum_via.osim");
  const CmdResult r =
      run("simulate --model=" + model + " --duration 0.5 --duration=0.05 --integrator euler --dt 0.01 --out s.sto");
  ASSERT_EQ(r.code, 0) << r.err;
  const redmax::osim::Storage s = redmax::osim::readStorage((dir_ / "s.sto").string());
  EXPECT_NEAR(s.time.back(), 0.05, 1e-12);
  // a negative number is a value, not a flag
  const CmdResult neg = run("simulate --model " + model + " --duration -1 --out s2.sto");
  EXPECT_EQ(neg.code, 2);
  EXPECT_NE(neg.err.find("--duration must be positive"), std::string::npos) << neg.err;
}

}  // namespace
