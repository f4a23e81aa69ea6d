// ExternalLoads files with their data, and InverseDynamicsTool setups with paths resolved from
// the setup file's folder (docs/opensim_compatibility.md §7), on the shared files and generated ones.
#include <gtest/gtest.h>

#include <filesystem>

#include "converter/external_loads.hpp"
#include "converter/id_setup.hpp"
#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

namespace fs = std::filesystem;
using test::sharedOpenSim;

bool sameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  return fs::equivalent(a, b, ec);
}

TEST(ExternalLoads, SharedGrfFilesResolveTheirColumns) {
  REDMAX_REQUIRE_SHARED();
  struct Case {
    const char* xml;
    const char* right_body;
    const char* left_force;
    int version_warnings;
  };
  const Case cases[] = {
      {"opensim-models/Pipelines/Gait2392_Simbody/subject01_walk1_grf.xml", "calcn_r",
       "1_ground_force_vx", 0},
      // the 2017 copy names a 3.x kinematics file and its filter: both ignored by 4.x
      {"opensim-models@a26e12c/Pipelines/Gait2392_Simbody/subject01_walk1_grf.xml", "calcn_r",
       "1_ground_force_vx", 2},
      {"opensim-models/Pipelines/Gait10dof18musc/OutputReference/ExperimentalData/subject01_walk_grf.xml",
       "calcn_r", "1_ground_force_vx", 0},
      {"opensim-core/OpenSim/Moco/Test/walk_gait1018_subject01_grf.xml", "calcn_r",
       "1_ground_force_vx", 0},
      {"opensim-core/OpenSim/Moco/Test/subject_walk_armless_external_loads.xml", "calcn_r",
       "ground_force_l_vx", 0},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.xml);
    const std::string xml = sharedOpenSim(c.xml);
    // the working directory is tried first; the 2017 copy has no data beside it, so its data
    // comes from the working directory (the current pipeline folder), the others' from beside
    // the XML
    const bool old = std::string(c.xml).find("@a26e12c") != std::string::npos;
    const std::string work =
        old ? sharedOpenSim("opensim-models/Pipelines/Gait2392_Simbody")
            : fs::path(xml).parent_path().string() + "/no_such_dir";
    const ExternalLoads l = readExternalLoads(xml, work);
    ASSERT_EQ(l.forces.size(), 2u);
    EXPECT_EQ(l.forces[0].applied_to_body, c.right_body);
    EXPECT_EQ(l.forces[1].applied_to_body, std::string(c.right_body) == "calcn_r" ? "calcn_l" : "");
    EXPECT_EQ(l.forces[0].force_expressed_in_body, "ground");
    EXPECT_TRUE(l.forces[0].applies_force);
    for (const auto& f : l.forces) {
      ASSERT_TRUE(f.hasForce() && f.hasPoint() && f.hasTorque());
      // the three columns are x, y, z in file order, and each starts with its identifier
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(l.data.labels[f.force_columns[k]].rfind(f.force_identifier, 0), 0u);
        EXPECT_EQ(l.data.labels[f.point_columns[k]].rfind(f.point_identifier, 0), 0u);
        EXPECT_EQ(l.data.labels[f.torque_columns[k]].rfind(f.torque_identifier, 0), 0u);
        if (k > 0) {
          EXPECT_GT(f.force_columns[k], f.force_columns[k - 1]);
        }
      }
    }
    EXPECT_EQ(l.data.labels[l.forces[1].force_columns[0]], c.left_force);
    EXPECT_EQ(static_cast<int>(l.warnings.size()), c.version_warnings);
    EXPECT_TRUE(sameFile(l.datafile_path,
                         (old ? fs::path(work) : fs::path(xml).parent_path()) / l.datafile));
  }
}

TEST(ExternalLoads, LoadsAgreeWithTheirModel) {
  REDMAX_REQUIRE_SHARED();
  const auto model = readOsimModel(
      sharedOpenSim("opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim"));
  ExternalLoads l = readExternalLoads(
      sharedOpenSim("opensim-models@a26e12c/Pipelines/Gait2392_Simbody/subject01_walk1_grf.xml"),
      sharedOpenSim("opensim-models/Pipelines/Gait2392_Simbody"));
  EXPECT_NO_THROW(checkExternalLoads(l, model));
  // the 2017 file names a 3.x kinematics file, ignored by 4.x
  ASSERT_FALSE(l.warnings.empty());
  EXPECT_NE(l.warnings[0].find("ignores"), std::string::npos);
  // an unknown applied_to_body is an error at the force's line
  l.forces[1].applied_to_body = "calcn_x";
  try {
    checkExternalLoads(l, model);
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), l.forces[1].line);
    EXPECT_NE(std::string(e.what()).find("calcn_x"), std::string::npos);
  }
  // an unknown expressed-in frame falls back to ground with a warning
  l.forces[1].applied_to_body = "/bodyset/calcn_l";
  l.forces[0].force_expressed_in_body = "nowhere";
  const size_t w = l.warnings.size();
  checkExternalLoads(l, model);
  EXPECT_EQ(l.forces[0].force_expressed_in_body, "ground");
  EXPECT_EQ(l.warnings.size(), w + 1);
}

std::string loadsXml(const std::string& datafile, const std::string& forces) {
  return "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<ExternalLoads name=\"L\">\n"
         "<objects>\n" + forces + "</objects>\n<datafile>" + datafile +
         "</datafile>\n</ExternalLoads>\n</OpenSimDocument>\n";
}

std::string force(const std::string& name, const std::string& body, const std::string& f,
                  const std::string& p = "", const std::string& t = "") {
  std::string s = "<ExternalForce name=\"" + name + "\">\n<applied_to_body>" + body +
                  "</applied_to_body>\n";
  if (!f.empty()) s += "<force_identifier>" + f + "</force_identifier>\n";
  if (!p.empty()) s += "<point_identifier>" + p + "</point_identifier>\n";
  if (!t.empty()) s += "<torque_identifier>" + t + "</torque_identifier>\n";
  return s + "</ExternalForce>\n";
}

const char* kData =
    "grf\nversion=1\nnRows=2\nnColumns=10\ninDegrees=no\nendheader\n"
    "time\tF_x\tF_y\tF_z\tP_x\tP_y\tP_z\tFF_x\tFF_y\tFF_z\n"
    "0\t1\t2\t3\t4\t5\t6\t7\t8\t9\n1\t1\t2\t3\t4\t5\t6\t7\t8\t9\n";

TEST(ExternalLoads, DataFileLookupPrefersTheWorkingDirectory) {
  test::TempDir dir;
  dir.write("loads/grf.mot", kData);
  const std::string xml = dir.write("loads/loads.xml", loadsXml("grf.mot", force("f", "a", "F_", "P_")));
  // not in the working directory: found beside the XML
  EXPECT_TRUE(sameFile(readExternalLoads(xml, dir.str()).datafile_path, dir.file("loads/grf.mot")));
  // present in the working directory: that one wins
  dir.write("grf.mot", kData);
  EXPECT_TRUE(sameFile(readExternalLoads(xml, dir.str()).datafile_path, dir.file("grf.mot")));
  // relative datafile paths with folders work too
  const std::string xml2 =
      dir.write("other/loads.xml", loadsXml("../loads/grf.mot", force("f", "a", "F_")));
  EXPECT_TRUE(sameFile(readExternalLoads(xml2, dir.file("nowhere")).datafile_path,
                       dir.file("loads/grf.mot")));
}

TEST(ExternalLoads, IdentifierMatchingAndErrors) {
  test::TempDir dir;
  dir.write("grf.mot", kData);
  // "F_" matches exactly F_x, F_y, F_z: "FF_x" does not start with "F_"
  const auto l = readExternalLoads(dir.write("ok.xml", loadsXml("grf.mot", force("f", "a", "F_", "P_", "FF_"))),
                                   dir.str());
  EXPECT_EQ(l.forces[0].force_columns, (std::array<int, 3>{0, 1, 2}));
  EXPECT_EQ(l.forces[0].point_columns, (std::array<int, 3>{3, 4, 5}));
  EXPECT_EQ(l.forces[0].torque_columns, (std::array<int, 3>{6, 7, 8}));
  auto expectErr = [&](const std::string& name, const std::string& text, const std::string& at,
                       const std::string& what) {
    const std::string p = dir.write(name, text);
    try {
      readExternalLoads(p, dir.str());
      ADD_FAILURE() << name;
    } catch (const ConvertError& e) {
      EXPECT_EQ(e.line(), test::lineContaining(text, at)) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  // "F" matches six columns (F_x.. and FF_x..)
  expectErr("six.xml", loadsXml("grf.mot", force("f", "a", "F")), "<force_identifier>",
            "matches 6 columns");
  expectErr("none.xml", loadsXml("grf.mot", force("f", "a", "G_")), "<force_identifier>",
            "matches 0 columns");
  expectErr("pointonly.xml", loadsXml("grf.mot", force("f", "a", "", "P_")), "<ExternalForce",
            "a point but no force");
  expectErr("nothing.xml", loadsXml("grf.mot", force("f", "a", "")), "<ExternalForce",
            "neither a force nor a torque");
  expectErr("nobody.xml", loadsXml("grf.mot", force("f", "", "F_")), "<ExternalForce",
            "has no applied_to_body");
  expectErr("nodata.xml", loadsXml("missing.mot", force("f", "a", "F_")), "<datafile>",
            "not found");
  expectErr("emptydata.xml", loadsXml("", force("f", "a", "F_")), "<datafile>", "no <datafile>");
  expectErr("wrongroot.xml", "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n"
            "<InverseDynamicsTool/>\n</OpenSimDocument>\n", "<OpenSimDocument", "no <ExternalLoads>");
}

TEST(InverseDynamicsSetup, SharedSetupsResolveRelativeToTheirFolder) {
  REDMAX_REQUIRE_SHARED();
  {
    const std::string setup = sharedOpenSim(
        "opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/walk_Setup_ID.xml");
    const auto s = readInverseDynamicsSetup(setup);
    const fs::path dir = fs::path(setup).parent_path();
    EXPECT_TRUE(sameFile(s.model_file, dir / "../subject01.osim"));
    EXPECT_TRUE(sameFile(s.coordinates_file, dir / "../IK/subject01_walk_IK.mot"));
    EXPECT_TRUE(sameFile(s.external_loads_file, dir / "../ExperimentalData/subject01_walk_grf.xml"));
    EXPECT_EQ(s.lowpass_cutoff_frequency_for_coordinates, 6.0);
    EXPECT_EQ(s.time_start, 0.0);
    EXPECT_EQ(s.time_end, 2.5);
    EXPECT_EQ(s.forces_to_exclude, std::vector<std::string>{"Muscles"});
    EXPECT_EQ(fs::path(s.output_gen_force_file).filename(), "subject01_walk_ID.sto");
    EXPECT_EQ(fs::path(s.output_gen_force_file).parent_path().filename(), "Results");
    EXPECT_TRUE(s.warnings.empty());
    // the whole chain loads: model, coordinates and loads, the loads' data found as OpenSim does
    EXPECT_NO_THROW(readOsimModel(s.model_file));
    EXPECT_NO_THROW(readStorage(s.coordinates_file));
    ExternalLoads l = readExternalLoads(s.external_loads_file, s.directory);
    checkExternalLoads(l, readOsimModel(s.model_file));
  }
  {
    // the 2.x setup: coordinates_in_degrees is reported as ignored; its files are named as the
    // tutorial lays them out (not all beside the setup), so only the resolution is checked
    const std::string setup = sharedOpenSim(
        "opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/InverseDynamics/"
        "arm26_Setup_InverseDynamics.xml");
    const auto s = readInverseDynamicsSetup(setup);
    EXPECT_EQ(fs::path(s.model_file), (fs::path(setup).parent_path() / "arm26.osim").lexically_normal());
    EXPECT_EQ(s.time_start, 0.0);
    EXPECT_EQ(s.time_end, 1.0);
    EXPECT_EQ(s.lowpass_cutoff_frequency_for_coordinates, 6.0);
    ASSERT_FALSE(s.warnings.empty());
    EXPECT_NE(s.warnings[0].find("coordinates_in_degrees"), std::string::npos);
  }
  {
    const std::string setup =
        sharedOpenSim("opensim-core/Applications/ID/tests/resources/ThorascapularShoulderModel_ID_static.xml");
    const auto s = readInverseDynamicsSetup(setup);
    EXPECT_TRUE(s.external_loads_file.empty());
    EXPECT_EQ(s.lowpass_cutoff_frequency_for_coordinates, -1.0);
    EXPECT_TRUE(sameFile(s.coordinates_file, fs::path(setup).parent_path() / "ThorascapularShoulderModel_static.mot"));
    EXPECT_EQ(s.time_start, 0.01);
    EXPECT_EQ(s.time_end, 0.06);
  }
  {
    const std::string setup =
        sharedOpenSim("opensim-models/Pipelines/Gait2392_Simbody/subject01_Setup_InverseDynamics.xml");
    const auto s = readInverseDynamicsSetup(setup);
    EXPECT_EQ(fs::path(s.output_gen_force_file).parent_path().filename(), "ResultsInverseDynamics");
    EXPECT_EQ(s.forces_to_exclude, std::vector<std::string>{"muscles"});
    EXPECT_NO_THROW(readStorage(s.coordinates_file));
    EXPECT_NO_THROW(readExternalLoads(s.external_loads_file, s.directory));
  }
}

TEST(InverseDynamicsSetup, DefaultsAbsolutePathsAndErrors) {
  test::TempDir dir;
  const std::string text =
      "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<InverseDynamicsTool name=\"t\">\n"
      "<model_file>/abs/model.osim</model_file>\n<coordinates_file>q.mot</coordinates_file>\n"
      "</InverseDynamicsTool>\n</OpenSimDocument>\n";
  const auto s = readInverseDynamicsSetup(dir.write("sub/setup.xml", text));
  EXPECT_EQ(s.model_file, "/abs/model.osim");
  EXPECT_TRUE(sameFile(fs::path(s.coordinates_file).parent_path(), dir.file("sub")));
  EXPECT_EQ(fs::path(s.output_gen_force_file).filename(), "inverse_dynamics.sto");
  EXPECT_EQ(s.lowpass_cutoff_frequency_for_coordinates, -1.0);
  EXPECT_TRUE(std::isinf(s.time_start) && s.time_start < 0);
  EXPECT_TRUE(std::isinf(s.time_end) && s.time_end > 0);
  const std::string bad =
      "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<InverseDynamicsTool>\n"
      "<time_range>2 1</time_range>\n</InverseDynamicsTool>\n</OpenSimDocument>\n";
  try {
    readInverseDynamicsSetup(dir.write("bad.xml", bad));
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), 4);
  }
  const std::string badnum =
      "<?xml version=\"1.0\"?>\n<InverseDynamicsTool>\n"
      "<lowpass_cutoff_frequency_for_coordinates>six</lowpass_cutoff_frequency_for_coordinates>\n"
      "</InverseDynamicsTool>\n";
  try {
    readInverseDynamicsSetup(dir.write("badnum.xml", badnum));
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(std::string(e.what()).find("'six' is not a number"), std::string::npos);
  }
}

}  // namespace
}  // namespace redmax::osim
