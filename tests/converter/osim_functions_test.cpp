// Every OpenSim Function type is stored as typed data with its parameters (semantics §4), in both
// the 4.0 named form <Type name="prop"> and the pre-4.0 wrapper form <prop><Type/></prop>;
// CustomJoint motion types follow §3.4 (unit-slope LinearFunction only, last such axis wins).
#include <gtest/gtest.h>

#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

// a PinJoint per function, the function as the coordinate's prescribed_function
std::string pinWithFunction(int i, const std::string& function_xml) {
  const std::string n = std::to_string(i);
  return "<PinJoint name=\"j" + n + "\">\n<socket_parent_frame>/ground</socket_parent_frame>\n"
         "<socket_child_frame>/bodyset/b" + n + "</socket_child_frame>\n<coordinates>"
         "<Coordinate name=\"q" + n + "\">\n<prescribed>true</prescribed>\n" + function_xml +
         "</Coordinate></coordinates>\n</PinJoint>\n";
}

TEST(OsimFunctions, EveryTypeIsReadAsData) {
  const std::vector<std::string> fx = {
      "<Constant name=\"prescribed_function\"><value>2.5</value></Constant>",
      "<prescribed_function><LinearFunction><coefficients>-1 0.5</coefficients></LinearFunction>"
      "</prescribed_function>",
      "<PolynomialFunction name=\"prescribed_function\"><coefficients>3 2 1</coefficients>"
      "</PolynomialFunction>",
      "<NaturalCubicSpline name=\"prescribed_function\"><x>0 1 2</x><y>0 1 4</y></NaturalCubicSpline>",
      "<GCVSpline name=\"prescribed_function\"><half_order>2</half_order><error_variance>0"
      "</error_variance><x>0 1 2 3</x><y>0 1 4 9</y><weights>1 1 1 1</weights></GCVSpline>",
      "<MultiplierFunction name=\"prescribed_function\"><function><SimmSpline><x>0 1</x><y>0 2</y>"
      "</SimmSpline></function><scale>-0.5</scale></MultiplierFunction>",
      "<PiecewiseLinearFunction name=\"prescribed_function\"><x>0 1</x><y>5 6</y>"
      "</PiecewiseLinearFunction>",
      "<PiecewiseConstantFunction name=\"prescribed_function\"><x>0 1 2</x><y>1 2 3</y>"
      "</PiecewiseConstantFunction>",
      "<Sine name=\"prescribed_function\"><amplitude>2</amplitude><omega>3</omega><phase>0.25</phase>"
      "</Sine>",
      "<prescribed_function><StepFunction><transition_start_time>1</transition_start_time>"
      "<transition_end_time>2</transition_end_time><end_value>7</end_value></StepFunction>"
      "</prescribed_function>",
      "<MultivariatePolynomialFunction name=\"prescribed_function\"><dimension>1</dimension>"
      "<order>2</order><coefficients>1 2 3</coefficients></MultivariatePolynomialFunction>",
      "<ExpressionBasedFunction name=\"prescribed_function\"><expression>sin(x)</expression>"
      "</ExpressionBasedFunction>",
  };
  std::string bodies, joints;
  for (size_t i = 0; i < fx.size(); ++i) {
    bodies += test::bodyXml("b" + std::to_string(i));
    joints += pinWithFunction(static_cast<int>(i), fx[i]);
  }
  test::TempDir dir;
  const auto d = readOsimModel(dir.write("f.osim", test::modernOsim(bodies, joints)));
  auto f = [&](int i) -> const FunctionDesc& {
    const auto& c = d.coordinates.at(d.findCoordinate("q" + std::to_string(i)));
    EXPECT_TRUE(c.prescribed);
    return c.prescribed_function.value();
  };
  EXPECT_EQ(f(0).kind, FunctionKind::Constant);
  EXPECT_EQ(f(0).value, 2.5);
  EXPECT_EQ(f(0).numArguments(), 0);
  EXPECT_EQ(f(1).kind, FunctionKind::Linear);
  EXPECT_EQ(f(1).coefficients, (std::vector<double>{-1, 0.5}));
  EXPECT_TRUE(f(1).isUnitSlopeLinear());
  EXPECT_EQ(f(1).numArguments(), 1);
  EXPECT_EQ(f(2).kind, FunctionKind::Polynomial);
  EXPECT_EQ(f(2).coefficients, (std::vector<double>{3, 2, 1}));
  EXPECT_EQ(f(3).kind, FunctionKind::SimmSpline);
  EXPECT_EQ(f(3).type, "SimmSpline");
  EXPECT_EQ(f(3).written_type, "NaturalCubicSpline");
  EXPECT_EQ(f(3).y, (std::vector<double>{0, 1, 4}));
  EXPECT_EQ(f(4).kind, FunctionKind::GCVSpline);
  EXPECT_EQ(f(4).half_order, 2);
  EXPECT_EQ(f(4).x.size(), 4u);
  EXPECT_EQ(f(5).kind, FunctionKind::Multiplier);
  EXPECT_EQ(f(5).scale, -0.5);
  ASSERT_EQ(f(5).inner.size(), 1u);
  EXPECT_EQ(f(5).inner[0].kind, FunctionKind::SimmSpline);
  EXPECT_EQ(f(5).numArguments(), 1);
  EXPECT_FALSE(f(5).isUnitSlopeLinear());
  EXPECT_EQ(f(6).kind, FunctionKind::PiecewiseLinear);
  EXPECT_EQ(f(6).y, (std::vector<double>{5, 6}));
  EXPECT_EQ(f(7).kind, FunctionKind::PiecewiseConstant);
  EXPECT_EQ(f(8).kind, FunctionKind::Sine);
  EXPECT_EQ(f(8).amplitude, 2.0);
  EXPECT_EQ(f(8).omega, 3.0);
  EXPECT_EQ(f(8).phase, 0.25);
  EXPECT_EQ(f(8).offset, 0.0);  // default
  EXPECT_EQ(f(9).kind, FunctionKind::Step);
  EXPECT_EQ(f(9).start_time, 1.0);
  EXPECT_EQ(f(9).end_time, 2.0);
  EXPECT_EQ(f(9).start_value, 0.0);  // default
  EXPECT_EQ(f(9).end_value, 7.0);
  EXPECT_EQ(f(10).kind, FunctionKind::MultivariatePolynomial);
  EXPECT_EQ(f(10).dimension, 1);
  EXPECT_EQ(f(10).order, 2);
  EXPECT_EQ(f(11).kind, FunctionKind::ExpressionBased);
  EXPECT_EQ(f(11).expression, "sin(x)");
  // the expression function cannot be evaluated: it is reported
  ASSERT_EQ(d.unsupported.size(), 1u);
  EXPECT_NE(d.unsupported[0].what.find("ExpressionBasedFunction"), std::string::npos);
}

std::string custom(const std::string& axes, const std::string& coords) {
  return "<CustomJoint name=\"c\">\n<socket_parent_frame>/ground</socket_parent_frame>\n"
         "<socket_child_frame>/bodyset/a</socket_child_frame>\n<coordinates>" + coords +
         "</coordinates>\n<SpatialTransform>\n" + axes + "</SpatialTransform>\n</CustomJoint>\n";
}

std::string axis(const std::string& name, const std::string& coords, const std::string& vec,
                 const std::string& fn = "") {
  return "<TransformAxis name=\"" + name + "\"><coordinates>" + coords + "</coordinates><axis>" +
         vec + "</axis>" + fn + "</TransformAxis>\n";
}

TEST(OsimFunctions, CustomJointMotionTypesAndMobilityOrder) {
  // coordinates listed b, a, k, u, s; the transform meets a, then b, ... -> q order a, b, ...
  const std::string lin2 = "<LinearFunction name=\"function\"><coefficients>2 0</coefficients></LinearFunction>";
  const std::string unit = "<LinearFunction name=\"function\"><coefficients>-1 0.3</coefficients></LinearFunction>";
  const std::string spline =
      "<SimmSpline name=\"function\"><x>0 1 2</x><y>0 0.1 0.3</y></SimmSpline>";
  const std::string two = "<LinearFunction name=\"function\"><coefficients>1 1 0</coefficients></LinearFunction>";
  const std::string axes =
      axis("rotation1", "a", "1 0 0") +           // no function, one coordinate: Linear(1,0)
      axis("rotation2", "b", "0 1 0", lin2) +     // slope 2: Coupled (unless another axis says)
      axis("rotation3", "k", "0 0 1", unit) +     // slope -1: Rotational
      axis("translation1", "k", "1 0 0", spline) +  // k stays Rotational (set before)
      axis("translation2", "b", "0 1 0", unit) +  // b becomes Translational: last unit axis wins
      axis("translation3", "u s", "0 0 1", two);  // first slope is 1: OpenSim says Translational
  const std::string coords =
      "<Coordinate name=\"b\"/><Coordinate name=\"a\"><default_value>0.2</default_value></Coordinate>"
      "<Coordinate name=\"k\"/><Coordinate name=\"u\"/><Coordinate name=\"s\"/>";
  test::TempDir dir;
  const auto d = readOsimModel(dir.write("c.osim", test::modernOsim(test::bodyXml("a"), custom(axes, coords))));
  const auto& j = d.joints[0];
  std::vector<std::string> names;
  for (int c : j.coordinates) names.push_back(d.coordinates[c].name);
  EXPECT_EQ(names, (std::vector<std::string>{"a", "b", "k", "u", "s"}));
  // properties travel with the name when the list is reordered
  EXPECT_EQ(d.coordinates[d.findCoordinate("a")].default_value, 0.2);
  EXPECT_EQ(d.coordinates[d.findCoordinate("a")].motion_type, MotionType::Undefined)
      << "rotation1 had no function in the file, so it set no motion type";
  EXPECT_EQ(d.coordinates[d.findCoordinate("b")].motion_type, MotionType::Translational);
  EXPECT_EQ(d.coordinates[d.findCoordinate("k")].motion_type, MotionType::Rotational);
  // LinearFunction::getSlope() is the first coefficient, so both arguments of a two-argument
  // linear function with leading slope 1 count as pure translations (CustomJoint::constructCoordinates)
  EXPECT_EQ(d.coordinates[d.findCoordinate("u")].motion_type, MotionType::Translational);
  EXPECT_EQ(d.coordinates[d.findCoordinate("s")].motion_type, MotionType::Translational);
  // the default function and the axes' mobility indices
  EXPECT_EQ(j.spatial_transform[0].function.kind, FunctionKind::Linear);
  EXPECT_EQ(j.spatial_transform[0].function.coefficients, (std::vector<double>{1, 0}));
  EXPECT_EQ(j.spatial_transform[5].mobilities, (std::vector<int>{3, 4}));
  EXPECT_EQ(j.spatial_transform[1].mobilities, (std::vector<int>{1}));
  EXPECT_EQ(j.spatial_transform[3].function.kind, FunctionKind::SimmSpline);
}

}  // namespace
}  // namespace redmax::osim
