// Muscle force models from .osim files: each muscle's class-specific properties with OpenSim's
// defaults and legacy rules, the model built from them, the class override (OpenSim's
// renameType), and bad values as errors at their line.
#include <gtest/gtest.h>

#include <cmath>

#include "converter/build/build_core_model.hpp"
#include "converter/json_writer.hpp"
#include "converter/osim_reader.hpp"
#include "core/muscles/hill/factory.hpp"
#include "core/muscles/hill/thelen2003_muscle.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using test::bodyXml;
using test::lineContaining;
using test::modernOsim;
using test::pinXml;

const std::string kArm26Forward = "opensim-core/Applications/Forward/tests/resources/arm26.osim";

TEST(MuscleModels, Arm26ReadsThelenPropertiesWithLegacyRules) {
  REDMAX_REQUIRE_SHARED();
  const ModelDescription d = readOsimModel(test::sharedOpenSim(kArm26Forward));
  const BuildResult b = buildCoreModel(d);
  const MusculoskeletalModel& m = b.model;
  ASSERT_EQ(m.numMuscles(), 6);
  const int k = m.findMuscle("TRIlong");
  ASSERT_GE(k, 0);
  ASSERT_TRUE(m.muscleModels()[k]);
  EXPECT_EQ(m.muscleModels()[k]->className(), "Thelen2003Muscle");
  const auto& p = *m.muscleParameters()[k];
  EXPECT_EQ(p.get("optimal_fiber_length", 0), 0.134);
  EXPECT_EQ(p.get("KshapeActive", 0), 0.5);
  EXPECT_EQ(p.get("Vmax", 0), 10.0);  // read, though Thelen2003Muscle (4.x) ignores it
  // a 20302 file's min_control 0 is dropped (Muscle::updateFromXMLNode < 30513): the class default
  EXPECT_FALSE(p.has("min_control"));
  EXPECT_EQ(m.muscleModels()[k]->minControl(), 0.01);
  const auto* thelen = dynamic_cast<const hill::Thelen2003Muscle*>(m.muscleModels()[k].get());
  ASSERT_NE(thelen, nullptr);
  EXPECT_EQ(thelen->curves().FmaxTendonStrain, 0.033);
  EXPECT_EQ(thelen->curves().fv_linear_extrap_threshold, 0.95);  // absent: OpenSim's default
  EXPECT_NEAR(thelen->properties().pennation_angle_at_optimal, 0.20943951, 0);
  for (int i = 0; i < m.numMuscles(); ++i) EXPECT_TRUE(m.muscleModels()[i]) << m.muscles()[i].name;
}

TEST(MuscleModels, Arm26ReadAsEachModelledClass) {
  REDMAX_REQUIRE_SHARED();
  const ModelDescription d = readOsimModel(test::sharedOpenSim(kArm26Forward));
  const MusculoskeletalModel base = buildCoreModel(d).model;
  for (const std::string& cls : hill::muscleModelClasses()) {
    MusculoskeletalModelBuilder edit(base);
    edit.overrideMuscleClass(cls);
    const MusculoskeletalModel m = edit.finalize();
    for (int i = 0; i < m.numMuscles(); ++i) {
      EXPECT_EQ(m.muscleClasses()[i], cls);
      ASSERT_TRUE(m.muscleModels()[i]) << cls;
      EXPECT_EQ(m.muscleModels()[i]->className(), cls);
      // every model equilibrates at the default pose with its states
      std::vector<double> z(m.muscleModels()[i]->numStates());
      m.muscleModels()[i]->defaultState(z.data());
      if (!z.empty()) z[0] = 0.5;
      EXPECT_NO_THROW(m.muscleModels()[i]->equilibrate({0.3, 0.0, 0.5}, z.data())) << cls;
    }
    // the original is untouched
    EXPECT_EQ(base.muscleModels()[0]->className(), "Thelen2003Muscle");
  }
  // a class redmax does not model is refused, and the builder keeps its models
  MusculoskeletalModelBuilder edit(base);
  EXPECT_THROW(edit.overrideMuscleClass("NoSuchMuscle"), hill::MuscleModelError);
  EXPECT_EQ(edit.finalize().muscleModels()[0]->className(), "Thelen2003Muscle");
}

std::string muscleXml(const std::string& cls, const std::string& props) {
  return "<ForceSet><objects>\n<" + cls + " name=\"m\">\n<GeometryPath name=\"path\">\n"
         "<PathPointSet><objects>\n"
         "<PathPoint name=\"o\">\n<socket_parent_frame>/bodyset/a</socket_parent_frame>\n"
         "<location>0 0 0</location>\n</PathPoint>\n"
         "<PathPoint name=\"i\">\n<socket_parent_frame>/bodyset/b</socket_parent_frame>\n"
         "<location>0 0.3 0</location>\n</PathPoint>\n"
         "</objects></PathPointSet>\n</GeometryPath>\n" + props + "</" + cls + ">\n</objects></ForceSet>\n";
}

std::string osimWithMuscle(const std::string& cls, const std::string& props) {
  return modernOsim(bodyXml("a") + bodyXml("b"),
                    pinXml("j1", "/ground", "/bodyset/a") + pinXml("j2", "/bodyset/a", "/bodyset/b"),
                    muscleXml(cls, props));
}

// read text; expect a ConvertError "FILE:LINE: ..." at the line of `at` mentioning `what`
void expectError(const std::string& text, const std::string& at, const std::string& what) {
  test::TempDir dir;
  const std::string path = dir.write("bad.osim", text);
  const int line = lineContaining(text, at);
  ASSERT_GT(line, 0) << "test bug: '" << at << "' not in the text";
  try {
    readOsimModel(path);
    ADD_FAILURE() << "no error for: " << what;
  } catch (const ConvertError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ":" + std::to_string(line) + ": ", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(MuscleModels, BadValuesAreErrorsAtTheirLine) {
  expectError(osimWithMuscle("Thelen2003Muscle", "<optimal_fiber_length>-0.1</optimal_fiber_length>\n"),
              "<optimal_fiber_length>", "optimal_fiber_length");
  expectError(osimWithMuscle("Thelen2003Muscle_Deprecated", "<optimal_fiber_length>0</optimal_fiber_length>\n"),
              "<optimal_fiber_length>", "must be finite and > 0");
  expectError(osimWithMuscle("Thelen2003Muscle", "<Flen>0.9</Flen>\n"), "<Flen>", "Flen");
  expectError(osimWithMuscle("Thelen2003Muscle", "<FmaxTendonStrain>x</FmaxTendonStrain>\n"),
              "<FmaxTendonStrain>", "not a number");
  expectError(osimWithMuscle("Thelen2003Muscle", "<min_control>0</min_control>\n"), "<min_control>",
              "minimum_activation");  // a 40000 file keeps its min_control
  expectError(osimWithMuscle("Thelen2003Muscle", "<ignore_tendon_compliance>true</ignore_tendon_compliance>\n"),
              "<ignore_tendon_compliance>", "not implemented");
  expectError(osimWithMuscle("Thelen2003Muscle", "<pennation_angle_at_optimal>2</pennation_angle_at_optimal>\n"),
              "<pennation_angle_at_optimal>", "pennation_angle_at_optimal");
}

TEST(MuscleModels, ConvertReportsClassAndParameters) {
  test::TempDir dir;
  const std::string path =
      dir.write("m.osim", osimWithMuscle("Thelen2003Muscle", "<KshapeActive>0.5</KshapeActive>\n"));
  const ModelDescription d = readOsimModel(path);
  const std::string json = describeAsJson(d);
  EXPECT_NE(json.find("\"force_model\": \"Thelen2003Muscle\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"KshapeActive\": 0.5"), std::string::npos);
  EXPECT_NE(json.find("\"Flen\": 1.3999999999999999"), std::string::npos);  // the default, reported
  EXPECT_NE(json.find("/forceset/m/fiber_length"), std::string::npos);
  EXPECT_NE(formatSummary(d).find("force models for 1 of 1 muscles"), std::string::npos) << formatSummary(d);
}

}  // namespace
}  // namespace redmax::osim
