// The wrap flags of the MUSCLE-MASS OPTIONS (cli/muscle_mass_flags.hpp) end to end: every value of
// --wrap is accepted where a model with muscle mass is built (simulate, id, validate), bad values and
// flags that would do nothing exit 2 with a clear message, the summary says which wrapping muscles
// carry mass, and a wrapping muscle with mass on the smooth model conserves energy through
// `redmax simulate` (the double pendulum of Fig. 6.5 and the running leg's gastrocnemii).
// Energy bounds are relative drifts max|E(t) - E(0)| / max(|E(0)|, max T) of the written columns.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "converter/storage.hpp"
#include "tests/cli/cli_test_util.hpp"
#include "validation/report/json_value.hpp"

namespace {

using namespace redmax::cli_test;

using redmax::osim::readStorage;
using redmax::osim::Storage;
using redmax::validation::JsonValue;

// largest |E(t_{i+1}) - E(t_i)| between written rows, J
double largestEnergyStep(const Storage& s) {
  const int e = s.findColumn("total_energy");
  double worst = 0.0;
  for (int i = 0; i + 1 < s.numRows(); ++i) worst = std::max(worst, std::abs(s.data(i + 1, e) - s.data(i, e)));
  return worst;
}

class WrapFlagsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_wrap_flags_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  CmdResult run(const std::string& args) const { return runRedmax(dir_, args); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// physiological mass at 50 kg/m^3 (0.02 kg: more would leave the 2 cm rod link1 non-physical)
const std::string kPendulum =
    "simulate --model " + scene("double_pendulum_wrap.osim") + " --muscle-mass physiological --muscle-density 50";

TEST_F(WrapFlagsCli, EveryWrapValueIsAcceptedAndTheSummarySaysWhoCarriesMass) {
  struct Case {
    std::string flags, expect;
  };
  const std::vector<Case> cases = {
      {"", "wrapping (Type III): 1 of 1 carry mass (wrap model smooth, width 0.05 radius)"},  // the default
      {"--wrap smooth", "wrapping (Type III): 1 of 1 carry mass (wrap model smooth, width 0.05 radius)"},
      {"--wrap smooth --wrap-width 0.004", "wrapping (Type III): 1 of 1 carry mass (wrap model smooth, width 0.004 m)"},
      {"--wrap exact", "wrapping (Type III): 1 of 1 carry mass (wrap model exact)"},
      {"--wrap lumped", "wrapping (Type III): 0 of 1 carry mass (wrap mass off)"},
  };
  for (const Case& c : cases) {
    const CmdResult r = run(kPendulum + " --duration 0.05 " + c.flags + " --out " + path("s.sto"));
    ASSERT_EQ(r.code, 0) << c.flags << "\n" << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.flags << "\n" << r.err;
    const bool lumped = c.flags == "--wrap lumped";
    EXPECT_EQ(r.out.find("(0 kg in mass points)") != std::string::npos, lumped) << c.flags << "\n" << r.out;
    if (lumped) {
      EXPECT_NE(r.err.find("wrap_muscle: Type III path (wrap mass off: --wrap lumped)"), std::string::npos) << r.err;
    }
  }
}

TEST_F(WrapFlagsCli, BadValuesExitTwoWithAClearMessage) {
  const std::string out = " --out " + path("never.sto");
  const std::string leg = " --model " + scene("running_leg.osim") + " --coordinates " + scene("running_leg_swing.mot");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {kPendulum + " --duration 1 --wrap bogus" + out, "--wrap must be smooth, exact, neural or lumped, got 'bogus'"},
      {kPendulum + " --duration 1 --wrap-width -1" + out, "--wrap-width must be a positive number of metres"},
      {kPendulum + " --duration 1 --wrap-width 0" + out, "--wrap-width must be a positive number of metres"},
      {kPendulum + " --duration 1 --wrap-width inf" + out, "--wrap-width"},
      {kPendulum + " --duration 1 --wrap-width x" + out, "--wrap-width"},
      {kPendulum + " --duration 1 --wrap exact --wrap-width 0.01" + out, "--wrap-width needs --wrap smooth or neural"},
      {kPendulum + " --duration 1 --wrap-network " + path("net.txt") + out, "--wrap-network needs --wrap neural"},
      {"simulate --model " + scene("double_pendulum_wrap.osim") + " --duration 1 --wrap exact" + out,
       "--wrap needs muscle mass"},
      {"simulate --model " + scene("double_pendulum_wrap.osim") + " --duration 1 --wrap-width 0.01" + out,
       "--wrap-width needs muscle mass"},
      {"simulate --model " + scene("double_pendulum_wrap.osim") + " --duration 1 --muscle-mass-kg wrap_muscle=1 --wrap x" +
           out,
       "--wrap must be"},
      {"id" + leg + " --muscle-mass physiological --wrap bogus" + out, "--wrap must be"},
      {"id" + leg + " --wrap smooth" + out, "--wrap needs --muscle-mass physiological or transfer"},
      {"id" + leg + " --muscle-mass physiological --wrap lumped --wrap-width 0.01" + out, "--wrap-width needs --wrap smooth"},
      {"id" + leg + " --muscle-mass physiological --wrap neural --wrap-network " + path("absent_dir") + out,
       "--wrap-network: " + path("absent_dir") + ": no such file or folder"},
      {"validate" + leg + " --report " + path("rep") + " --muscle-mass physiological --wrap bogus",
       "--wrap must be"},
      {"validate" + leg + " --report " + path("rep") + " --wrap exact", "--wrap needs --muscle-mass"},
  };
  for (const auto& [args, message] : cases) {
    const CmdResult r = run(args);
    EXPECT_EQ(r.code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << "\n" << r.err;
  }
  EXPECT_FALSE(fs::exists(path("never.sto")));
  EXPECT_FALSE(fs::exists(path("rep")));
}

TEST_F(WrapFlagsCli, NeuralTakesANetworkAndFallsBackOutsideItsBox) {
  const std::string sim = kPendulum + " --duration 0.05 --wrap neural";
  // without --wrap-network: the committed networks (osim_models/networks/wrap_networks.txt), said so
  const CmdResult none = run(sim + " --out " + path("s.sto"));
  EXPECT_EQ(none.code, 0) << none.err;
  EXPECT_EQ(none.err.rfind("note: --wrap neural without --wrap-network: using the committed networks ", 0), 0u)
      << none.err;
  EXPECT_NE(none.err.find("osim_models/networks/wrap_networks.txt"), std::string::npos) << none.err;
  fs::remove(path("s.sto"));
  std::ofstream(path("bad_net.txt")) << "not a network\n";
  const CmdResult bad = run(sim + " --wrap-network " + path("bad_net.txt") + " --out " + path("s.sto"));
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("bad_net.txt"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(path("s.sto")));
  // the committed cylinder network (osim_models/networks/README.md)
  const CmdResult r = run(sim + " --wrap-network " + scene("networks/cylinder_3x64.txt") + " --out " + path("s.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("wrapping (Type III): 1 of 1 carry mass (wrap model neural"), std::string::npos) << r.err;
  // networks are trained without a quadrant: this cylinder's -x quadrant forces the smooth model,
  // said once per muscle as a warning and counted at the end
  EXPECT_NE(r.err.find("warning: muscle 'wrap_muscle', wrap object 'joint_cylinder': the network wrap model fell "
                       "back to the smooth model"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("wrap network fallbacks:\n  wrap_muscle: "), std::string::npos) << r.err;
}

// The wrapping pendulum of Fig. 6.5 with the dissertation's equal masses (1 kg links, 1 kg muscle
// added on 20 points), 1 s from the default pose (wrapped at q2 = 30 deg), tight rk45. The smooth
// model keeps the mass matrix continuous: the drift stays at integrator error (bound 1e-8). Exact
// wrapping with finite-difference Jacobians is printed for comparison (its jumps need a contact
// change, which depends on the swing).
TEST_F(WrapFlagsCli, SmoothWrapMassConservesEnergyOnTheWrappingPendulum) {
  const std::string base = "simulate --model " + scene("double_pendulum_wrap.osim") +
                           " --duration 1 --integrator rk45 --rtol 1e-11 --atol 1e-12 --full-precision"
                           " --muscle-mass-kg wrap_muscle=1 --quiet";
  const CmdResult rs = run(base + " --wrap smooth --out " + path("smooth.sto"));
  ASSERT_EQ(rs.code, 0) << rs.err;
  const Storage s = readStorage(path("smooth.sto"));
  const double drift = energyDrift(s);
  EXPECT_GE(drift, 0.0);
  EXPECT_LE(drift, 1e-8);
  // the muscle moved: its mass is in the energy (lumped gives another trajectory)
  const CmdResult rl = run(base + " --wrap lumped --out " + path("lumped.sto"));
  ASSERT_EQ(rl.code, 2) << "a wrapping muscle named in --muscle-mass-kg cannot stay lumped\n" << rl.err;
  EXPECT_NE(rl.err.find("wrap_muscle"), std::string::npos) << rl.err;
  const CmdResult re = run(base + " --wrap exact --out " + path("exact.sto"));
  ASSERT_EQ(re.code, 0) << re.err;
  const Storage x = readStorage(path("exact.sto"));
  // the exact library's Jacobian jumps at the contact change: its energy jumps by orders more
  EXPECT_GT(energyDrift(x), 1e3 * drift);
  std::printf("[ measured ] wrapping pendulum, 1 kg muscle, 1 s rk45 1e-11: energy drift smooth %.3e, exact+FD %.3e "
              "(largest step between rows %.3e vs %.3e J)\n",
              drift, energyDrift(x), largestEnergyStep(s), largestEnergyStep(x));
}

TEST_F(WrapFlagsCli, PhysiologicalWrapMassConservesEnergy) {
  const CmdResult r = run(kPendulum + " --duration 1 --integrator rk45 --rtol 1e-11 --atol 1e-12 --full-precision"
                                      " --wrap smooth --out " + path("p.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("wrap_muscle: 0.02 kg, 20 points"), std::string::npos) << r.err;  // 50 * 480 / 0.6e6 * 0.5
  const double drift = energyDrift(readStorage(path("p.sto")));
  EXPECT_LE(drift, 1e-9);  // measured 7.0e-11
  std::printf("[ measured ] wrapping pendulum, physiological wrap mass, 1 s rk45 1e-11: energy drift %.3e\n", drift);
}

// The running leg's gastrocnemii (origin on the femur, condyle cylinder, insertion on the calcaneus)
// take their physiological mass through Type III. Falling freely with the hip, knee and ankle
// swinging (3, -4, 2 rad/s) the knee flexes from 0 past the wrap/no-wrap event (about 18 deg) to
// about 70 deg; tight rk45 for 1 s as the work-precision running-leg scene. With the gastrocnemii
// carrying mass (--muscles), the smooth model keeps the drift at integrator error (bound 1e-10;
// the exact model's jump at the event is orders larger). With every muscle the tibialis anterior's
// via point adds its own sliding-point drift (Type II, docs/notes.md), printed only.
TEST_F(WrapFlagsCli, RunningLegGastrocnemiiCarryMassAndConserveEnergy) {
  std::ofstream(path("init.sto")) << "initial\nversion=1\nnRows=1\nnColumns=4\ninDegrees=no\nendheader\n"
                                     "time\thip_flexion_r_u\tknee_angle_r_u\tankle_angle_r_u\n0\t3\t-4\t2\n";
  const std::string base = "simulate --model " + scene("running_leg.osim") + " --initial " + path("init.sto") +
                           " --duration 1 --integrator rk45 --rtol 1e-11 --atol 1e-12 --full-precision"
                           " --muscle-mass physiological";
  const std::string gas = " --muscles '.*_gas_r'";
  const CmdResult r = run(base + gas + " --wrap smooth --out " + path("leg.sto"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("wrapping (Type III): 2 of 2 carry mass (wrap model smooth"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("med_gas_r: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("lat_gas_r: "), std::string::npos) << r.err;
  const Storage s = readStorage(path("leg.sto"));
  const int knee = s.findColumn("/jointset/knee_r/knee_angle_r/value");
  ASSERT_GE(knee, 0);
  EXPECT_LT(s.data.col(knee).minCoeff(), -0.5);
  const double drift = energyDrift(s);
  EXPECT_GE(drift, 0.0);
  EXPECT_LE(drift, 1e-10);  // measured 9.3e-12
  const CmdResult re = run(base + gas + " --wrap exact --quiet --out " + path("leg_exact.sto"));
  ASSERT_EQ(re.code, 0) << re.err;
  const double drift_exact = energyDrift(readStorage(path("leg_exact.sto")));
  EXPECT_GT(drift_exact, 100 * drift);
  const CmdResult ra = run(base + " --quiet --out " + path("leg_all.sto"));
  ASSERT_EQ(ra.code, 0) << ra.err;
  std::printf("[ measured ] running leg, 1 s rk45 1e-11: gastrocnemii with mass: drift smooth %.3e, exact+FD %.3e; "
              "all four muscles (smooth): %.3e\n",
              drift, drift_exact, energyDrift(readStorage(path("leg_all.sto"))));
}

// `redmax id`: both engines take the wrap mass by default (the running leg's gastrocnemii have the
// origin -> wrap -> insertion shape Simbody's muscle inertia takes) and agree; --wrap lumped keeps
// them massless in both; the wrapping muscles' mass changes the torques
TEST_F(WrapFlagsCli, IdEnginesTakeWrapMassAlike) {
  const std::string leg = "id --model " + scene("running_leg.osim") + " --coordinates " + scene("running_leg_swing.mot") +
                          " --muscle-mass physiological --full-precision";
  const CmdResult rc = run(leg + " --out " + path("core.sto"));
  ASSERT_EQ(rc.code, 0) << rc.err;
  EXPECT_NE(rc.err.find("wrapping (Type III): 2 of 2 carry mass (wrap model smooth"), std::string::npos) << rc.err;
  const CmdResult rs = run(leg + " --engine simbody --out " + path("sb.sto"));
  ASSERT_EQ(rs.code, 0) << rs.err;
  EXPECT_NE(rs.err.find("wrapping (Type III): 2 of 2 carry mass (wrap model smooth"), std::string::npos) << rs.err;
  const CmdResult rl = run(leg + " --wrap lumped --out " + path("lumped.sto"));
  ASSERT_EQ(rl.code, 0) << rl.err;
  EXPECT_NE(rl.err.find("wrapping (Type III): 0 of 2 carry mass (wrap mass off)"), std::string::npos) << rl.err;
  const CmdResult rsl = run(leg + " --engine simbody --wrap lumped --out " + path("sb_lumped.sto"));
  ASSERT_EQ(rsl.code, 0) << rsl.err;
  const Storage c = readStorage(path("core.sto")), b = readStorage(path("sb.sto"));
  const Storage l = readStorage(path("lumped.sto")), bl = readStorage(path("sb_lumped.sto"));
  ASSERT_EQ(c.data.rows(), b.data.rows());
  ASSERT_EQ(l.data.rows(), bl.data.rows());
  const double peak = c.data.cwiseAbs().maxCoeff();
  EXPECT_LE((c.data - b.data).cwiseAbs().maxCoeff(), 2e-13 * peak);  // measured 1.1e-14
  EXPECT_LE((l.data - bl.data).cwiseAbs().maxCoeff(), 2e-13 * peak);
  EXPECT_GT((c.data - l.data).cwiseAbs().maxCoeff(), 1e-4 * peak);
  std::printf("[ measured ] running leg swing, physiological: core vs Simbody with wrap mass %.2g of the peak; "
              "gastrocnemii's mass changes the torques by up to %.3g of the peak\n",
              (c.data - b.data).cwiseAbs().maxCoeff() / peak, (c.data - l.data).cwiseAbs().maxCoeff() / peak);
}

// `redmax validate --mass-sweep` with the default wrap mass: the sweep's report says how many
// wrapping muscles carry mass (summary.json mass_sweep.wrapping), the zero check holds, and Simbody
// with muscle inertia (which takes the gastrocnemii's origin -> wrap -> insertion) agrees with the
// core at the largest value within its tolerance (counted in the verdict)
TEST_F(WrapFlagsCli, ValidateSweepReportsWrappingMuscles) {
  const CmdResult r = run("validate --model " + scene("running_leg.osim") + " --coordinates " +
                          scene("running_leg_swing.mot") + " --muscle-mass physiological --mass-sweep 0,0.5,1 --no-plots"
                          " --quiet --report " + path("rep"));
  ASSERT_EQ(r.code, 0) << r.err;
  const JsonValue j = JsonValue::parse(slurp(dir_ / "rep" / "summary.json"));
  const JsonValue& sw = j.at("mass_sweep");
  ASSERT_TRUE(sw.contains("wrapping")) << sw.dump();
  const JsonValue& w = sw.at("wrapping");
  EXPECT_TRUE(w.at("wrap_mass").asBool());
  EXPECT_EQ(w.at("wrap_model").asString(), "smooth");
  EXPECT_EQ(w.at("wrapping_muscles").asNumber(), 2);
  EXPECT_EQ(w.at("with_mass").asNumber(), 2);
  EXPECT_EQ(w.at("lumped").size(), 0u);
  EXPECT_TRUE(sw.at("zero_check").at("passed").asBool());
  EXPECT_NE(slurp(dir_ / "rep" / "report.md").find("wrapping (Type III): 2 of 2 carry mass"), std::string::npos);
  const JsonValue& sb = sw.at("simbody_check");
  if (sb.at("ran").asBool()) {
    ASSERT_TRUE(j.contains("simbody_mass_check")) << j.dump();
    EXPECT_TRUE(j.at("simbody_mass_check").at("agrees").asBool()) << j.at("simbody_mass_check").dump();
  } else {
    ADD_FAILURE() << "Simbody with muscle inertia did not run: " << sb.at("skipped").asString();
  }
  // lumped: the report says so
  const CmdResult rl = run("validate --model " + scene("running_leg.osim") + " --coordinates " +
                           scene("running_leg_swing.mot") +
                           " --muscle-mass physiological --mass-sweep 0,1 --wrap lumped --no-plots --no-simbody --quiet"
                           " --report " + path("rep_lumped"));
  ASSERT_EQ(rl.code, 0) << rl.err;
  const JsonValue jl = JsonValue::parse(slurp(dir_ / "rep_lumped" / "summary.json"));
  EXPECT_EQ(jl.at("mass_sweep").at("wrapping").at("with_mass").asNumber(), 0);
  EXPECT_EQ(jl.at("mass_sweep").at("wrapping").at("lumped").size(), 2u);
}

}  // namespace
