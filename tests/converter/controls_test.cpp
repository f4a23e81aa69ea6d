// OpenSim controls (converter/controls.hpp) and ForwardTool setups (converter/forward_setup.hpp):
// ControlLinear's interpolation (linear and steps), extrapolation, min/max, names; controls .sto;
// malformed files fail with FILE:LINE; arm26's SO controls and setup read as OpenSim reads them.
#include "converter/controls.hpp"

#include <gtest/gtest.h>

#include "converter/forward_setup.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

const char* kSet = R"(<?xml version="1.0" encoding="UTF-8"?>
<OpenSimDocument Version="40000">
<ControlSet name="c">
  <objects>
    <ControlLinear name="A.excitation">
      <extrapolate> true </extrapolate>
      <default_min> 0.02 </default_min>
      <default_max> 0.9 </default_max>
      <x_nodes>
        <ControlLinearNode><t> 0 </t><value> 0.1 </value></ControlLinearNode>
        <ControlLinearNode><t> 1 </t><value> 0.3 </value></ControlLinearNode>
        <ControlLinearNode><t> 2 </t><value> 0.2 </value></ControlLinearNode>
      </x_nodes>
      <max_nodes>
        <ControlLinearNode><t> 0 </t><value> 0.5 </value></ControlLinearNode>
      </max_nodes>
    </ControlLinear>
    <ControlLinear name="B">
      <extrapolate> false </extrapolate>
      <use_steps> true </use_steps>
      <x_nodes>
        <ControlLinearNode><t> 0 </t><value> 1 </value></ControlLinearNode>
        <ControlLinearNode><t> 1 </t><value> 2 </value></ControlLinearNode>
        <ControlLinearNode><t> 2 </t><value> 3 </value></ControlLinearNode>
      </x_nodes>
    </ControlLinear>
    <ControlLinear name="P.excitation">
      <is_model_control> false </is_model_control>
    </ControlLinear>
    <ControlConstant name="C.excitation"><value> 0.25 </value></ControlConstant>
  </objects>
</ControlSet>
</OpenSimDocument>
)";

TEST(Controls, ControlLinearInterpolatesExtrapolatesAndSteps) {
  test::TempDir dir;
  const ControlSetDesc cs = readControlSet(dir.write("c.xml", kSet));
  ASSERT_EQ(cs.controls.size(), 4u);
  const ControlLinearDesc* a = cs.findForActuator("A");
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->actuator(), "A");
  EXPECT_DOUBLE_EQ(a->value(0.5), 0.2);
  EXPECT_DOUBLE_EQ(a->value(1.0), 0.3);
  EXPECT_DOUBLE_EQ(a->value(1.5), 0.25);
  EXPECT_DOUBLE_EQ(a->value(-1.0), -0.1);  // extrapolated with the first two nodes
  EXPECT_DOUBLE_EQ(a->value(3.0), 0.1);    // and the last two
  EXPECT_DOUBLE_EQ(a->minValue(0.7), 0.02);
  EXPECT_DOUBLE_EQ(a->maxValue(0.7), 0.5);  // one node: its value
  const ControlLinearDesc* b = cs.findForActuator("B");
  ASSERT_NE(b, nullptr);
  EXPECT_DOUBLE_EQ(b->value(0.5), 2.0);  // steps: the next node's value
  EXPECT_DOUBLE_EQ(b->value(1.0), 2.0);  // (t_i, t_i+1]: at a node its own value (OpenSim)
  EXPECT_DOUBLE_EQ(b->value(1.0 + 1e-12), 3.0);
  EXPECT_DOUBLE_EQ(b->value(-5.0), 1.0);  // no extrapolation: end values
  EXPECT_DOUBLE_EQ(b->value(5.0), 3.0);
  EXPECT_EQ(cs.findForActuator("P"), nullptr);  // not a model control
  ASSERT_NE(cs.findForActuator("C"), nullptr);
  EXPECT_DOUBLE_EQ(cs.findForActuator("C")->value(7.0), 0.25);
  // as a core function of time
  FunctionValue v;
  VecJ x(1);
  x[0] = 1.5;
  makeControlFunction(*a)->evaluate(x, 0, v);
  EXPECT_DOUBLE_EQ(v.value, 0.25);
}

// use_steps never extrapolates, even with extrapolate true (ControlLinear::getControlValue)
TEST(Controls, StepsDoNotExtrapolate) {
  test::TempDir dir;
  const ControlSetDesc cs = readControlSet(dir.write("s.xml", R"(<ControlSet name="s"><objects>
<ControlLinear name="S"><extrapolate> true </extrapolate><use_steps> true </use_steps><x_nodes>
<ControlLinearNode><t> 0 </t><value> 1 </value></ControlLinearNode>
<ControlLinearNode><t> 1 </t><value> 2 </value></ControlLinearNode>
</x_nodes></ControlLinear></objects></ControlSet>
)"));
  const ControlLinearDesc* s = cs.findForActuator("S");
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->value(-1.0), 1.0);
  EXPECT_EQ(s->value(0.0), 1.0);
  EXPECT_EQ(s->value(0.5), 2.0);
  EXPECT_EQ(s->value(3.0), 2.0);
}

TEST(Controls, StorageColumnsBecomeLinearControls) {
  test::TempDir dir;
  const std::string f = dir.write("c.sto",
                                  "controls\nversion=1\nnRows=2\nnColumns=3\ninDegrees=no\nendheader\n"
                                  "time\tA\tB.excitation\n0\t0\t1\n1\t1\t0\n");
  const ControlSetDesc cs = readControlSet(f);
  ASSERT_EQ(cs.controls.size(), 2u);
  EXPECT_DOUBLE_EQ(cs.findForActuator("A")->value(0.25), 0.25);
  EXPECT_DOUBLE_EQ(cs.findForActuator("B")->value(0.25), 0.75);
}

TEST(Controls, MalformedFilesNameFileAndLine) {
  test::TempDir dir;
  struct Case {
    const char* what;
    std::string body;
    int line;
  };
  const std::string head = "<ControlSet>\n<objects>\n";
  const std::string tail = "</objects>\n</ControlSet>\n";
  const Case cases[] = {
      {"unknown class", head + "<ControlBogus name=\"x\"/>\n" + tail, 3},
      {"bad number", head + "<ControlLinear name=\"x\"><x_nodes>\n<ControlLinearNode><t> zz </t><value> 1 </value></ControlLinearNode>\n</x_nodes></ControlLinear>\n" + tail, 4},
      {"decreasing", head + "<ControlLinear name=\"x\"><x_nodes>\n<ControlLinearNode><t> 1 </t><value> 1 </value></ControlLinearNode>\n<ControlLinearNode><t> 0 </t><value> 1 </value></ControlLinearNode>\n</x_nodes></ControlLinear>\n" + tail, 5},
      {"duplicate", head + "<ControlLinear name=\"x\"/>\n<ControlLinear name=\"x\"/>\n" + tail, 4},
      {"no name", head + "<ControlLinear/>\n" + tail, 3},
  };
  for (const Case& c : cases) {
    const std::string f = dir.write(std::string(c.what) + ".xml", c.body);
    try {
      readControlSet(f);
      ADD_FAILURE() << c.what << ": no error";
    } catch (const ConvertError& e) {
      EXPECT_EQ(e.file(), f) << c.what;
      EXPECT_EQ(e.line(), c.line) << c.what << ": " << e.what();
    }
  }
  EXPECT_THROW(readControlSet(dir.file("missing.xml")), ConvertError);
  EXPECT_THROW(readControlSet(dir.write("trunc.xml", "<ControlSet><objects>")), ConvertError);
}

TEST(Controls, ControlLinearWithoutNodesIsRefusedWhereItDrivesAnActuator) {
  // OpenSim's ControlLinear::getControlValue is NaN without nodes; a ControlConstant has a value
  test::TempDir dir;
  const std::string f = dir.write("c.xml",
                                  "<ControlSet>\n<objects>\n<ControlConstant name=\"K\"><value>0.3</value></ControlConstant>\n"
                                  "<ControlLinear name=\"E.excitation\"/>\n</objects>\n</ControlSet>\n");
  std::vector<std::string> warnings;
  const ResolvedController k = resolveControlsFile(f, {"K"}, warnings);
  ASSERT_EQ(k.entries.size(), 1u);
  VecJ t(1);
  t[0] = 0.7;
  EXPECT_EQ(k.entries[0].function->value(t), 0.3);
  try {
    resolveControlsFile(f, {"K", "E"}, warnings);
    ADD_FAILURE() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.file(), f);
    EXPECT_EQ(e.line(), 4) << e.what();
    EXPECT_NE(std::string(e.what()).find("no x_nodes"), std::string::npos) << e.what();
  }
}

TEST(ForwardSetup, Arm26SetupAndControlsReadAsOpenSimReadsThem) {
  REDMAX_REQUIRE_SHARED();
  const std::string dir = test::sharedOpenSim("opensim-core/Applications/Forward/tests/resources");
  const ForwardSetup s = readForwardSetup(dir + "/arm26_Setup_Forward.xml");
  EXPECT_EQ(s.name, "arm26");
  EXPECT_EQ(s.model_file, dir + "/arm26.osim");
  EXPECT_EQ(s.states_file, dir + "/arm26_InitialStates.sto");
  EXPECT_EQ(s.results_directory, dir + "/Results");
  EXPECT_DOUBLE_EQ(s.final_time, 1.0);
  EXPECT_DOUBLE_EQ(s.integrator_error_tolerance, 1e-5);
  EXPECT_EQ(s.maximum_number_of_integrator_steps, 30000);
  EXPECT_FALSE(s.solve_for_equilibrium);
  ASSERT_EQ(s.controllers.size(), 1u);
  EXPECT_EQ(s.controllers[0].type, "ControlSetController");
  EXPECT_EQ(s.controllers[0].controls_file, dir + "/arm26_StaticOptimization_controls.xml");
  const ControlSetDesc cs = readControlSet(s.controllers[0].controls_file);
  EXPECT_EQ(cs.controls.size(), 6u);
  for (const char* m : {"TRIlong", "TRIlat", "TRImed", "BIClong", "BICshort", "BRA"})
    EXPECT_NE(cs.findForActuator(m), nullptr) << m;
  // the first node is at -2e-8 s with 0.01007432202249311700 (TRIlong)
  EXPECT_NEAR(cs.findForActuator("TRIlong")->value(-0.00000002000000343116), 0.010074322022493117, 1e-15);
}

TEST(ForwardSetup, BadSetupsFailWithFileAndLine) {
  test::TempDir dir;
  const std::string f = dir.write("s.xml",
                                  "<OpenSimDocument Version=\"40000\">\n<ForwardTool name=\"x\">\n"
                                  "<model_file>m.osim</model_file>\n<initial_time>1</initial_time>\n"
                                  "<final_time>0.5</final_time>\n</ForwardTool>\n</OpenSimDocument>\n");
  try {
    readForwardSetup(f);
    ADD_FAILURE() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), 5) << e.what();
  }
  const std::string g = dir.write("t.xml",
                                  "<ForwardTool name=\"x\">\n<integrator_error_tolerance>-1</integrator_error_tolerance>\n"
                                  "</ForwardTool>\n");
  EXPECT_THROW(readForwardSetup(g), ConvertError);
  const std::string h = dir.write("u.xml",
                                  "<ForwardTool name=\"x\">\n<ControllerSet><objects>\n<FooController/>\n"
                                  "</objects></ControllerSet>\n</ForwardTool>\n");
  try {
    readForwardSetup(h);
    ADD_FAILURE() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), 3) << e.what();
  }
}

}  // namespace
}  // namespace redmax::osim
