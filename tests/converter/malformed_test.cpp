// Malformed inputs generated in a temporary folder: each must fail with a ConvertError whose
// message starts "FILE:LINE:" at the offending element, and nothing may crash. A fuzz pass
// truncates and corrupts real models (fixed seed) and accepts only success or ConvertError.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>

#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using test::bodyXml;
using test::lineContaining;
using test::modernOsim;
using test::pinXml;

// read text; expect a ConvertError at the line of `at` whose message contains `what`
void expectError(const std::string& text, const std::string& at, const std::string& what) {
  test::expectReadError(text, at, what);
}

const std::string kTwoBodies = bodyXml("a") + bodyXml("b");
const std::string kChain =
    pinXml("j1", "/ground", "/bodyset/a") + pinXml("j2", "/bodyset/a", "/bodyset/b");

TEST(Malformed, ValidBaselineReads) {
  test::TempDir dir;
  const auto d = readOsimModel(dir.write("ok.osim", modernOsim(kTwoBodies, kChain)));
  EXPECT_EQ(d.numDofs(), 2);
}

TEST(Malformed, MissingFileAndBrokenXml) {
  try {
    readOsimModel("/nonexistent/dir/model.osim");
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/dir/model.osim: cannot open file");
  }
  // truncated in the middle of the JointSet: the parser reports where the document breaks
  const std::string full = modernOsim(kTwoBodies, kChain);
  const std::string cut = full.substr(0, full.find("<PinJoint name=\"j2\">") + 10);
  test::TempDir dir;
  const std::string path = dir.write("cut.osim", cut);
  try {
    readOsimModel(path);
    ADD_FAILURE();
  } catch (const ConvertError& e) {
    EXPECT_GT(e.line(), 0);
    EXPECT_NE(std::string(e.what()).find("malformed XML"), std::string::npos);
  }
  expectError("<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<Model>\n"
              "<BodySet></Model>\n</OpenSimDocument>\n", "", "malformed XML");
}

TEST(Malformed, WrongVersionsAndRoots) {
  expectError("<?xml version=\"1.0\"?>\n<Model name=\"x\"/>\n", "<Model", "not <OpenSimDocument");
  expectError("<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"10600\">\n<Model/>\n"
              "</OpenSimDocument>\n", "<OpenSimDocument", "older than 10901");
  expectError("<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"4.0\">\n<Model/>\n"
              "</OpenSimDocument>\n", "<OpenSimDocument", "not a file version number");
  expectError("<?xml version=\"1.0\"?>\n<OpenSimDocument>\n<Model/>\n</OpenSimDocument>\n",
              "<OpenSimDocument", "no Version attribute");
  expectError("<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<Thing/>\n"
              "</OpenSimDocument>\n", "<OpenSimDocument", "no <Model>");
}

TEST(Malformed, MissingElementsAndBadNumbers) {
  expectError(modernOsim("<Body name=\"a\">\n<mass_center>0 0 0</mass_center>\n</Body>\n",
                         pinXml("j1", "/ground", "/bodyset/a")),
              "<Body name=\"a\">", "has no <mass>");
  expectError(modernOsim("<Body name=\"a\">\n<mass>1</mass>\n<mass_center>0 x 0</mass_center>\n"
                         "</Body>\n", pinXml("j1", "/ground", "/bodyset/a")),
              "<mass_center>", "'x' is not a number");
  expectError(modernOsim("<Body name=\"a\">\n<mass>1</mass>\n<inertia>1 1 1 0 0</inertia>\n"
                         "</Body>\n", pinXml("j1", "/ground", "/bodyset/a")),
              "<inertia>", "needs 6 numbers, found 5");
  expectError(modernOsim("<Body name=\"a\">\n<mass>-2</mass>\n</Body>\n",
                         pinXml("j1", "/ground", "/bodyset/a")),
              "<mass>-2", "invalid mass");
  expectError(modernOsim(bodyXml("a"),
                         "<PinJoint name=\"j1\">\n<socket_parent_frame>/ground</socket_parent_frame>\n"
                         "<socket_child_frame>/bodyset/a</socket_child_frame>\n<coordinates>"
                         "<Coordinate name=\"q\">\n<locked>maybe</locked>\n</Coordinate>"
                         "</coordinates>\n</PinJoint>\n"),
              "<locked>", "is not true or false");
  expectError(modernOsim(bodyXml("a"),
                         "<PinJoint name=\"j1\">\n<socket_child_frame>/bodyset/a</socket_child_frame>\n"
                         "</PinJoint>\n"),
              "<PinJoint name=\"j1\">", "has no parent_frame socket");
}

TEST(Malformed, UnknownJointTypeAndWrongCoordinateCounts) {
  expectError(modernOsim(bodyXml("a"),
                         "<HingeJoint name=\"h\">\n<socket_parent_frame>/ground</socket_parent_frame>"
                         "\n<socket_child_frame>/bodyset/a</socket_child_frame>\n</HingeJoint>\n"),
              "<HingeJoint", "unknown joint type <HingeJoint>");
  expectError(modernOsim(bodyXml("a"),
                         "<PinJoint name=\"j1\">\n<socket_parent_frame>/ground</socket_parent_frame>\n"
                         "<socket_child_frame>/bodyset/a</socket_child_frame>\n<coordinates>"
                         "<Coordinate name=\"q1\"/><Coordinate name=\"q2\"/></coordinates>\n"
                         "</PinJoint>\n"),
              "<PinJoint name=\"j1\">", "has 2 coordinates; a PinJoint has 1");
}

TEST(Malformed, BrokenSocketPaths) {
  expectError(modernOsim(kTwoBodies, pinXml("j1", "/ground", "/bodyset/nothere") +
                                         pinXml("j2", "/bodyset/a", "/bodyset/b")),
              "/bodyset/nothere", "does not name a frame");
  expectError(modernOsim(kTwoBodies, pinXml("j1", "../../../../ground", "/bodyset/a") +
                                         pinXml("j2", "/bodyset/a", "/bodyset/b")),
              "../../../../ground", "leaves the model");
  // a relative offset-frame name that the joint does not own
  expectError(modernOsim(kTwoBodies, pinXml("j1", "ground_offset", "/bodyset/a") +
                                         pinXml("j2", "/bodyset/a", "/bodyset/b")),
              "ground_offset", "/jointset/j1/ground_offset");
  // both frames on one body
  expectError(modernOsim(kTwoBodies, pinXml("j1", "/bodyset/a", "/bodyset/a") +
                                         pinXml("j2", "/bodyset/a", "/bodyset/b")),
              "<PinJoint name=\"j1\">", "both fixed to 'a'");
  // a frame type that is read but not modelled cannot carry a joint
  std::string sdf = modernOsim(kTwoBodies, pinXml("j1", "/ground", "/bodyset/a/sdf") +
                                               pinXml("j2", "/bodyset/a", "/bodyset/b"));
  sdf.insert(sdf.find("<mass>1.000000</mass>"),
             "<components><StationDefinedFrame name=\"sdf\"/></components>\n");
  expectError(sdf, "/bodyset/a/sdf", "is a StationDefinedFrame, which is not supported");
  // a cycle of offset frames (a frame's socket is relative to the frame itself: siblings are ../)
  const std::string cyc =
      "<PinJoint name=\"j1\">\n<socket_parent_frame>f1</socket_parent_frame>\n"
      "<socket_child_frame>/bodyset/a</socket_child_frame>\n<coordinates><Coordinate name=\"q\"/>"
      "</coordinates>\n<frames>\n<PhysicalOffsetFrame name=\"f1\"><socket_parent>../f2</socket_parent>"
      "</PhysicalOffsetFrame>\n<PhysicalOffsetFrame name=\"f2\"><socket_parent>../f1</socket_parent>"
      "</PhysicalOffsetFrame>\n</frames>\n</PinJoint>\n";
  expectError(modernOsim(bodyXml("a"), cyc), "", "cycle of frames");
}

std::string customJoint(const std::string& axes, const std::string& coords = "<Coordinate name=\"q\"/>") {
  return "<CustomJoint name=\"c\">\n<socket_parent_frame>/ground</socket_parent_frame>\n"
         "<socket_child_frame>/bodyset/a</socket_child_frame>\n<coordinates>" + coords +
         "</coordinates>\n<SpatialTransform>\n" + axes + "</SpatialTransform>\n</CustomJoint>\n";
}

TEST(Malformed, CustomJointsAndFunctions) {
  expectError(modernOsim(bodyXml("a"), customJoint(
                  "<TransformAxis name=\"rotation1\"><coordinates>q</coordinates><axis>0 0 1</axis>\n"
                  "<FooFunction name=\"function\"/></TransformAxis>\n")),
              "<FooFunction", "unknown function type <FooFunction>");
  expectError(modernOsim(bodyXml("a"), customJoint(
                  "<TransformAxis name=\"rotation1\"><coordinates>q</coordinates><axis>0 0 1</axis>\n"
                  "<SimmSpline name=\"function\"><x>0 1 2</x><y>0 1</y></SimmSpline>\n"
                  "</TransformAxis>\n")),
              "<SimmSpline", "x has 3 values but y has 2");
  expectError(modernOsim(bodyXml("a"), customJoint(
                  "<TransformAxis name=\"rotation1\"><coordinates>q</coordinates><axis>0 0 1</axis>"
                  "</TransformAxis>\n<TransformAxis name=\"rotation2\"><axis>0 0 2</axis>"
                  "</TransformAxis>\n")),
              "<SpatialTransform>", "collinear rotation axes");
  expectError(modernOsim(bodyXml("a"), customJoint(
                  "<TransformAxis name=\"rotation1\"><coordinates>q</coordinates><axis>0 0 1</axis>"
                  "</TransformAxis>\n", "<Coordinate name=\"q\"/><Coordinate name=\"extra\"/>")),
              "<CustomJoint", "'extra' is not used by any TransformAxis");
  expectError(modernOsim(bodyXml("a"), customJoint(
                  "<TransformAxis name=\"rotation1\"><coordinates>q r</coordinates>"
                  "<axis>0 0 1</axis></TransformAxis>\n",
                  "<Coordinate name=\"q\"/><Coordinate name=\"r\"/>")),
              "<SpatialTransform>", "several coordinates but no function");
  expectError(modernOsim(bodyXml("a"), customJoint(
                  "<TransformAxis name=\"rotation1\"><coordinates>q</coordinates><axis>0 0 1</axis>\n"
                  "<LinearFunction name=\"function\"><coefficients>1 2 0</coefficients>"
                  "</LinearFunction></TransformAxis>\n")),
              "<LinearFunction", "takes 2 arguments but 1 coordinates");
  expectError(modernOsim(bodyXml("a"), customJoint(
                  "<TransformAxis name=\"rotation7\"><coordinates>q</coordinates></TransformAxis>\n")),
              "rotation7", "not rotation1..3 or translation1..3");
  expectError(modernOsim(bodyXml("a"), customJoint(
                  "<TransformAxis name=\"rotation1\"><coordinates>q</coordinates><axis>0 0 1</axis>\n"
                  "<GCVSpline name=\"function\"><half_order>3</half_order><x>0 1 2</x><y>0 1 2</y>"
                  "</GCVSpline></TransformAxis>\n")),
              "<GCVSpline", "needs at least 6 points");
}

TEST(Malformed, CoordinatesAndConstraints) {
  expectError(modernOsim(bodyXml("a"),
                         "<PinJoint name=\"j1\">\n<socket_parent_frame>/ground</socket_parent_frame>\n"
                         "<socket_child_frame>/bodyset/a</socket_child_frame>\n<coordinates>\n"
                         "<Coordinate name=\"q\"><default_value>2</default_value><range>-1 1</range>"
                         "<clamped>true</clamped></Coordinate>\n</coordinates>\n</PinJoint>\n"),
              "<Coordinate name=\"q\">", "clamped but its default_value");
  const std::string coupler =
      "<ConstraintSet><objects>\n<CoordinateCouplerConstraint name=\"cc\">\n"
      "<coupled_coordinates_function><LinearFunction><coefficients>1 0</coefficients>"
      "</LinearFunction></coupled_coordinates_function>\n"
      "<independent_coordinate_names>j1_q nope</independent_coordinate_names>\n"
      "<dependent_coordinate_name>j2_q</dependent_coordinate_name>\n"
      "</CoordinateCouplerConstraint>\n</objects></ConstraintSet>\n";
  expectError(modernOsim(kTwoBodies, kChain, coupler), "<independent_coordinate_names>",
              "coordinate 'nope' does not exist");
  const std::string weld =
      "<ConstraintSet><objects>\n<WeldConstraint name=\"w\">\n"
      "<socket_frame1>/bodyset/a</socket_frame1>\n<socket_frame2>/bodyset/zz</socket_frame2>\n"
      "</WeldConstraint>\n</objects></ConstraintSet>\n";
  expectError(modernOsim(kTwoBodies, kChain, weld), "<socket_frame2>", "does not name a frame");
}

std::string muscle(const std::string& points, const std::string& wraps = "") {
  return "<ForceSet><objects>\n<Thelen2003Muscle name=\"m\">\n<GeometryPath name=\"path\">\n"
         "<PathPointSet><objects>\n" + points + "</objects></PathPointSet>\n"
         "<PathWrapSet><objects>\n" + wraps + "</objects></PathWrapSet>\n"
         "</GeometryPath>\n</Thelen2003Muscle>\n</objects></ForceSet>\n";
}

std::string point(const std::string& name, const std::string& frame, const std::string& more = "") {
  return "<PathPoint name=\"" + name + "\">\n<socket_parent_frame>" + frame +
         "</socket_parent_frame>\n<location>0 0 0</location>\n" + more + "</PathPoint>\n";
}

TEST(Malformed, PathsAndWrapObjects) {
  expectError(modernOsim(kTwoBodies, kChain, muscle(point("o", "/bodyset/a") + point("i", "/bodyset/q"))),
              "/bodyset/q", "does not name a frame");
  expectError(modernOsim(kTwoBodies, kChain, muscle(point("o", "/bodyset/a"))), "<PathPointSet>",
              "has 1 path points");
  expectError(modernOsim(kTwoBodies, kChain,
                         muscle(point("o", "/bodyset/a") + point("i", "/bodyset/b"),
                                "<PathWrap name=\"pw\">\n<wrap_object>ghost</wrap_object>\n"
                                "</PathWrap>\n")),
              "<wrap_object>ghost", "wrap object 'ghost' does not exist");
  const std::string cond =
      "<ConditionalPathPoint name=\"c\">\n<socket_parent_frame>/bodyset/a</socket_parent_frame>\n"
      "<range>0 1</range>\n<socket_coordinate>/jointset/j1/nope</socket_coordinate>\n"
      "</ConditionalPathPoint>\n";
  expectError(modernOsim(kTwoBodies, kChain,
                         muscle(point("o", "/bodyset/a") + cond + point("i", "/bodyset/b"))),
              "<socket_coordinate>", "does not name a coordinate");
  const std::string body_with_wrap =
      "<Body name=\"a\">\n<mass>1</mass>\n<WrapObjectSet><objects>\n<WrapCylinder name=\"cyl\">\n"
      "<quadrant>+w</quadrant>\n</WrapCylinder>\n</objects></WrapObjectSet>\n</Body>\n" +
      bodyXml("b");
  expectError(modernOsim(body_with_wrap, kChain), "<quadrant>+w", "quadrant '+w'");
  const std::string mov =
      "<MovingPathPoint name=\"mv\">\n<socket_parent_frame>/bodyset/a</socket_parent_frame>\n"
      "<socket_x_coordinate>/jointset/j1/j1_q</socket_x_coordinate>\n"
      "<socket_y_coordinate>/jointset/j2/j2_q</socket_y_coordinate>\n</MovingPathPoint>\n";
  expectError(modernOsim(kTwoBodies, kChain,
                         muscle(point("o", "/bodyset/a") + mov + point("i", "/bodyset/b"))),
              "<MovingPathPoint", "names different coordinates");
}

TEST(Malformed, LegacyLayout) {
  const std::string head =
      "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"20303\">\n<Model name=\"x\">\n"
      "<BodySet><objects>\n<Body name=\"ground\"><mass>0</mass><Joint/></Body>\n";
  const std::string tail = "</objects></BodySet>\n</Model>\n</OpenSimDocument>\n";
  expectError(head + "<Body name=\"a\"><mass>1</mass><Joint>\n<PinJoint name=\"p\">\n"
                     "<location>0 0 0</location></PinJoint>\n</Joint></Body>\n" + tail,
              "<PinJoint name=\"p\">", "has no <parent_body>");
  expectError(head + "<Body name=\"a\"><mass>1</mass><Joint>\n<PinJoint name=\"p\">\n"
                     "<parent_body>ghost</parent_body>\n</PinJoint>\n</Joint></Body>\n" + tail,
              "<parent_body>ghost", "does not name a frame");
}

// truncations and corruptions of real models: success or ConvertError, never anything else
void fuzzModel(const std::string& path, int trials, unsigned seed) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  ASSERT_GT(text.size(), 1000u);
  std::mt19937 rng(seed);
  test::TempDir dir;
  int errors = 0;
  for (int t = 0; t < trials; ++t) {
    std::string bad = text;
    const size_t at = std::uniform_int_distribution<size_t>(0, text.size() - 1)(rng);
    switch (t % 4) {
      case 0: bad.resize(at); break;                        // truncated
      case 1: bad[at] = "<>/\"x9-.e "[t % 10]; break;        // one byte changed
      case 2: bad.erase(at, std::min<size_t>(40, bad.size() - at)); break;  // a chunk removed
      case 3: {                                             // a number replaced by garbage
        const size_t d = bad.find_first_of("0123456789", at);
        if (d != std::string::npos) bad.replace(d, 1, "q");
        break;
      }
    }
    const std::string p = dir.write("fuzz.osim", bad);
    try {
      readOsimModel(p);
    } catch (const ConvertError& e) {
      ++errors;
      EXPECT_EQ(std::string(e.what()).rfind(p + ":", 0), 0u) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "trial " << t << ": unexpected " << typeid(e).name() << ": " << e.what();
    }
  }
  EXPECT_GT(errors, trials / 4);  // most corruptions are noticed
}

TEST(Malformed, FuzzedRealModelsFailCleanly) {
  REDMAX_REQUIRE_SHARED();
  fuzzModel(test::sharedOpenSim("opensim-models/Models/Arm26/arm26.osim"), 120, 12345u);
  fuzzModel(test::sharedOpenSim(
                "opensim-models@a26e12c/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim"),
            120, 777u);
  fuzzModel(test::sharedOpenSim("opensim-models/Models/Leg6Dof9Musc/leg6dof9musc.osim"), 80, 4242u);
}

}  // namespace
}  // namespace redmax::osim
