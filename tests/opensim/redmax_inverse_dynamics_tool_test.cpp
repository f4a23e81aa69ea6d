// The OpenSim plugin (plugin/opensim) on the real inverse-dynamics set F (Gait10dof18musc,
// /work/shared/opensim/README.md): at zero muscle mass it must be OpenSim's own InverseDynamicsTool
// (same process, same inputs); at 80% tibia transfer it must agree with `redmax id` (the converter's
// InverseDynamicsTool with the core engine), which computes the same mass points with the core's
// kinematics instead of OpenSim's Simbody system. Built only when OpenSim is found.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

const std::string kF = "Pipelines/Gait10dof18musc/OutputReference/";
std::string modelF() { return shared("opensim-models@a26e12c/" + kF + "subject01.osim"); }
std::string coordinatesF() { return shared("opensim-models/" + kF + "IK/subject01_walk_IK.mot"); }
std::string loadsF() { return shared("opensim-models/" + kF + "ExperimentalData/subject01_walk_grf.xml"); }

bool haveSetF() { return fs::exists(modelF()) && fs::exists(coordinatesF()) && fs::exists(loadsF()); }

#define SKIP_WITHOUT_SET_F()                                                                         \
  if (!haveSetF()) GTEST_SKIP() << "shared OpenSim data not found under " << REDMAX_SHARED_DIR        \
                                << "/opensim (set F); skipping"

fs::path tempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("redmax_opensim_test_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// an ID setup for set F (t 0-2.5, 6 Hz, muscles excluded), as <element>, with `extra` properties
std::string writeSetupF(const fs::path& dir, const std::string& element, const std::string& out,
                        const std::string& extra = "") {
  const fs::path file = dir / (element + "_setup.xml");
  std::ofstream f(file);
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
    << "  <" << element << " name=\"walk\">\n"
    << "    <results_directory>" << dir.string() << "</results_directory>\n"
    << "    <model_file>" << modelF() << "</model_file>\n"
    << "    <time_range> 0 2.5</time_range>\n"
    << "    <forces_to_exclude> Muscles</forces_to_exclude>\n"
    << "    <external_loads_file>" << loadsF() << "</external_loads_file>\n"
    << "    <coordinates_file>" << coordinatesF() << "</coordinates_file>\n"
    << "    <lowpass_cutoff_frequency_for_coordinates>6</lowpass_cutoff_frequency_for_coordinates>\n"
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
  osim::CoreIdEngine engine(tool.model(), tool.muscles(), tool.engineOptions());
  return tool.run(engine);
}

const char* kTransfer80 =
    "    <muscle_mass>transfer</muscle_mass>\n    <transfer_body>tibia_r</transfer_body>\n"
    "    <transfer_fraction>0.8</transfer_fraction>\n    <full_precision>true</full_precision>\n";

TEST(RedmaxInverseDynamicsTool, ZeroMassIsOpenSimsOwnInverseDynamics) {
  SKIP_WITHOUT_SET_F();
  const fs::path dir = tempDir("zero");
  OpenSim::InverseDynamicsTool osim_tool(writeSetupF(dir, "InverseDynamicsTool", "opensim.sto"));
  ASSERT_TRUE(osim_tool.run());
  const osim::Storage ref = osim::readStorage((dir / "opensim.sto").string());
  const osim::Storage ours = runPlugin(
      writeSetupF(dir, "RedmaxInverseDynamicsTool", "plugin.sto", "    <full_precision>true</full_precision>\n"));
  EXPECT_EQ(ours.name, "Inverse Dynamics Generalized Forces");
  EXPECT_EQ(ours.labels, ref.labels);  // same columns in the same (u) order
  // the same computation; OpenSim prints 8 decimals, so the difference is its rounding (5e-9)
  for (const ColumnDiff& d : compare(ours, ref)) EXPECT_LE(d.max_abs, 1e-8) << d.label;
}

TEST(RedmaxInverseDynamicsTool, TibiaTransferAgreesWithRedmaxId) {
  SKIP_WITHOUT_SET_F();
  const fs::path dir = tempDir("transfer");
  const osim::Storage p0 = runPlugin(
      writeSetupF(dir, "RedmaxInverseDynamicsTool", "p0.sto", "    <full_precision>true</full_precision>\n"));
  const osim::Storage p80 = runPlugin(writeSetupF(dir, "RedmaxInverseDynamicsTool", "p80.sto", kTransfer80));
  const std::string plain = writeSetupF(dir, "InverseDynamicsTool", "unused.sto");
  osim::MuscleMassOptions mm;
  const osim::Storage r0 = runRedmaxId(plain, mm);
  mm.source = osim::MuscleMassOptions::Source::Transfer;
  mm.transfer_body = "tibia_r";
  mm.transfer_fraction = 0.8;
  const osim::Storage r80 = runRedmaxId(plain, mm);

  // the mass points matter: moving 80% of the tibia into its muscles changes the torques
  double largest_effect = 0.0;
  for (const ColumnDiff& d : compare(p80, p0)) largest_effect = std::max(largest_effect, d.max_abs);
  EXPECT_GT(largest_effect, 0.5);  // N m or N
  // plugin (OpenSim's Simbody kinematics) and redmax id (the core's) agree on the torques ...
  for (const ColumnDiff& d : compare(p80, r80)) EXPECT_LE(d.max_abs, 1e-5 * std::max(1.0, d.peak)) << d.label;
  // ... and on the muscle-mass part alone (differences of differences)
  osim::Storage dp = p80, dr = r80;
  dp.data -= p0.data;
  dr.data -= r0.data;
  for (const ColumnDiff& d : compare(dp, dr)) EXPECT_LE(d.max_abs, 1e-6 * std::max(1.0, d.peak)) << d.label;
}

TEST(RedmaxInverseDynamicsTool, BadMuscleMassOptionsFailWithoutOutput) {
  SKIP_WITHOUT_SET_F();
  const fs::path dir = tempDir("bad");
  for (const std::string& extra :
       {std::string("    <muscle_mass>bones</muscle_mass>\n"),
        std::string("    <muscle_mass>transfer</muscle_mass>\n    <transfer_body>tibia_r</transfer_body>\n"
                    "    <transfer_fraction>1.5</transfer_fraction>\n"),
        std::string("    <muscle_mass>transfer</muscle_mass>\n    <transfer_body>no_such_body</transfer_body>\n"
                    "    <transfer_fraction>0.5</transfer_fraction>\n"),
        std::string("    <muscle_mass>physiological</muscle_mass>\n    <mass_points>0</mass_points>\n")}) {
    const std::string setup = writeSetupF(dir, "RedmaxInverseDynamicsTool", "bad.sto", extra);
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
  const fs::path dir = tempDir("props");
  const std::string setup = writeSetupF(dir, "RedmaxInverseDynamicsTool", "x.sto",
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
  EXPECT_EQ(tool.getCoordinatesFileName(), coordinatesF());
  EXPECT_DOUBLE_EQ(tool.getLowpassCutoffFrequency(), 6.0);
}

// the OpenSim plugin mechanism itself: opensim-cmd loads the library and runs the tool by name
TEST(RedmaxInverseDynamicsTool, OpensimCmdRunsThePlugin) {
  SKIP_WITHOUT_SET_F();
  const std::string cmd = REDMAX_OPENSIM_CMD, lib = REDMAX_OPENSIM_PLUGIN;
  if (!fs::exists(cmd)) GTEST_SKIP() << "opensim-cmd not found at " << cmd << "; skipping";
  const fs::path dir = tempDir("cmd");
  const std::string setup = writeSetupF(dir, "RedmaxInverseDynamicsTool", "cmd.sto", kTransfer80);
  const std::string line = "'" + cmd + "' -L '" + lib + "' run-tool '" + setup + "' > '" + (dir / "log.txt").string() + "' 2>&1";
  ASSERT_EQ(std::system(line.c_str()), 0) << line;
  const osim::Storage from_cmd = osim::readStorage((dir / "cmd.sto").string());
  const osim::Storage in_process = runPlugin(writeSetupF(dir, "RedmaxInverseDynamicsTool", "in.sto", kTransfer80));
  for (const ColumnDiff& d : compare(from_cmd, in_process)) EXPECT_LE(d.max_abs, 1e-12 * std::max(1.0, d.peak)) << d.label;
}

}  // namespace
}  // namespace redmax::opensim
