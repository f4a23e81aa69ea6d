// Converted OpenSim models in the core (converter/build/build_core_model.hpp):
//  - every model of docs/shared_data.md's table builds (exact, Simbody-compatible, with
//    couplers eliminated), with the description's coordinates in the same order;
//  - body poses at the default and at random configurations within the coordinate ranges equal
//    an independent composition X_G,child = X_G,parent X_PF X_FM(q) X_BM^-1 through the tree
//    written here from docs/opensim_compatibility.md §3.2-3.3 (reversed joints inverted), to 1e-12;
//  - J_mr against differences of the body poses and Jdot_mr against differences of J_mr along
//    qdot (central, h = 1e-6, relative 1e-6 in nearRel's sense) at random configurations;
//  - synthetic models with every joint type, offset frames, reversed joints and a loop.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <iostream>
#include <map>
#include <numbers>
#include <random>

#include "converter/build/build_core_model.hpp"
#include "converter/build/functions_to_core.hpp"
#include "converter/osim_reader.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

using test::sharedOpenSim;
constexpr double kPi = std::numbers::pi;
constexpr double kH = 1e-6;
constexpr double kFdTol = 1e-6;

// the models table of docs/shared_data.md, and the models of the published inverse-dynamics sets
const std::vector<std::string>& sharedModels() {
  static const std::vector<std::string> m = {
      "opensim-models/Models/Arm26/arm26.osim",
      "opensim-models/Models/DoublePendulum/double_pendulum.osim",
      "opensim-models/Models/Pendulum/double_pendulum.osim",
      "opensim-core/OpenSim/Tools/Test/double_pendulum33.osim",
      "opensim-models/Models/Tug_of_War/Tug_of_War.osim",
      "opensim-models/Models/Tug_of_War/Tug_of_War_Millard.osim",
      "opensim-models/Models/Leg6Dof9Musc/leg6dof9musc.osim",
      "opensim-models/Models/Leg39/leg39.osim",
      "opensim-models/Models/Gait10dof18musc/gait10dof18musc.osim",
      "opensim-models/Models/Gait2354_Simbody/gait2354_simbody.osim",
      "opensim-models/Models/Gait2392_Simbody/gait2392_thelen2003muscle.osim",
      "opensim-models/Models/Gait2392_Simbody/gait2392_millard2012muscle.osim",
      "opensim-models/Models/Hamner/FullBodyModel_Hamner2010_v2_0.osim",
      "opensim-models/Models/Rajagopal/Rajagopal2016.osim",
      "opensim-models/Models/Rajagopal/RajagopalLaiUhlrich2023.osim",
      "opensim-models/Models/WristModel/wrist.osim",
      "opensim-core/OpenSim/Tests/shared/ThoracoscapularShoulderModel.osim",
      "opensim-core/OpenSim/Tests/Wrapping/"
      "testGeometryPathWrapping_ShoulderWrappingWithPathSprings.osim",
      "opensim-core/OpenSim/Tools/Test/test_wrapAllVis.osim",
      "opensim-core/OpenSim/Tests/Wrapping/testWrapObject_updateFromXMLNode30515.osim",
      "opensim-core/OpenSim/Moco/Test/subject_walk_armless_18musc.osim",
      "opensim-core/OpenSim/Moco/Test/walk_gait1018_subject01.osim",
      "opensim-core/OpenSim/Simulation/Test/P2PBallJointMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/P2PBallCustomJointMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/P2PCustomJointMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/MovingPathPointMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/MovingPointCustomJointMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/WrapPathCustomJointMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/PathOnConstrainedBodyMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/MultipleMPPsMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/CoupledCoordinatesMPPsMomentArmTest.osim",
      "opensim-core/OpenSim/Simulation/Test/testMomentArmsConstraintB.osim",
      "opensim-models@a26e12c/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim",
      "opensim-models@a26e12c/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim",
      "opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim",
      "opensim-models/Pipelines/Gait2392_Simbody/OutputReference/subject01_simbody.osim",
      "opensim-models/Pipelines/Gait10dof18musc/OutputReference/subject01.osim",
      "opensim-models/Tutorials/Computed_Muscle_Control/OutputReference/arm26.osim",
  };
  return m;
}

Mat4 pose(const Mat3& R, const Vec3& p = Vec3::Zero()) { return makeE(R, p); }
Mat3 rot(const Vec3& axis, double a) { return Eigen::AngleAxisd(a, axis.normalized()).toRotationMatrix(); }
Mat3 bodyXYZ(double a, double b, double c) {
  return rot(Vec3::UnitX(), a) * rot(Vec3::UnitY(), b) * rot(Vec3::UnitZ(), c);
}

// X_FM(q) of a description joint, written from the semantics table (q: description indices)
Mat4 referenceXFM(const ModelDescription& d, const JointDesc& j, const VecX& q) {
  auto c = [&](int k) { return q[j.coordinates[k]]; };
  switch (j.kind) {
    case JointKind::Weld: return Mat4::Identity();
    case JointKind::Pin: return pose(rot(Vec3::UnitZ(), c(0)));
    case JointKind::Slider: return makeTranslation(Vec3(c(0), 0, 0));
    case JointKind::Universal: return pose(rot(Vec3::UnitX(), c(0)) * rot(Vec3::UnitY(), c(1)));
    case JointKind::Ball:
    case JointKind::Gimbal: return pose(bodyXYZ(c(0), c(1), c(2)));
    case JointKind::Free: return pose(bodyXYZ(c(0), c(1), c(2)), Vec3(c(3), c(4), c(5)));
    case JointKind::Planar: return pose(rot(Vec3::UnitZ(), c(0)), Vec3(c(1), c(2), 0));
    case JointKind::Ellipsoid: {
      const Mat3 R = bodyXYZ(c(0), c(1), c(2));
      return pose(R, j.radii.cwiseProduct(Vec3(R.col(2))));
    }
    case JointKind::Scapulothoracic: {
      const Mat3 C = rot(Vec3::UnitZ(), kPi / 2);
      const Mat3 R = bodyXYZ(c(0), c(1), c(2));
      const Vec3 radii(j.radii.y(), j.radii.x(), j.radii.z());
      const Vec3 dir(-std::sin(j.winging_direction), std::cos(j.winging_direction), 0);
      const Mat4 W = pose(Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), dir).toRotationMatrix(),
                          Vec3(j.winging_origin.x(), j.winging_origin.y(), 0));
      return pose(C) * pose(R, radii.cwiseProduct(Vec3(R.col(2)))) * pose(C.transpose()) * W *
             pose(rot(Vec3::UnitZ(), c(3))) * inverseE(W);
    }
    case JointKind::Custom: {
      // R = R(th1, a1) R(th2, a2) R(th3, a3) body-fixed; p = sum d_k t_k in F
      Mat3 R = Mat3::Identity();
      Vec3 p = Vec3::Zero();
      for (int k = 0; k < 6; ++k) {
        const TransformAxisDesc& ax = j.spatial_transform[k];
        VecJ x(static_cast<int>(ax.mobilities.size()));
        for (size_t i = 0; i < ax.mobilities.size(); ++i) x[i] = c(ax.mobilities[i]);
        const double v =
            makeCoreFunction(ax.function, static_cast<int>(x.size()), d.source_file, j.name)->value(x);
        if (k < 3) R = R * rot(ax.axis, v);
        else p += v * ax.axis.normalized();
      }
      return pose(R, p);
    }
    case JointKind::Unsupported: break;
  }
  ADD_FAILURE() << "no reference X_FM for " << j.type;
  return Mat4::Identity();
}

// body poses in ground by composing through the description's tree (slaves left out)
std::map<std::string, Mat4> referencePoses(const ModelDescription& d, const VecX& q) {
  std::map<std::string, Mat4> X;
  X[d.ground_name] = Mat4::Identity();
  std::map<std::string, bool> slave;
  for (const auto& s : d.tree.slaves) slave[s.name] = true;
  for (const MobilizerDesc& m : d.tree.mobilizers) {
    if (slave.count(m.outboard_body)) continue;
    const JointDesc& j = d.joints[m.joint];
    const Mat4 XFM = referenceXFM(d, j, q);
    // reversed: the joint's parent body is outboard, X_GP = X_GB X_BM X_FM^-1 X_PF^-1
    X[m.outboard_body] = m.reversed
                             ? X.at(m.inboard_body) * j.X_BM * inverseE(XFM) * inverseE(j.X_PF)
                             : X.at(m.inboard_body) * j.X_PF * XFM * inverseE(j.X_BM);
  }
  return X;
}

VecX defaultQ(const ModelDescription& d) {
  VecX q(d.numDofs());
  for (int k = 0; k < d.numDofs(); ++k) q[k] = d.coordinates[k].default_value;
  return q;
}

// uniform within each coordinate's range (wide default ranges limited to +-pi)
VecX randomQ(const ModelDescription& d, std::mt19937& rng) {
  VecX q(d.numDofs());
  for (int k = 0; k < d.numDofs(); ++k) {
    const double lo = std::max(d.coordinates[k].range_min, -kPi);
    const double hi = std::min(d.coordinates[k].range_max, kPi);
    q[k] = hi > lo ? std::uniform_real_distribution<double>(lo, hi)(rng) : lo;
  }
  return q;
}

void expectPosesMatchReference(const ModelDescription& d, const BuildResult& r, const VecX& q,
                               const std::string& what) {
  std::vector<Mat4> E;
  calcBodyPoses(r.model, q, E);
  const auto ref = referencePoses(d, q);
  for (size_t b = 0; b < d.bodies.size(); ++b) {
    const int i = r.body_index[b];
    ASSERT_GE(i, 0) << d.bodies[b].name;
    EXPECT_TRUE(nearRel(E[i], ref.at(d.bodies[b].name), 1e-12))
        << what << " body " << d.bodies[b].name << "\ncore:\n" << E[i] << "\nreference:\n"
        << ref.at(d.bodies[b].name);
  }
}

// J_mr vs pose differences; Jdot_mr vs J_mr differences along qdot
void expectJacobiansMatchDifferences(const Model& model, const VecX& q, const VecX& qdot,
                                     const std::string& what) {
  SkeletonWorkspace ws(model);
  State s{0.0, q, qdot};
  calcKinematics(model, s, ws);
  const MatX J = ws.J_mr, Jdot = ws.Jdot_mr;
  std::vector<Mat4> E, Ep, Em;
  calcBodyPoses(model, q, E);
  for (int k = 0; k < model.nr(); ++k) {
    VecX qp = q, qm = q;
    qp[k] += kH;
    qm[k] -= kH;
    calcBodyPoses(model, qp, Ep);
    calcBodyPoses(model, qm, Em);
    for (int i = 0; i < model.nb(); ++i) {
      const Mat4 fd = inverseE(E[i]) * (Ep[i] - Em[i]) / (2 * kH);
      const Vec6 col = J.block<6, 1>(6 * i, k);
      EXPECT_TRUE(nearRel(bracket6(col), fd, kFdTol))
          << what << " body " << model.bodies()[i].name << " coordinate "
          << model.coordinates()[k].name << "\nJ  = " << col.transpose()
          << "\nfd = " << unbracket6(fd).transpose();
    }
  }
  SkeletonWorkspace wp(model), wm(model);
  calcKinematics(model, State{0.0, q + kH * qdot, qdot}, wp);
  calcKinematics(model, State{0.0, q - kH * qdot, qdot}, wm);
  const MatX fd = (wp.J_mr - wm.J_mr) / (2 * kH);
  EXPECT_TRUE(nearRel(Jdot, fd, kFdTol)) << what << ": |Jdot - fd| = " << (Jdot - fd).norm()
                                         << ", |fd| = " << fd.norm();
}

class BuildSharedModels : public ::testing::TestWithParam<std::string> {};

TEST_P(BuildSharedModels, BuildsWithTheDescriptionsCoordinatesAndPoses) {
  REDMAX_REQUIRE_SHARED();
  const ModelDescription d = readOsimModel(sharedOpenSim(GetParam()));
  const BuildResult r = buildCoreModel(d);
  const Model& m = r.model;
  ASSERT_EQ(m.nr(), d.numDofs());
  for (int k = 0; k < d.numDofs(); ++k) {
    EXPECT_EQ(m.coordinates()[k].name, d.coordinates[k].name);
    EXPECT_EQ(r.coordinate_index[k], k);
    EXPECT_EQ(m.coordinates()[k].default_value, d.coordinates[k].default_value);
  }
  EXPECT_EQ(m.nb(), static_cast<int>(d.bodies.size() + d.tree.slaves.size()));
  // total mass is kept (slaves share their master's)
  double mass_d = 0, mass_c = 0;
  for (const auto& b : d.bodies) mass_d += b.mass;
  for (const auto& b : m.bodies()) mass_c += b.mass;
  EXPECT_NEAR(mass_c, mass_d, 1e-12 * (1 + mass_d));
  // parents precede children
  for (int i = 0; i < m.nb(); ++i) EXPECT_LT(m.joints()[i].parent, i);
  // every path force becomes a muscle
  EXPECT_EQ(r.model.muscles().size(), d.muscles.size());
  for (const auto& u : r.unsupported) ADD_FAILURE() << GetParam() << ": " << u.what;

  expectPosesMatchReference(d, r, defaultQ(d), "default q");
  std::mt19937 rng(17);
  for (int t = 0; t < 3; ++t) expectPosesMatchReference(d, r, randomQ(d, rng), "random q");
  for (int t = 0; t < 2; ++t) {
    VecX qdot(d.numDofs());
    for (int k = 0; k < qdot.size(); ++k) qdot[k] = std::uniform_real_distribution<double>(-1, 1)(rng);
    expectJacobiansMatchDifferences(m, randomQ(d, rng), qdot, GetParam());
  }

  // the other build options build the same skeleton
  BuildOptions compat;
  compat.simbody_compat = true;
  compat.couplers = CouplerHandling::Eliminate;
  const BuildResult rc = buildCoreModel(d, compat);
  EXPECT_EQ(rc.model.nr(), m.nr());
  const VecX q = randomQ(d, rng);
  std::vector<Mat4> E1, E2;
  calcBodyPoses(m, q, E1);
  calcBodyPoses(rc.model, q, E2);
  for (int i = 0; i < m.nb(); ++i) EXPECT_TRUE(nearRel(E1[i], E2[i], 1e-14));
  BuildOptions none;
  none.constraints = false;
  none.muscles = false;
  const BuildResult rn = buildCoreModel(d, none);
  EXPECT_TRUE(rn.model.constraints().empty());
  EXPECT_TRUE(rn.model.muscles().empty());
  EXPECT_EQ(rn.model.coordinateMap(), nullptr);
}

INSTANTIATE_TEST_SUITE_P(Readme, BuildSharedModels, ::testing::ValuesIn(sharedModels()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string n = info.param;
                           n = n.substr(n.rfind('/') + 1);
                           n = n.substr(0, n.find('.'));
                           std::string out;
                           for (char ch : n) out += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
                           return out + "_" + std::to_string(info.index);
                         });

// ---------------------------------------------------------------------------------------------
// synthetic models: every joint type, offset frames with rotations, reversed joints

std::string frameXml(const std::string& name, const std::string& parent, const Vec3& t,
                     const Vec3& o) {
  auto v = [](const Vec3& x) {
    return std::to_string(x[0]) + " " + std::to_string(x[1]) + " " + std::to_string(x[2]);
  };
  return "<PhysicalOffsetFrame name=\"" + name + "\"><socket_parent>" + parent +
         "</socket_parent><translation>" + v(t) + "</translation><orientation>" + v(o) +
         "</orientation></PhysicalOffsetFrame>\n";
}

std::string coordXml(const std::string& name, double def) {
  return "<Coordinate name=\"" + name + "\"><default_value>" + std::to_string(def) +
         "</default_value><range>-1.5 1.5</range></Coordinate>\n";
}

// a joint between two bodies through offset frames on both; coords: names with defaults
std::string jointXml(const std::string& type, const std::string& name, const std::string& parent,
                     const std::string& child, const std::vector<std::pair<std::string, double>>& coords,
                     const std::string& extra = "") {
  std::string x = "<" + type + " name=\"" + name + "\">\n<socket_parent_frame>" + name +
                  "_p</socket_parent_frame>\n<socket_child_frame>" + name +
                  "_c</socket_child_frame>\n<coordinates>\n";
  for (const auto& [n, v] : coords) x += coordXml(n, v);
  x += "</coordinates>\n" + extra + "<frames>\n" +
       frameXml(name + "_p", parent, Vec3(0.1, -0.2, 0.05), Vec3(0.3, -0.1, 0.2)) +
       frameXml(name + "_c", child, Vec3(-0.05, 0.15, 0.02), Vec3(-0.2, 0.4, 0.1)) +
       "</frames>\n</" + type + ">\n";
  return x;
}

std::string bodyXml(const std::string& name, double mass = 1.5) {
  return "<Body name=\"" + name + "\"><mass>" + std::to_string(mass) +
         "</mass><mass_center>0.01 -0.1 0.02</mass_center><inertia>0.1 0.12 0.08 0.01 -0.005 "
         "0.002</inertia></Body>\n";
}

std::string customXml(const std::string& name, const std::string& parent, const std::string& child) {
  // a coupled CustomJoint: two coordinates, one driving two rotations through a spline
  const std::string st =
      "<SpatialTransform>\n"
      "<TransformAxis name=\"rotation1\"><coordinates>ca</coordinates><axis>0 0 1</axis>"
      "<LinearFunction name=\"function\"><coefficients>1 0</coefficients></LinearFunction></TransformAxis>\n"
      "<TransformAxis name=\"rotation2\"><coordinates>ca</coordinates><axis>1 0.2 0</axis>"
      "<SimmSpline name=\"function\"><x>-2 -1 0 1 2</x><y>-0.3 -0.1 0 0.2 0.5</y></SimmSpline></TransformAxis>\n"
      "<TransformAxis name=\"rotation3\"><coordinates>cb</coordinates><axis>0 1 0</axis>"
      "<LinearFunction name=\"function\"><coefficients>-1 0.1</coefficients></LinearFunction></TransformAxis>\n"
      "<TransformAxis name=\"translation1\"><coordinates>ca</coordinates><axis>1 0 0</axis>"
      "<PolynomialFunction name=\"function\"><coefficients>0.02 -0.01 0.03</coefficients></PolynomialFunction></TransformAxis>\n"
      "<TransformAxis name=\"translation2\"><coordinates></coordinates><axis>0 1 0</axis>"
      "<Constant name=\"function\"><value>0.05</value></Constant></TransformAxis>\n"
      "<TransformAxis name=\"translation3\"><coordinates>cb ca</coordinates><axis>0 0 1</axis>"
      "<LinearFunction name=\"function\"><coefficients>0.1 -0.2 0.01</coefficients></LinearFunction></TransformAxis>\n"
      "</SpatialTransform>\n";
  return jointXml("CustomJoint", name, parent, child, {{"cb", 0.2}, {"ca", -0.3}}, st);
}

ModelDescription readText(const std::string& text) {
  test::TempDir dir;
  return readOsimModel(dir.write("m.osim", text));
}

TEST(BuildSynthetic, EveryJointTypeWithOffsetFramesAndReversedJoints) {
  const std::string bodies = bodyXml("a") + bodyXml("b") + bodyXml("c") + bodyXml("d") +
                             bodyXml("e") + bodyXml("f") + bodyXml("g") + bodyXml("h") +
                             bodyXml("i") + bodyXml("k") + bodyXml("l");
  std::string joints =
      // reversed free joint: ground is its child
      jointXml("FreeJoint", "free", "/bodyset/a", "/ground",
               {{"f0", 0.1}, {"f1", -0.2}, {"f2", 0.3}, {"f3", 0.4}, {"f4", 0.5}, {"f5", -0.6}}) +
      jointXml("BallJoint", "ball", "/bodyset/a", "/bodyset/b", {{"b0", 0.2}, {"b1", 0.3}, {"b2", -0.1}}) +
      jointXml("GimbalJoint", "gimbal", "/bodyset/b", "/bodyset/c", {{"g0", -0.4}, {"g1", 0.2}, {"g2", 0.6}}) +
      jointXml("UniversalJoint", "universal", "/bodyset/c", "/bodyset/d", {{"u0", 0.3}, {"u1", -0.5}}) +
      jointXml("PlanarJoint", "planar", "/bodyset/d", "/bodyset/e", {{"p0", 0.7}, {"p1", 0.1}, {"p2", -0.2}}) +
      jointXml("SliderJoint", "slider", "/bodyset/e", "/bodyset/f", {{"s0", 0.25}}) +
      jointXml("EllipsoidJoint", "ellipsoid", "/bodyset/f", "/bodyset/g",
               {{"e0", 0.1}, {"e1", 0.2}, {"e2", 0.3}}, "<radii_x_y_z>0.1 0.2 0.15</radii_x_y_z>\n") +
      // reversed pin and reversed custom joint further down the tree
      jointXml("PinJoint", "pin_rev", "/bodyset/h", "/bodyset/g", {{"pr", 0.4}}) +
      customXml("custom_rev", "/bodyset/i", "/bodyset/h") +
      jointXml("WeldJoint", "weld", "/bodyset/i", "/bodyset/k", {}) +
      jointXml("ScapulothoracicJoint", "st", "/bodyset/k", "/bodyset/l",
               {{"abd", 0.2}, {"ele", -0.3}, {"uprot", 0.4}, {"wing", 0.1}},
               "<thoracic_ellipsoid_radii_x_y_z>0.07 0.15 0.08</thoracic_ellipsoid_radii_x_y_z>\n"
               "<scapula_winging_axis_origin>-0.05 0.01</scapula_winging_axis_origin>\n"
               "<scapula_winging_axis_direction>0.6</scapula_winging_axis_direction>\n");
  const ModelDescription d = readText(test::modernOsim(bodies, joints));
  int reversed = 0;
  for (const auto& m : d.tree.mobilizers) reversed += m.reversed;
  ASSERT_EQ(reversed, 3) << "the model should exercise reversed free, pin and custom joints";
  const BuildResult r = buildCoreModel(d);
  ASSERT_EQ(r.model.nr(), d.numDofs());
  for (int k = 0; k < d.numDofs(); ++k) EXPECT_EQ(r.model.skeleton().coordinates()[k].name, d.coordinates[k].name);
  expectPosesMatchReference(d, r, defaultQ(d), "default q");
  std::mt19937 rng(23);
  for (int t = 0; t < 5; ++t) expectPosesMatchReference(d, r, randomQ(d, rng), "random q");
  for (int t = 0; t < 3; ++t) {
    VecX qdot(d.numDofs());
    for (int k = 0; k < qdot.size(); ++k) qdot[k] = std::uniform_real_distribution<double>(-1, 1)(rng);
    expectJacobiansMatchDifferences(r.model, randomQ(d, rng), qdot, "synthetic");
  }
  // mass properties are taken as given: products of inertia are matrix entries
  const Body& b = r.model.skeleton().bodies()[r.body_index[d.findBody("b")]];
  EXPECT_EQ(b.mass, 1.5);
  EXPECT_TRUE(nearRel(b.com, Vec3(0.01, -0.1, 0.02), 0.0));
  Mat3 I;
  I << 0.1, 0.01, -0.005, 0.01, 0.12, 0.002, -0.005, 0.002, 0.08;
  EXPECT_TRUE(nearRel(b.inertia_com, I, 0.0));
}

TEST(BuildSynthetic, LoopIsCutBySlaveBodyWithHalfTheMassAndAWeld) {
  // a triangle ground -pin- a -pin- b -pin- ground (rigid: the loop closes at isolated q, one of
  // them q = 0 with the pivots at (0,0), (1,0), (1,1)); the joint a-b closes the loop, b is split
  auto pin = [&](const std::string& name, const std::string& pf, const std::string& pb, const Vec3& px,
                 const std::string& cf, const std::string& cb, const Vec3& cx) {
    return "<PinJoint name=\"" + name + "\"><socket_parent_frame>" + pf +
           "</socket_parent_frame><socket_child_frame>" + cf + "</socket_child_frame><coordinates>" +
           coordXml(name + "_q", 0.0) + "</coordinates><frames>" + frameXml(pf, pb, px, Vec3::Zero()) +
           frameXml(cf, cb, cx, Vec3::Zero()) + "</frames></PinJoint>\n";
  };
  const std::string joints =
      pin("j1", "g1", "/ground", Vec3::Zero(), "a1", "/bodyset/a", Vec3::Zero()) +
      pin("j3", "g3", "/ground", Vec3(1, 1, 0), "b3", "/bodyset/b", Vec3(0, 1, 0)) +
      pin("j2", "a2", "/bodyset/a", Vec3(1, 0, 0), "b2", "/bodyset/b", Vec3::Zero());
  const ModelDescription d = readText(test::modernOsim(bodyXml("a", 1.0) + bodyXml("b", 3.0), joints));
  ASSERT_EQ(d.tree.slaves.size(), 1u);
  const BuildResult r = buildCoreModel(d);
  ASSERT_EQ(r.model.nb(), 3);
  const int master = r.body_index[d.findBody("b")];
  const int slave = r.model.skeleton().findBody(d.tree.slaves[0].name);
  ASSERT_GE(slave, 0);
  EXPECT_EQ(r.model.skeleton().bodies()[master].mass, 1.5);
  EXPECT_EQ(r.model.skeleton().bodies()[slave].mass, 1.5);
  EXPECT_TRUE(nearRel(r.model.skeleton().bodies()[slave].inertia_com, 0.5 * d.bodies[1].inertiaMatrix(), 1e-15));
  // one weld (master-slave); satisfied where the loop closes, violated elsewhere
  ASSERT_EQ(r.model.constraints().size(), 1u);
  System sys = r.makeSystem();
  DynamicsWorkspace ws(sys.model());
  State s = sys.defaultState();
  sys.calcMassAndForce(s, ws);
  sys.calcConstraints(s, ws);
  EXPECT_LT(ws.pos_err.cwiseAbs().maxCoeff(), 1e-14);
  s.q[0] = 0.2;
  sys.calcMassAndForce(s, ws);
  sys.calcConstraints(s, ws);
  EXPECT_GT(ws.pos_err.cwiseAbs().maxCoeff(), 0.1);
  // and the projection brings the four-bar back onto its loop
  EXPECT_LT(sys.projectPositions(s, ws, 1e-12, 30), 1e-10);
}

}  // namespace
}  // namespace redmax::osim

namespace redmax::osim {
namespace {

// The OpenSim-compatibility switch (docs/design.md §2) on CustomJoints: poses are the same; Simbody's
// velocity-product terms are exact for pelvis/hip-like joints (gait2392: identical Jdot_mr, so
// identical inverse dynamics) and differ where one coordinate drives several rotations
// (Rajagopal's knees): the difference is measured and must be nonzero there.
double idDifference(const ModelDescription& d, const std::string& what, double* jdot_diff) {
  BuildOptions exact_opt, compat_opt;
  exact_opt.constraints = compat_opt.constraints = false;
  compat_opt.simbody_compat = true;
  const BuildResult exact = buildCoreModel(d, exact_opt), compat = buildCoreModel(d, compat_opt);
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-2, 2);
  double max_tau = 0.0;
  *jdot_diff = 0.0;
  for (int t = 0; t < 5; ++t) {
    State s{0.0, randomQ(d, rng), VecX(d.numDofs())};
    VecX qddot(d.numDofs());
    for (int k = 0; k < d.numDofs(); ++k) s.qdot[k] = u(rng), qddot[k] = u(rng);
    SkeletonWorkspace we(exact.model), wc(compat.model);
    calcKinematics(exact.model, s, we);
    calcKinematics(compat.model, s, wc);
    EXPECT_TRUE(nearRel(we.J_mr, wc.J_mr, 1e-13)) << what;
    *jdot_diff = std::max(*jdot_diff, (we.Jdot_mr - wc.Jdot_mr).cwiseAbs().maxCoeff());
    System se(exact.model), sc(compat.model);
    DynamicsWorkspace de(exact.model), dc(compat.model);
    const VecX te = se.inverseDynamics(s, qddot, de), tc = sc.inverseDynamics(s, qddot, dc);
    max_tau = std::max(max_tau, (te - tc).cwiseAbs().maxCoeff());
  }
  return max_tau;
}

TEST(BuildCompat, SimbodyVelocityTermsDifferOnlyForCoupledRotations) {
  REDMAX_REQUIRE_SHARED();
  double jdot = 0.0;
  const double gait = idDifference(
      readOsimModel(sharedOpenSim("opensim-models/Models/Gait2392_Simbody/gait2392_millard2012muscle.osim")),
      "gait2392", &jdot);
  EXPECT_LT(jdot, 1e-12);
  EXPECT_LT(gait, 1e-9);
  const double raj =
      idDifference(readOsimModel(sharedOpenSim("opensim-models/Models/Rajagopal/Rajagopal2016.osim")),
                   "Rajagopal2016", &jdot);
  EXPECT_GT(jdot, 1e-6);
  EXPECT_GT(raj, 1e-6);
  std::cout << "exact vs Simbody-compatible inverse dynamics, max |tau| difference over 5 random "
               "states: gait2392 "
            << gait << ", Rajagopal2016 " << raj << " (max |Jdot_mr| difference " << jdot << ")\n";
}

}  // namespace
}  // namespace redmax::osim

namespace redmax::osim {
namespace {

// the project's own scenes (osim_models/, written by the scenes work) run in the core too
TEST(BuildProjectScenes, EveryOsimModelBuildsWithMatchingPosesAndJacobians) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(REDMAX_SOURCE_DIR) / "osim_models";
  if (!fs::is_directory(dir)) GTEST_SKIP() << "no osim_models folder at " << dir;
  int built = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".osim") continue;
    const std::string name = e.path().filename().string();
    const ModelDescription d = readOsimModel(e.path().string());
    const BuildResult r = buildCoreModel(d);
    ASSERT_EQ(r.model.nr(), d.numDofs()) << name;
    for (const auto& u : r.unsupported) ADD_FAILURE() << name << ": " << u.what;
    EXPECT_EQ(r.model.muscles().size(), d.muscles.size()) << name;
    std::mt19937 rng(41);
    expectPosesMatchReference(d, r, defaultQ(d), name);
    expectPosesMatchReference(d, r, randomQ(d, rng), name);
    VecX qdot = VecX::Ones(d.numDofs());
    expectJacobiansMatchDifferences(r.model, randomQ(d, rng), qdot, name);
    ++built;
  }
  if (built == 0) GTEST_SKIP() << "no .osim files in " << dir;
}

}  // namespace
}  // namespace redmax::osim
