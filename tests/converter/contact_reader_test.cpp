// Contact geometry and contact forces read from .osim and built as core terms
// (converter/osim_forces.cpp, converter/build/force_terms.hpp, docs/contact.md): OpenSim's
// property names and defaults, geometry poses in their bodies, unsupported geometry and forces
// listed with their reason, bad values refused at their line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "converter/build/force_terms.hpp"
#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

std::string scenePath(const std::string& f) { return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + f; }

std::string ballModel(const std::string& geometry, const std::string& forces) {
  const std::string joints =
      "<SliderJoint name=\"drop\"><socket_parent_frame>/ground</socket_parent_frame>"
      "<socket_child_frame>/bodyset/ball</socket_child_frame><coordinates><Coordinate name=\"y\"/></coordinates>"
      "</SliderJoint>\n";
  return test::modernOsim(test::bodyXml("ball"), joints,
                          "<ContactGeometrySet><objects>\n" + geometry + "</objects></ContactGeometrySet>\n"
                          "<ForceSet><objects>\n" + forces + "</objects></ForceSet>\n");
}

const std::string kFloor =
    "<ContactHalfSpace name=\"floor\"><socket_frame>/ground</socket_frame><location>0 0.1 0</location>"
    "<orientation>0 0 -1.5707963267948966</orientation></ContactHalfSpace>\n";
const std::string kBall =
    "<ContactSphere name=\"ball_s\"><socket_frame>/bodyset/ball</socket_frame><location>0.01 0.02 0.03</location>"
    "<radius>0.2</radius></ContactSphere>\n";

int errorLine(const std::string& text) {
  test::TempDir dir;
  try {
    readOsimModel(dir.write("m.osim", text));
  } catch (const ConvertError& e) {
    return e.line();
  }
  return -1;
}

TEST(ContactReader, BallDropSceneIsReadAndBuilt) {
  const ModelDescription d = readOsimModel(scenePath("ball_drop.osim"));
  EXPECT_TRUE(d.unsupported.empty());
  ASSERT_EQ(d.contact_geometry.size(), 2u);
  const ContactGeometryDesc& floor = d.contact_geometry[0];
  EXPECT_EQ(floor.class_name, "ContactHalfSpace");
  EXPECT_EQ(floor.body, "ground");
  // rotated -90 deg about z: the frame's x axis (the half-space's inward normal) points down
  EXPECT_LE((floor.X_body.block<3, 1>(0, 0) - Vec3(0, -1, 0)).norm(), 1e-15);
  EXPECT_EQ(d.contact_geometry[1].class_name, "ContactSphere");
  EXPECT_DOUBLE_EQ(d.contact_geometry[1].radius, 0.1);
  ASSERT_EQ(d.forces.size(), 1u);
  const ForceDesc& f = d.forces[0];
  EXPECT_TRUE(f.modelled);
  ASSERT_EQ(f.contact_parameters.size(), 1u);
  EXPECT_EQ(f.contact_parameters[0].geometry, (std::vector<std::string>{"floor", "ball_surface"}));
  EXPECT_DOUBLE_EQ(f.contact_parameters[0].stiffness, 1e7);
  EXPECT_DOUBLE_EQ(f.contact_parameters[0].dissipation, 0.5);
  EXPECT_DOUBLE_EQ(f.contact_parameters[0].static_friction, 0.8);
  EXPECT_DOUBLE_EQ(f.contact_parameters[0].dynamic_friction, 0.5);
  EXPECT_DOUBLE_EQ(f.transition_velocity, 0.01);
  const BuildResult b = buildCoreModel(d);
  std::vector<std::string> warnings;
  const ForceTermSet t = buildForceTerms(d, b, warnings);
  EXPECT_TRUE(warnings.empty());
  ASSERT_TRUE(t.hunt_crossley);
  ASSERT_EQ(t.hunt_crossley->forces().size(), 1u);
  EXPECT_EQ(t.hunt_crossley->forces()[0].surfaces.size(), 2u);
  EXPECT_EQ(t.hunt_crossley->forces()[0].surfaces[0].body, -1);
  EXPECT_EQ(t.passiveTerms().size(), 1u);
}

TEST(ContactReader, SmoothSpheresWithOpenSimsDefaults) {
  test::TempDir dir;
  const ModelDescription d = readOsimModel(dir.write(
      "m.osim", ballModel(kFloor + kBall, "<SmoothSphereHalfSpaceForce name=\"s\"><socket_sphere>/contactgeometryset/ball_s"
                                          "</socket_sphere><socket_half_space>/contactgeometryset/floor</socket_half_space>"
                                          "</SmoothSphereHalfSpaceForce>\n")));
  ASSERT_EQ(d.forces.size(), 1u);
  const ForceDesc& f = d.forces[0];
  EXPECT_EQ(f.sphere, "ball_s");
  EXPECT_EQ(f.half_space, "floor");
  // OpenSim's defaults: stiffness 1, dissipation and friction 0, vt 0.01, cf 1e-5, bd 300, bv 50
  ASSERT_EQ(f.contact_parameters.size(), 1u);
  EXPECT_DOUBLE_EQ(f.contact_parameters[0].stiffness, 1.0);
  EXPECT_DOUBLE_EQ(f.contact_parameters[0].dissipation, 0.0);
  EXPECT_DOUBLE_EQ(f.transition_velocity, 0.01);
  EXPECT_DOUBLE_EQ(f.constant_contact_force, 1e-5);
  EXPECT_DOUBLE_EQ(f.hertz_smoothing, 300.0);
  EXPECT_DOUBLE_EQ(f.hunt_crossley_smoothing, 50.0);
  // the sphere's location in its body, the plane's offset in ground
  EXPECT_LE((d.contact_geometry[1].X_body.topRightCorner<3, 1>() - Vec3(0.01, 0.02, 0.03)).norm(), 1e-15);
  EXPECT_LE((d.contact_geometry[0].X_body.topRightCorner<3, 1>() - Vec3(0, 0.1, 0)).norm(), 1e-15);
  const BuildResult b = buildCoreModel(d);
  std::vector<std::string> warnings;
  const ForceTermSet t = buildForceTerms(d, b, warnings);
  ASSERT_TRUE(t.smooth_contacts);
  EXPECT_EQ(t.smooth_contacts->contactList()[0].sphere.body, 0);
  EXPECT_EQ(t.smooth_contacts->contactList()[0].half_space.body, -1);
}

TEST(ContactReader, WalkerSceneHasFourSmoothContacts) {
  const ModelDescription d = readOsimModel(scenePath("walker2d.osim"));
  EXPECT_TRUE(d.unsupported.empty());
  EXPECT_EQ(d.contact_geometry.size(), 5u);
  int smooth = 0;
  for (const ForceDesc& f : d.forces) smooth += f.class_name == "SmoothSphereHalfSpaceForce" && f.modelled;
  EXPECT_EQ(smooth, 4);
}

TEST(ContactReader, MeshesAndElasticFoundationAreListedWithTheirReason) {
  test::TempDir dir;
  const ModelDescription d = readOsimModel(dir.write(
      "m.osim", ballModel(kFloor + "<ContactMesh name=\"m\"><socket_frame>/bodyset/ball</socket_frame>"
                                   "<filename>ball.obj</filename></ContactMesh>\n",
                          "<ElasticFoundationForce name=\"ef\" />\n")));
  ASSERT_EQ(d.unsupported.size(), 2u);
  EXPECT_NE(d.unsupported[0].what.find("ContactMesh 'm'"), std::string::npos) << d.unsupported[0].what;
  EXPECT_NE(d.unsupported[1].what.find("ElasticFoundationForce) is listed but its force is not modelled: triangle-mesh"),
            std::string::npos)
      << d.unsupported[1].what;
  EXPECT_FALSE(d.contact_geometry[1].modelled);
}

TEST(ContactReader, BadValuesAreRefusedAtTheirLine) {
  const std::string hc_head = "<HuntCrossleyForce name=\"hc\"><HuntCrossleyForce::ContactParametersSet><objects>\n"
                              "<HuntCrossleyForce::ContactParameters>\n";
  const std::string hc_tail = "</HuntCrossleyForce::ContactParameters>\n</objects></HuntCrossleyForce::ContactParametersSet>"
                              "</HuntCrossleyForce>\n";
  // the line of the offending element: count the model's lines up to it
  auto lineOf = [](const std::string& text, const std::string& needle) {
    const auto at = text.find(needle);
    return at == std::string::npos ? -2 : 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  };
  {  // an unknown geometry name
    const std::string t = ballModel(kFloor + kBall, hc_head + "<geometry>floor nope</geometry>\n<stiffness>1e6</stiffness>\n" + hc_tail);
    EXPECT_EQ(errorLine(t), lineOf(t, "<geometry>"));
  }
  {  // zero stiffness (Simbody's s1 = 0/0)
    const std::string t = ballModel(kFloor + kBall, hc_head + "<geometry>floor ball_s</geometry>\n<stiffness>0</stiffness>\n" + hc_tail);
    EXPECT_EQ(errorLine(t), lineOf(t, "<stiffness>"));
  }
  {  // negative dissipation
    const std::string t = ballModel(kFloor + kBall, hc_head + "<geometry>floor ball_s</geometry>\n<stiffness>1e6</stiffness>\n"
                                                              "<dissipation>-1</dissipation>\n" + hc_tail);
    EXPECT_EQ(errorLine(t), lineOf(t, "<dissipation>"));
  }
  {  // a smooth force whose sphere socket names the half-space
    const std::string t = ballModel(kFloor + kBall, "<SmoothSphereHalfSpaceForce name=\"s\">\n"
                                                    "<socket_sphere>/contactgeometryset/floor</socket_sphere>\n"
                                                    "<socket_half_space>floor</socket_half_space></SmoothSphereHalfSpaceForce>\n");
    EXPECT_EQ(errorLine(t), lineOf(t, "<socket_sphere>"));
  }
  {  // a sphere without a positive radius
    const std::string t = ballModel(kFloor + "<ContactSphere name=\"b\"><socket_frame>/bodyset/ball</socket_frame>\n"
                                             "<radius>-1</radius></ContactSphere>\n", "");
    EXPECT_EQ(errorLine(t), lineOf(t, "<radius>"));
  }
  {  // a geometry on a frame the model lacks
    const std::string t = ballModel("<ContactSphere name=\"b\">\n<socket_frame>/bodyset/nope</socket_frame>"
                                    "<radius>1</radius></ContactSphere>\n", "");
    EXPECT_EQ(errorLine(t), lineOf(t, "<socket_frame>"));
  }
}

}  // namespace
}  // namespace redmax::osim
