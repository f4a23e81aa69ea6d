// The OpenSim plugin (plugin/opensim) on the real inverse-dynamics set F (Gait10dof18musc,
// docs/shared_data.md): at zero muscle mass it must be OpenSim's own InverseDynamicsTool
// (same process, same inputs); at 80% tibia transfer it must agree with `redmax id` (the converter's
// InverseDynamicsTool with the core engine), which computes the same mass points with the core's
// kinematics instead of OpenSim's Simbody system. Built only when OpenSim is found.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <OpenSim/Common/Function.h>
#include <OpenSim/Tools/InverseDynamicsTool.h>

#include "converter/id/core_id_engine.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/storage.hpp"
#include "plugin/opensim/redmax_inverse_dynamics_tool.hpp"

namespace redmax::opensim {
namespace {

namespace fs = std::filesystem;

std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }

// the inverse-dynamics sets of docs/shared_data.md (A filtered, E, F) and the body whose
// mass moves into its muscles in the transfer runs (arm26 has no tibia: its humerus, spanned by the
// one muscle without wrap objects, BICshort)
struct IdSet {
  std::string name, model, coordinates, loads;
  double t0, t1, lowpass;
  std::string transfer_body;
};
void PrintTo(const IdSet& s, std::ostream* os) { *os << s.name; }

IdSet setA() {
  const std::string cmc = "Tutorials/Computed_Muscle_Control/OutputReference/";
  return {"A", shared("opensim-models@a26e12c/" + cmc + "arm26.osim"),
          shared("opensim-models/" + cmc + "InverseKinematics/arm26_InverseKinematics.mot"), "", 0.0, 1.0, 6.0,
          "r_humerus"};
}
IdSet setE() {
  const std::string e = "Pipelines/Gait2392_Simbody/";
  return {"E", shared("opensim-models@a26e12c/" + e + "OutputReference/subject01_simbody.osim"),
          shared("opensim-models/" + e + "subject01_walk1_ik.mot"), shared("opensim-models/" + e + "subject01_walk1_grf.xml"),
          0.4, 1.6, 6.0, "tibia_r"};
}
IdSet setF() {
  const std::string f = "Pipelines/Gait10dof18musc/OutputReference/";
  return {"F", shared("opensim-models@a26e12c/" + f + "subject01.osim"),
          shared("opensim-models/" + f + "IK/subject01_walk_IK.mot"),
          shared("opensim-models/" + f + "ExperimentalData/subject01_walk_grf.xml"), 0.0, 2.5, 6.0, "tibia_r"};
}

bool haveSet(const IdSet& s) {
  return fs::exists(s.model) && fs::exists(s.coordinates) && (s.loads.empty() || fs::exists(s.loads));
}

#define SKIP_WITHOUT(set)                                                                              \
  if (!haveSet(set)) GTEST_SKIP() << "shared OpenSim data not found under " << REDMAX_SHARED_DIR        \
                                  << "/opensim (set " << (set).name << "); skipping"

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("redmax_opensim_test_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// an ID setup for a set (muscles excluded), as <element>, with `extra` properties
std::string writeSetup(const IdSet& set, const fs::path& dir, const std::string& element, const std::string& out,
                       const std::string& extra = "") {
  const fs::path file = dir / (element + "_" + out + "_setup.xml");
  std::ofstream f(file);
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
    << "  <" << element << " name=\"" << set.name << "\">\n"
    << "    <results_directory>" << dir.string() << "</results_directory>\n"
    << "    <model_file>" << set.model << "</model_file>\n"
    << "    <time_range> " << set.t0 << " " << set.t1 << "</time_range>\n"
    << "    <forces_to_exclude> Muscles</forces_to_exclude>\n"
    << "    <external_loads_file>" << set.loads << "</external_loads_file>\n"
    << "    <coordinates_file>" << set.coordinates << "</coordinates_file>\n"
    << "    <lowpass_cutoff_frequency_for_coordinates>" << set.lowpass << "</lowpass_cutoff_frequency_for_coordinates>\n"
    << "    <output_gen_force_file>" << out << "</output_gen_force_file>\n"
    << extra << "  </" << element << ">\n</OpenSimDocument>\n";
  return file.string();
}

// largest |a - b| per column (matched by label; rows must share their times to 1e-9 s) and the
// largest |b| of that column
struct ColumnDiff {
  std::string label;
  double max_abs = 0.0, peak = 0.0;
};
std::vector<ColumnDiff> compare(const osim::Storage& a, const osim::Storage& b) {
  EXPECT_EQ(a.numRows(), b.numRows());
  std::vector<ColumnDiff> out;
  const int n = std::min(a.numRows(), b.numRows());
  for (int r = 0; r < n; ++r) EXPECT_NEAR(a.time[r], b.time[r], 1e-9) << "row " << r;
  for (int ca = 0; ca < a.numColumns(); ++ca) {
    const int cb = b.findColumn(a.labels[ca]);
    EXPECT_GE(cb, 0) << a.labels[ca] << " missing";
    if (cb < 0) continue;
    ColumnDiff d{a.labels[ca]};
    for (int r = 0; r < n; ++r) {
      d.max_abs = std::max(d.max_abs, std::abs(a.data(r, ca) - b.data(r, cb)));
      d.peak = std::max(d.peak, std::abs(b.data(r, cb)));
    }
    out.push_back(d);
  }
  EXPECT_EQ(a.numColumns(), b.numColumns());
  return out;
}

osim::Storage runPlugin(const std::string& setup) {
  RedmaxInverseDynamicsTool tool(setup);
  EXPECT_TRUE(tool.run());
  return osim::readStorage(tool.outputPath());
}

// `redmax id --setup` with the core engine, in process
osim::Storage runRedmaxId(const std::string& setup, const osim::MuscleMassOptions& mm) {
  osim::IdToolSettings st;
  st.setup_file = setup;
  st.muscle_mass = mm;
  osim::InverseDynamicsTool tool(osim::resolveIdSettings(st));
  osim::CoreIdEngine engine(tool.musculoskeletalModel(), tool.engineOptions());
  return tool.run(engine);
}

std::string transfer80(const IdSet& set) {
  return "    <muscle_mass>transfer</muscle_mass>\n    <transfer_body>" + set.transfer_body +
         "</transfer_body>\n    <transfer_fraction>0.8</transfer_fraction>\n    <full_precision>true</full_precision>\n";
}
const char* kFull = "    <full_precision>true</full_precision>\n";

class PluginOnSet : public ::testing::TestWithParam<IdSet> {};

// at zero mass the plugin is OpenSim's own InverseDynamicsTool (same process, same inputs)
TEST_P(PluginOnSet, ZeroMassIsOpenSimsOwnInverseDynamics) {
  const IdSet set = GetParam();
  SKIP_WITHOUT(set);
  const fs::path dir = tempDir("zero_" + set.name);
  OpenSim::InverseDynamicsTool osim_tool(writeSetup(set, dir, "InverseDynamicsTool", "opensim.sto"));
  ASSERT_TRUE(osim_tool.run());
  const osim::Storage ref = osim::readStorage((dir / "opensim.sto").string());
  const osim::Storage ours = runPlugin(writeSetup(set, dir, "RedmaxInverseDynamicsTool", "plugin.sto", kFull));
  EXPECT_EQ(ours.name, "Inverse Dynamics Generalized Forces");
  EXPECT_EQ(ours.labels, ref.labels);  // same columns in the same (u) order
  // the same computation; OpenSim prints 8 decimals, so the difference is its rounding (5e-9)
  double worst = 0.0;
  for (const ColumnDiff& d : compare(ours, ref)) {
    EXPECT_LE(d.max_abs, 1e-8) << d.label;
    worst = std::max(worst, d.max_abs);
  }
  std::printf("set %s, no muscle mass: plugin vs OpenSim's InverseDynamicsTool, max abs diff %.3g\n", set.name.c_str(), worst);
}

// the mass points' share of the torques (with mass minus without: differences of differences) of
// the plugin against redmax id's, every column to 1e-8 of its peak; returns (worst, largest peak)
std::pair<double, double> compareMassShare(const osim::Storage& plugin_mass, const osim::Storage& plugin_zero,
                                           const osim::Storage& redmax_mass, const osim::Storage& redmax_zero) {
  osim::Storage dp = plugin_mass, dr = redmax_mass;
  dp.data -= plugin_zero.data;
  dr.data -= redmax_zero.data;
  double worst = 0.0, peak = 0.0;
  for (const ColumnDiff& d : compare(dp, dr)) {
    EXPECT_LE(d.max_abs, 1e-8 * std::max(1.0, d.peak)) << d.label;
    worst = std::max(worst, d.max_abs);
    peak = std::max(peak, d.peak);
  }
  return {worst, peak};
}

// at 80% transfer the plugin (mass points on OpenSim's Simbody) agrees with `redmax id` (the
// converter's tool with the core engine: the core's kinematics)
TEST_P(PluginOnSet, TransferAgreesWithRedmaxId) {
  const IdSet set = GetParam();
  SKIP_WITHOUT(set);
  const fs::path dir = tempDir("transfer_" + set.name);
  const osim::Storage p0 = runPlugin(writeSetup(set, dir, "RedmaxInverseDynamicsTool", "p0.sto", kFull));
  const osim::Storage p80 = runPlugin(writeSetup(set, dir, "RedmaxInverseDynamicsTool", "p80.sto", transfer80(set)));
  const std::string plain = writeSetup(set, dir, "InverseDynamicsTool", "unused.sto");
  osim::MuscleMassOptions mm;
  const osim::Storage r0 = runRedmaxId(plain, mm);
  mm.source = osim::MuscleMassOptions::Source::Transfer;
  mm.transfer_body = set.transfer_body;
  mm.transfer_fraction = 0.8;
  const osim::Storage r80 = runRedmaxId(plain, mm);

  // the mass points matter: moving 80% of the body into its muscles changes the torques
  double effect = 0.0;
  for (const ColumnDiff& d : compare(p80, p0)) effect = std::max(effect, d.max_abs);
  EXPECT_GT(effect, 1e-3);  // N m or N
  // plugin and redmax id agree on the torques (redmax id equals OpenSim 4.6 to ~1e-8 of the peak)
  double worst_abs = 0.0, worst_rel = 0.0;
  for (const ColumnDiff& d : compare(p80, r80)) {
    EXPECT_LE(d.max_abs, 1e-5 * std::max(1.0, d.peak)) << d.label;
    worst_abs = std::max(worst_abs, d.max_abs);
    worst_rel = std::max(worst_rel, d.max_abs / std::max(1e-300, d.peak));
  }
  // ... and on the muscle-mass part alone: the same mass points moved by OpenSim's Simbody and by the core
  const auto [worst_mass, peak_mass] = compareMassShare(p80, p0, r80, r0);
  std::printf("set %s, 80%% %s transfer: largest effect of the mass %.4g; plugin vs redmax id max abs %.3g, "
              "max rel (of column peak) %.3g; mass part alone max abs %.3g (peak %.4g)\n",
              set.name.c_str(), set.transfer_body.c_str(), effect, worst_abs, worst_rel, worst_mass, peak_mass);
}

// physiological mass in every muscle (wrapping muscles over the smooth wrap model, also on OpenSim's
// Simbody): the mass points' share of the plugin's torques equals redmax id's
TEST_P(PluginOnSet, PhysiologicalMassAgreesWithRedmaxId) {
  const IdSet set = GetParam();
  SKIP_WITHOUT(set);
  const fs::path dir = tempDir("physiological_" + set.name);
  const osim::Storage p0 = runPlugin(writeSetup(set, dir, "RedmaxInverseDynamicsTool", "p0.sto", kFull));
  const osim::Storage pp = runPlugin(writeSetup(set, dir, "RedmaxInverseDynamicsTool", "pp.sto",
                                                std::string("    <muscle_mass>physiological</muscle_mass>\n") + kFull));
  const std::string plain = writeSetup(set, dir, "InverseDynamicsTool", "unused.sto");
  osim::MuscleMassOptions mm;
  const osim::Storage r0 = runRedmaxId(plain, mm);
  mm.source = osim::MuscleMassOptions::Source::Physiological;
  const osim::Storage rp = runRedmaxId(plain, mm);
  const auto [worst_mass, peak_mass] = compareMassShare(pp, p0, rp, r0);
  EXPECT_GT(peak_mass, 1e-3);  // the mass points matter
  std::printf("set %s, physiological: mass part plugin vs redmax id max abs %.3g (peak %.4g)\n", set.name.c_str(),
              worst_mass, peak_mass);
}

INSTANTIATE_TEST_SUITE_P(Sets, PluginOnSet, ::testing::Values(setA(), setE(), setF()),
                         [](const ::testing::TestParamInfo<IdSet>& i) { return i.param.name; });

TEST(RedmaxInverseDynamicsTool, BadMuscleMassOptionsFailWithoutOutput) {
  const IdSet set = setF();
  SKIP_WITHOUT(set);
  const fs::path dir = tempDir("bad");
  for (const std::string& extra :
       {std::string("    <muscle_mass>bones</muscle_mass>\n"),
        std::string("    <muscle_mass>transfer</muscle_mass>\n    <transfer_body>tibia_r</transfer_body>\n"
                    "    <transfer_fraction>1.5</transfer_fraction>\n"),
        std::string("    <muscle_mass>transfer</muscle_mass>\n    <transfer_body>no_such_body</transfer_body>\n"
                    "    <transfer_fraction>0.5</transfer_fraction>\n"),
        std::string("    <muscle_mass>physiological</muscle_mass>\n    <mass_points>0</mass_points>\n")}) {
    const std::string setup = writeSetup(set, dir, "RedmaxInverseDynamicsTool", "bad.sto", extra);
    RedmaxInverseDynamicsTool tool(setup);
    try {
      tool.run();
      ADD_FAILURE() << "no error for " << extra;
    } catch (const OpenSim::Exception& e) {
      // the message names the file it is about
      const std::string what = e.getMessage();
      EXPECT_TRUE(what.find(".xml") != std::string::npos || what.find(".osim") != std::string::npos) << what;
    }
    EXPECT_FALSE(fs::exists(dir / "bad.sto")) << extra;
  }
}

TEST(RedmaxInverseDynamicsTool, SetupPropertiesAreRead) {
  const IdSet set = setF();
  const fs::path dir = tempDir("props");
  const std::string setup = writeSetup(set, dir, "RedmaxInverseDynamicsTool", "x.sto",
                                       "    <muscle_mass>transfer</muscle_mass>\n    <muscles>.*_r</muscles>\n"
                                       "    <mass_points>7</mass_points>\n    <transfer_body>tibia_r</transfer_body>\n"
                                       "    <transfer_fraction>0.25</transfer_fraction>\n");
  RedmaxInverseDynamicsTool tool(setup);
  const osim::MuscleMassOptions o = tool.muscleMassOptions();
  EXPECT_EQ(o.source, osim::MuscleMassOptions::Source::Transfer);
  EXPECT_EQ(o.muscles, ".*_r");
  EXPECT_EQ(o.mass_points, 7);
  EXPECT_EQ(o.transfer_body, "tibia_r");
  EXPECT_DOUBLE_EQ(o.transfer_fraction, 0.25);
  EXPECT_DOUBLE_EQ(o.density, osim::kDefaultMuscleDensity);
  EXPECT_EQ(tool.getCoordinatesFileName(), set.coordinates);
  EXPECT_DOUBLE_EQ(tool.getLowpassCutoffFrequency(), 6.0);
}

// the OpenSim plugin mechanism itself: opensim-cmd loads the library and runs the tool by name
TEST(RedmaxInverseDynamicsTool, OpensimCmdRunsThePlugin) {
  const IdSet set = setF();
  SKIP_WITHOUT(set);
  const std::string cmd = REDMAX_OPENSIM_CMD, lib = REDMAX_OPENSIM_PLUGIN;
  if (!fs::exists(cmd)) GTEST_SKIP() << "opensim-cmd not found at " << cmd << "; skipping";
  const fs::path dir = tempDir("cmd");
  const std::string setup = writeSetup(set, dir, "RedmaxInverseDynamicsTool", "cmd.sto", transfer80(set));
  const std::string line =
      "'" + cmd + "' -L '" + lib + "' run-tool '" + setup + "' > '" + (dir / "log.txt").string() + "' 2>&1";
  ASSERT_EQ(std::system(line.c_str()), 0) << line;
  const osim::Storage from_cmd = osim::readStorage((dir / "cmd.sto").string());
  const osim::Storage in_process = runPlugin(writeSetup(set, dir, "RedmaxInverseDynamicsTool", "in.sto", transfer80(set)));
  for (const ColumnDiff& d : compare(from_cmd, in_process))
    EXPECT_LE(d.max_abs, 1e-12 * std::max(1.0, d.peak)) << d.label;
}

}  // namespace
}  // namespace redmax::opensim
