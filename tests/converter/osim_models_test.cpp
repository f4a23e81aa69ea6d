// The project's own scenes (osim_models/): each loads through the converter with nothing left
// unsupported and with the bodies, coordinates, muscles, path types and wrap objects the scene
// promises; the geometry does what its header comment says (flexion signs, moment arms, where a
// wrap engages, tendon slack lengths), checked with forward kinematics of Pin/Weld chains built
// here from the description and with central differences; and running_leg_swing.mot reads with
// the model's coordinate names, in degrees, equal to its closed-form generator.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/types.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

const double kPi = 3.14159265358979323846;

std::string scenePath(const std::string& file) {
  return std::string(REDMAX_SOURCE_DIR) + "/osim_models/" + file;
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const PathForceDesc& muscle(const ModelDescription& d, const std::string& name) {
  for (const auto& m : d.muscles)
    if (m.name == name) return m;
  throw std::runtime_error("no muscle " + name);
}

std::vector<std::string> coordinateNames(const ModelDescription& d) {
  std::vector<std::string> names;
  for (const auto& c : d.coordinates) names.push_back(c.name);
  return names;
}

// ---------------------------------------------------------------------------------------------
// forward kinematics of the Pin/Weld part of a model, written independently of core/: the pose
// of the child is X_parent * X_PF * X_FM(q) * inverse(X_BM), X_FM a rotation about z for a Pin

using Coords = std::map<std::string, double>;

Mat4 rotZ(double q) {
  Mat4 X = Mat4::Identity();
  X(0, 0) = std::cos(q);
  X(0, 1) = -std::sin(q);
  X(1, 0) = std::sin(q);
  X(1, 1) = std::cos(q);
  return X;
}

double coordValue(const ModelDescription& d, int c, const Coords& q) {
  auto it = q.find(d.coordinates[c].name);
  return it != q.end() ? it->second : d.coordinates[c].default_value;
}

/// poses of the bodies reachable from root through Pin and Weld joints, relative to root;
/// coordinates missing from q take their default values
std::map<std::string, Mat4> chainPoses(const ModelDescription& d, const std::string& root,
                                       const Coords& q) {
  std::map<std::string, Mat4> X;
  X[root] = Mat4::Identity();
  for (bool grew = true; grew;) {
    grew = false;
    for (const auto& j : d.joints) {
      if (!X.count(j.parent_body) || X.count(j.child_body)) continue;
      Mat4 X_FM = Mat4::Identity();
      if (j.kind == JointKind::Pin)
        X_FM = rotZ(coordValue(d, j.coordinates.at(0), q));
      else if (j.kind != JointKind::Weld)
        continue;
      X[j.child_body] = X.at(j.parent_body) * j.X_PF * X_FM * j.X_BM.inverse();
      grew = true;
    }
  }
  return X;
}

Vec3 apply(const Mat4& X, const Vec3& p) {
  return X.topLeftCorner<3, 3>() * p + X.topRightCorner<3, 1>();
}

/// path points of a muscle in the root frame
std::vector<Vec3> pathPoints(const ModelDescription& d, const PathForceDesc& m,
                             const std::string& root, const Coords& q) {
  const auto X = chainPoses(d, root, q);
  std::vector<Vec3> p;
  for (const auto& pt : m.points) {
    EXPECT_EQ(pt.kind, PathPointKind::Fixed) << m.name << " " << pt.name;
    p.push_back(apply(X.at(pt.body) * pt.X_body_frame, pt.location));
  }
  return p;
}

/// length of the polyline through the path points (wrap objects ignored)
double polylineLength(const ModelDescription& d, const PathForceDesc& m, const std::string& root,
                      const Coords& q) {
  const auto p = pathPoints(d, m, root, q);
  double L = 0.0;
  for (size_t i = 1; i < p.size(); ++i) L += (p[i] - p[i - 1]).norm();
  return L;
}

/// moment arm -dL/dq by central differences (h = 1e-6; error O(h^2) ~ 1e-12 m)
double momentArm(const ModelDescription& d, const PathForceDesc& m, const std::string& root,
                 const std::string& coord, Coords q = {}) {
  const double h = 1e-6;
  const double q0 =
      q.count(coord) ? q[coord] : d.coordinates[d.findCoordinate(coord)].default_value;
  q[coord] = q0 + h;
  const double Lp = polylineLength(d, m, root, q);
  q[coord] = q0 - h;
  const double Lm = polylineLength(d, m, root, q);
  return -(Lp - Lm) / (2 * h);
}

/// distance from a wrap cylinder's axis to the straight origin-insertion segment, measured in
/// the cylinder's xy plane (the scenes are planar in that plane); below the radius the straight
/// line would cut the cylinder, so the path must wrap
double axisToSegment2d(const ModelDescription& d, const PathForceDesc& m, const std::string& root,
                       const Coords& q) {
  const WrapObjectDesc& w = d.wrap_objects.at(d.findWrapObject(m.wraps.at(0).wrap_object));
  const auto X = chainPoses(d, root, q);
  const Mat4 X_rw = X.at(w.body) * w.X_body;
  const Mat4 X_wr = X_rw.inverse();
  const auto p = pathPoints(d, m, root, q);
  const Vec2 a = apply(X_wr, p.front()).head<2>(), b = apply(X_wr, p.back()).head<2>();
  const double t = std::clamp(-a.dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (a + t * (b - a)).norm();
}

// ---------------------------------------------------------------------------------------------
// every scene

struct SceneCounts {
  const char* file;
  std::vector<std::string> bodies;       // BodySet order
  std::vector<std::string> coordinates;  // multibody-tree order
  int type1, type2, type3, wrap_objects;
};

const std::vector<SceneCounts>& scenes() {
  static const std::vector<SceneCounts> s = {
      {"double_pendulum_via.osim", {"link1", "link2"}, {"q1", "q2"}, 0, 1, 0, 0},
      {"double_pendulum_straight.osim", {"link1", "link2"}, {"q1", "q2"}, 1, 0, 0, 0},
      {"double_pendulum_wrap.osim", {"link1", "link2"}, {"q1", "q2"}, 0, 0, 1, 1},
      {"finger.osim",
       {"metacarpal", "proximal", "middle", "distal"},
       {"mcp_flexion", "pip_flexion", "dip_flexion"},
       0, 2, 0, 0},
      {"running_leg.osim",
       {"pelvis", "femur_r", "tibia_r", "calcn_r"},
       {"pelvis_tilt", "pelvis_list", "pelvis_rotation", "pelvis_tx", "pelvis_ty", "pelvis_tz",
        "hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r"},
       1, 1, 2, 1},
      {"reach_arm.osim",
       {"scapula", "humerus", "forearm", "hand"},
       {"shoulder_flexion", "shoulder_adduction", "shoulder_rotation", "elbow_flexion"},
       0, 0, 6, 2},
  };
  return s;
}

TEST(OsimModels, EverySceneReadsStrictWithTheExpectedCounts) {
  for (const auto& s : scenes()) {
    SCOPED_TRACE(s.file);
    const ModelDescription d = readOsimModel(scenePath(s.file));
    // redmax convert --strict accepts it: nothing read but not modelled
    EXPECT_TRUE(d.unsupported.empty()) << d.unsupported.front().what;
    for (const auto& w : d.warnings) ADD_FAILURE() << "warning: " << w;
    EXPECT_EQ(d.osim_version, 40000);
    EXPECT_LT((d.gravity - Vec3(0, -9.80665, 0)).norm(), 1e-15);
    std::vector<std::string> bodies;
    for (const auto& b : d.bodies) bodies.push_back(b.name);
    EXPECT_EQ(bodies, s.bodies);
    EXPECT_EQ(coordinateNames(d), s.coordinates);
    // no FreeJoint was added: every body is connected by a joint of the file
    for (const auto& j : d.joints) EXPECT_FALSE(j.added) << j.name;
    EXPECT_TRUE(d.constraints.empty());
    int n[3] = {0, 0, 0};
    for (const auto& m : d.muscles) {
      ++n[static_cast<int>(m.path_type)];
      EXPECT_TRUE(m.is_muscle);
      EXPECT_TRUE(m.class_name == "Thelen2003Muscle" ||
                  m.class_name == "Millard2012EquilibriumMuscle")
          << m.name << " " << m.class_name;
      // plausible muscle parameters, all written explicitly (none left at OpenSim's defaults)
      EXPECT_GT(m.max_isometric_force, 10.0) << m.name;
      EXPECT_LT(m.max_isometric_force, 5000.0) << m.name;
      EXPECT_GT(m.optimal_fiber_length, 0.02) << m.name;
      EXPECT_LT(m.optimal_fiber_length, 1.0) << m.name;
      EXPECT_NE(m.tendon_slack_length, 0.2) << m.name << ": tendon slack left at the default";
      EXPECT_GT(m.tendon_slack_length, 0.0) << m.name;
      EXPECT_GE(m.pennation_angle_at_optimal, 0.0) << m.name;
      EXPECT_LT(m.pennation_angle_at_optimal, 0.5) << m.name;
      const std::string xml = readText(scenePath(s.file));
      const size_t begin = xml.find("<" + m.class_name + " name=\"" + m.name + "\"");
      ASSERT_NE(begin, std::string::npos) << m.name;
      const std::string element = xml.substr(begin, xml.find("</" + m.class_name, begin) - begin);
      for (const char* tag : {"<max_isometric_force>", "<optimal_fiber_length>",
                              "<tendon_slack_length>", "<pennation_angle_at_optimal>"})
        EXPECT_NE(element.find(tag), std::string::npos) << m.name << " " << tag;
    }
    EXPECT_EQ(n[0], s.type1);
    EXPECT_EQ(n[1], s.type2);
    EXPECT_EQ(n[2], s.type3);
    EXPECT_EQ(static_cast<int>(d.wrap_objects.size()), s.wrap_objects);
    for (const auto& b : d.bodies) EXPECT_GT(b.mass, 0.0) << b.name;
  }
}

TEST(OsimModels, EverySceneCarriesItsHeaderComment) {
  for (const auto& s : scenes()) {
    SCOPED_TRACE(s.file);
    const std::string xml = readText(scenePath(s.file));
    const size_t comment = xml.find("<!--");
    ASSERT_NE(comment, std::string::npos);
    // the comment comes before the document element and names the scene, its source and use
    EXPECT_LT(comment, xml.find("<OpenSimDocument"));
    const std::string header = xml.substr(comment, xml.find("-->") - comment);
    EXPECT_NE(header.find(s.file), std::string::npos);
    EXPECT_NE(header.find("Authored for redmax"), std::string::npos);
    EXPECT_NE(header.find("section"), std::string::npos);
    EXPECT_NE(header.find("6.2."), std::string::npos);
    EXPECT_NE(header.find("SI units"), std::string::npos);
  }
}

TEST(OsimModels, EverySceneBuildsInTheCoreWithTheSameLengths) {
  // the core model from converter/build has the scene's q order, and its polyline lengths of the
  // Type I/II muscles equal the independent forward kinematics above (1e-12 m) at the default,
  // the zero and 20 random poses within the coordinate ranges (fixed seed)
  std::mt19937 rng(20240611);
  for (const auto& s : scenes()) {
    SCOPED_TRACE(s.file);
    const ModelDescription d = readOsimModel(scenePath(s.file));
    const BuildResult r = buildCoreModel(d);
    EXPECT_TRUE(r.unsupported.empty()) << r.unsupported.front().what;
    ASSERT_EQ(r.model.muscles().size(), d.muscles.size());
    ASSERT_EQ(r.model.skeleton().defaultQ().size(), d.numDofs());
    for (int c = 0; c < d.numDofs(); ++c) EXPECT_EQ(r.coordinate_index[c], c);
    // the leg's Custom pelvis and hip are outside chainPoses; lengths do not depend on the root
    const std::string root = s.file == std::string("running_leg.osim") ? "femur_r" : "ground";
    std::vector<Coords> poses = {{}, {}};
    for (const auto& c : d.coordinates) poses[1][c.name] = 0.0;
    for (int k = 0; k < 20; ++k) {
      Coords q;
      for (const auto& c : d.coordinates)
        q[c.name] = std::uniform_real_distribution<double>(c.range_min, c.range_max)(rng);
      poses.push_back(q);
    }
    std::vector<Mat4> E;
    for (const Coords& pose : poses) {
      VecX q = r.model.skeleton().defaultQ();
      for (int c = 0; c < d.numDofs(); ++c) q[c] = coordValue(d, c, pose);
      calcBodyPoses(r.model, q, E);
      for (size_t m = 0; m < r.model.muscles().size(); ++m) {
        const PathForceDesc& pf = d.muscles[r.muscle_source[m]];
        if (pf.path_type == PathType::III) continue;  // the core lumps wraps for now
        EXPECT_NEAR(calcPathLength(r.model, r.model.muscles()[m].path, q, E),
                    polylineLength(d, pf, root, pose), 1e-12)
            << pf.name;
      }
    }
  }
}

TEST(OsimModels, FingerTakesItsIntendedMuscleMasses) {
  // the 0.2 kg per flexor of 6.2.5 goes on through the muscle-mass machinery: 20 points each
  const ModelDescription d = readOsimModel(scenePath("finger.osim"));
  const BuildResult r = buildCoreModel(d);
  const auto heavy = addMusclePointMasses(r.model.muscles(), {0.2, 0.2});
  ASSERT_EQ(heavy.size(), 2u);
  for (const auto& m : heavy) {
    EXPECT_EQ(m.mass_points.size(), 20) << m.name;
    EXPECT_NEAR(m.mass_points.totalMass(), 0.2, 1e-15) << m.name;
  }
  // together 8 times the mass of the four bones (50 g)
  double bones = 0.0;
  for (const auto& b : d.bodies) bones += b.mass;
  EXPECT_NEAR(bones, 0.04997, 1e-5);
}

// ---------------------------------------------------------------------------------------------
// double pendulums

TEST(OsimModels, PendulumLinksAreOneMetreOneKilogram) {
  for (const char* file :
       {"double_pendulum_via.osim", "double_pendulum_straight.osim", "double_pendulum_wrap.osim"}) {
    SCOPED_TRACE(file);
    const ModelDescription d = readOsimModel(scenePath(file));
    for (const auto& b : d.bodies) {
      EXPECT_EQ(b.mass, 1.0);
      EXPECT_LT((b.mass_center - Vec3(0, -0.5, 0)).norm(), 1e-15);
      // solid cylinder L = 1, r = 0.02: (3 r^2 + L^2) / 12 across, r^2 / 2 along
      EXPECT_NEAR(b.inertia[0], (3 * 0.02 * 0.02 + 1.0) / 12, 1e-15);
      EXPECT_NEAR(b.inertia[1], 0.02 * 0.02 / 2, 1e-15);
      EXPECT_NEAR(b.inertia[2], (3 * 0.02 * 0.02 + 1.0) / 12, 1e-15);
    }
    ASSERT_EQ(d.joints.size(), 2u);
    for (const auto& j : d.joints) EXPECT_EQ(j.kind, JointKind::Pin);
    // at q = 0 the pendulum hangs straight down: link2's far end at (0, -2, 0)
    const auto X = chainPoses(d, "ground", {{"q1", 0.0}, {"q2", 0.0}});
    EXPECT_LT((apply(X.at("link2"), Vec3(0, -1, 0)) - Vec3(0, -2, 0)).norm(), 1e-15);
    // default pose: 45 and 30 degrees, released from rest
    EXPECT_NEAR(d.coordinates[0].default_value, kPi / 4, 1e-14);
    EXPECT_NEAR(d.coordinates[1].default_value, kPi / 6, 1e-14);
    // physiological mass density * F / 0.25 MPa * L_opt is about one link (1 kg), as the
    // dissertation's equal-mass experiments use
    const auto& m = d.muscles.at(0);
    EXPECT_NEAR(1059.7 * m.max_isometric_force / 0.25e6 * m.optimal_fiber_length, 1.017, 1e-3);
  }
}

TEST(OsimModels, PendulumMusclesSpanTheJointsTheySay) {
  // via muscle: ground -> link1 -> link2 spans both joints; straight muscle: link1 -> link2
  // spans the middle joint only (dL/dq1 is exactly zero)
  const ModelDescription via = readOsimModel(scenePath("double_pendulum_via.osim"));
  const auto& mv = muscle(via, "via_muscle");
  ASSERT_EQ(mv.points.size(), 3u);
  EXPECT_EQ(mv.points[0].body, "ground");
  EXPECT_EQ(mv.points[1].body, "link1");
  EXPECT_EQ(mv.points[2].body, "link2");
  EXPECT_GT(std::abs(momentArm(via, mv, "ground", "q1")), 0.01);
  EXPECT_GT(momentArm(via, mv, "ground", "q2"), 0.01);  // on the +x side: shortens as q2 grows
  // the via point bends the path: shorter than the polyline it replaces would be without it
  const auto p = pathPoints(via, mv, "ground", {});
  EXPECT_GT((p[1] - p[0]).norm() + (p[2] - p[1]).norm(), (p[2] - p[0]).norm() + 1e-3);

  const ModelDescription st = readOsimModel(scenePath("double_pendulum_straight.osim"));
  const auto& ms = muscle(st, "straight_muscle");
  ASSERT_EQ(ms.points.size(), 2u);
  EXPECT_LT(std::abs(momentArm(st, ms, "ground", "q1")), 1e-9);  // rigid rotation: round-off only
  // -x side, 0.1 m off the links: at q2 = 0 the moment arm is exactly -0.1 m (lengthens as q2
  // grows); without a cylinder the line reaches the joint centre at q2 = pi - 2 atan(4) (28.1
  // deg) and the moment arm changes sign there, which is what the wrap scene prevents
  EXPECT_NEAR(momentArm(st, ms, "ground", "q2", {{"q2", 0.0}}), -0.1, 1e-9);
  const double q_cross = kPi - 2 * std::atan(4.0);
  EXPECT_LT(momentArm(st, ms, "ground", "q2", {{"q2", q_cross - 0.01}}), -1e-4);
  EXPECT_GT(momentArm(st, ms, "ground", "q2", {{"q2", q_cross + 0.01}}), 1e-4);
  EXPECT_LT(std::abs(momentArm(st, ms, "ground", "q2", {{"q2", q_cross}})), 1e-8);
  // path length 0.8 m at q2 = 0 equals optimal fibre + tendon slack length
  const double L0 = polylineLength(st, ms, "ground", {{"q2", 0.0}});
  EXPECT_NEAR(L0, 0.8, 1e-14);
  EXPECT_NEAR(L0, ms.optimal_fiber_length + ms.tendon_slack_length, 1e-14);
}

TEST(OsimModels, PendulumCylinderSitsOnTheMiddleJointAndEngagesAtTheStatedAngle) {
  const ModelDescription d = readOsimModel(scenePath("double_pendulum_wrap.osim"));
  ASSERT_EQ(d.wrap_objects.size(), 1u);
  const WrapObjectDesc& w = d.wrap_objects[0];
  EXPECT_EQ(w.type, "WrapCylinder");
  EXPECT_EQ(w.body, "link1");
  EXPECT_EQ(w.quadrant_axis, 0);
  EXPECT_EQ(w.quadrant_sign, -1);
  EXPECT_DOUBLE_EQ(w.radius, 0.08);
  const JointDesc& pin2 = d.joints.at(d.findJoint("pin2"));
  EXPECT_EQ(pin2.parent_body, "link1");
  // centred on the middle joint, axis parallel to the pin axis
  EXPECT_LT((w.X_body.topRightCorner<3, 1>() - pin2.X_PF.topRightCorner<3, 1>()).norm(), 1e-15);
  EXPECT_LT((w.X_body.block<3, 1>(0, 2) - pin2.X_PF.block<3, 1>(0, 2)).norm(), 1e-15);
  const auto& m = muscle(d, "wrap_muscle");
  ASSERT_EQ(m.wraps.size(), 1u);
  EXPECT_EQ(m.wraps[0].wrap_object, "joint_cylinder");
  // origin and insertion stay outside the cylinder (OpenSim returns insideRadius otherwise)
  for (const Vec3& p : pathPoints(d, m, "link1", {}))
    EXPECT_GT((p - w.X_body.topRightCorner<3, 1>()).head<2>().norm(), 0.3);
  // straight at q2 = 0 (the segment passes 0.1 m from the axis), wrapped at the default 30 deg
  EXPECT_NEAR(axisToSegment2d(d, m, "ground", {{"q2", 0.0}}), 0.1, 1e-14);
  EXPECT_LT(axisToSegment2d(d, m, "ground", {}), w.radius);
  // engagement angle: both ends 0.4 m along the links and 0.1 m off them, at d = sqrt(0.17)
  // from the axis; the segment is at d cos(phi / 2) from the axis, phi = 2 atan(4) + q2
  const double dist = std::sqrt(0.17);
  const double q_star = 2 * std::acos(w.radius / dist) - 2 * std::atan(4.0);
  double lo = 0.0, hi = kPi / 6;  // bisection on the forward-kinematics distance
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (axisToSegment2d(d, m, "ground", {{"q2", mid}}) > w.radius ? lo : hi) = mid;
  }
  EXPECT_NEAR(lo, q_star, 1e-12);
  EXPECT_NEAR(q_star, 0.0993, 1e-3);  // "q2 > about 0.1 rad" in the header
}

// ---------------------------------------------------------------------------------------------
// finger

TEST(OsimModels, FingerBonesChainAndFlexTowardsThePalm) {
  const ModelDescription d = readOsimModel(scenePath("finger.osim"));
  EXPECT_EQ(d.joints.at(d.findJoint("wrist_weld")).kind, JointKind::Weld);
  for (const char* j : {"mcp", "pip", "dip"})
    EXPECT_EQ(d.joints.at(d.findJoint(j)).kind, JointKind::Pin);
  // masses: bone cylinders at 5 g/cm^3 (the dissertation's density), 4 significant digits
  const std::map<std::string, std::pair<double, double>> bone = {{"metacarpal", {0.065, 0.005}},
                                                                 {"proximal", {0.045, 0.0045}},
                                                                 {"middle", {0.025, 0.004}},
                                                                 {"distal", {0.020, 0.0035}}};
  for (const auto& b : d.bodies) {
    const auto [L, r] = bone.at(b.name);
    EXPECT_NEAR(b.mass, 5000 * kPi * r * r * L, 5e-4 * b.mass) << b.name;
    EXPECT_NEAR(b.mass_center.x(), L / 2, 1e-15) << b.name;
  }
  // the fingertip marker
  ASSERT_EQ(d.markers.size(), 1u);
  EXPECT_EQ(d.markers[0].name, "fingertip");
  EXPECT_EQ(d.markers[0].body, "distal");
  const Vec3 tip_d = d.markers[0].X_body_frame.topLeftCorner<3, 3>() * d.markers[0].location +
                     d.markers[0].X_body_frame.topRightCorner<3, 1>();
  // straight finger: the tip is 65 + 45 + 25 + 20 mm along x
  Coords zero = {{"mcp_flexion", 0.0}, {"pip_flexion", 0.0}, {"dip_flexion", 0.0}};
  EXPECT_LT((apply(chainPoses(d, "ground", zero).at("distal"), tip_d) - Vec3(0.155, 0, 0)).norm(),
            1e-14);
  // positive flexion of each joint moves the tip palmar (-y); dy/dq = -(distance along x)
  for (const char* q : {"mcp_flexion", "pip_flexion", "dip_flexion"}) {
    Coords c = zero;
    c[q] = 1e-6;
    const Vec3 tp = apply(chainPoses(d, "ground", c).at("distal"), tip_d);
    c[q] = -1e-6;
    const Vec3 tm = apply(chainPoses(d, "ground", c).at("distal"), tip_d);
    const double lever = std::string(q) == "mcp_flexion"   ? 0.09
                         : std::string(q) == "pip_flexion" ? 0.045
                                                           : 0.02;
    EXPECT_NEAR((tp.y() - tm.y()) / 2e-6, -lever, 1e-8) << q;
  }
  // default pose lightly flexed with DIP at half of PIP (the dissertation's coupled IP joints)
  EXPECT_NEAR(d.coordinates[2].default_value, 0.5 * d.coordinates[1].default_value, 1e-15);
}

TEST(OsimModels, FingerFlexorsHaveTheStatedMomentArms) {
  const ModelDescription d = readOsimModel(scenePath("finger.osim"));
  const auto& fdp = muscle(d, "FDP");
  const auto& fds = muscle(d, "FDS");
  EXPECT_EQ(fdp.points.front().body, "ground");  // near the elbow: the fixed forearm
  EXPECT_EQ(fdp.points.back().body, "distal");
  EXPECT_EQ(fds.points.back().body, "middle");
  // a pulley (path point) on each phalanx the tendon passes
  std::set<std::string> fdp_bodies, fds_bodies;
  for (const auto& p : fdp.points) fdp_bodies.insert(p.body);
  for (const auto& p : fds.points) fds_bodies.insert(p.body);
  EXPECT_EQ(fdp_bodies,
            (std::set<std::string>{"ground", "metacarpal", "proximal", "middle", "distal"}));
  EXPECT_EQ(fds_bodies, (std::set<std::string>{"ground", "metacarpal", "proximal", "middle"}));
  // moment arms -dL/dq at the default pose, the values written in the header (0.05 mm)
  EXPECT_NEAR(momentArm(d, fdp, "ground", "mcp_flexion"), 0.0110, 5e-5);
  EXPECT_NEAR(momentArm(d, fdp, "ground", "pip_flexion"), 0.0090, 5e-5);
  EXPECT_NEAR(momentArm(d, fdp, "ground", "dip_flexion"), 0.0061, 5e-5);
  EXPECT_NEAR(momentArm(d, fds, "ground", "mcp_flexion"), 0.0129, 5e-5);
  EXPECT_NEAR(momentArm(d, fds, "ground", "pip_flexion"), 0.0098, 5e-5);
  EXPECT_EQ(momentArm(d, fds, "ground", "dip_flexion"), 0.0);  // FDS ends before the DIP
  // flexors over the whole flexion range: the pulleys never let the path cross a joint centre,
  // so flexing any joint shortens them, with moment arms of 4 to 20 mm
  const char* joints[] = {"mcp_flexion", "pip_flexion", "dip_flexion"};
  for (double f : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    Coords q;
    for (const char* c : joints) q[c] = f * d.coordinates[d.findCoordinate(c)].range_max;
    for (const char* c : joints) {
      const double r_fdp = momentArm(d, fdp, "ground", c, q);
      EXPECT_GT(r_fdp, 0.004) << c << " at " << f;
      EXPECT_LT(r_fdp, 0.020) << c << " at " << f;
      if (std::string(c) == "dip_flexion") continue;
      const double r_fds = momentArm(d, fds, "ground", c, q);
      EXPECT_GT(r_fds, 0.004) << c << " at " << f;
      EXPECT_LT(r_fds, 0.020) << c << " at " << f;
    }
  }
  // tendon slack: fibre at optimal length in the default pose with a rigid tendon (0.1 mm)
  for (const auto* m : {&fdp, &fds})
    EXPECT_NEAR(polylineLength(d, *m, "ground", {}) - m->tendon_slack_length,
                m->optimal_fiber_length * std::cos(m->pennation_angle_at_optimal), 1e-4)
        << m->name;
  // the intended 0.2 kg muscle mass is recorded in the file (OpenSim has no property for it)
  const std::string xml = readText(scenePath("finger.osim"));
  EXPECT_NE(xml.find("0.2 kg"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// running leg

TEST(OsimModels, RunningLegSegmentsFollowDeLeva) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  // de Leva (1996) male mass fractions of a 73 kg body; 4 significant digits in the file
  const std::map<std::string, double> fraction = {
      {"pelvis", 0.1117}, {"femur_r", 0.1416}, {"tibia_r", 0.0433}, {"calcn_r", 0.0137}};
  for (const auto& b : d.bodies) {
    EXPECT_NEAR(b.mass, fraction.at(b.name) * 73.0, 5e-4 * b.mass) << b.name;
    // a valid inertia: positive, triangle inequality
    const Eigen::Vector3d I = b.inertia.head<3>();
    EXPECT_GT(I.minCoeff(), 0.0) << b.name;
    EXPECT_LE(I.maxCoeff(), I.sum() - I.maxCoeff()) << b.name;
  }
  // joint types and coordinate motion types
  EXPECT_EQ(d.joints.at(d.findJoint("ground_pelvis")).kind, JointKind::Custom);
  EXPECT_EQ(d.joints.at(d.findJoint("hip_r")).kind, JointKind::Custom);
  EXPECT_EQ(d.joints.at(d.findJoint("knee_r")).kind, JointKind::Pin);
  EXPECT_EQ(d.joints.at(d.findJoint("ankle_r")).kind, JointKind::Pin);
  for (const auto& c : d.coordinates) {
    const bool translation =
        c.name == "pelvis_tx" || c.name == "pelvis_ty" || c.name == "pelvis_tz";
    EXPECT_EQ(c.motion_type, translation ? MotionType::Translational : MotionType::Rotational)
        << c.name;
  }
  // standing default: knee 422.2 mm below the hip, ankle 434.0 mm below the knee
  const auto X = chainPoses(d, "femur_r", {});
  EXPECT_LT((X.at("tibia_r").topRightCorner<3, 1>() - Vec3(0, -0.4222, 0)).norm(), 1e-15);
  EXPECT_LT((X.at("calcn_r").topRightCorner<3, 1>() - Vec3(0, -0.8562, 0)).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(d.coordinates[d.findCoordinate("pelvis_ty")].default_value, 1.0);
}

TEST(OsimModels, RunningLegAnkleMusclesHaveTheStatedPathsAndMomentArms) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  const auto& sol = muscle(d, "soleus_r");
  const auto& ta = muscle(d, "tib_ant_r");
  for (const auto& m : d.muscles) EXPECT_EQ(m.class_name, "Millard2012EquilibriumMuscle");
  EXPECT_EQ(sol.path_type, PathType::I);
  EXPECT_EQ(ta.path_type, PathType::II);
  EXPECT_EQ(muscle(d, "med_gas_r").path_type, PathType::III);
  EXPECT_EQ(muscle(d, "lat_gas_r").path_type, PathType::III);
  EXPECT_EQ(sol.points.front().body, "tibia_r");
  EXPECT_EQ(sol.points.back().body, "calcn_r");
  ASSERT_EQ(ta.points.size(), 3u);
  EXPECT_EQ(ta.points[1].body, "tibia_r");  // the via point near the ankle
  for (const char* g : {"med_gas_r", "lat_gas_r"}) {
    EXPECT_EQ(muscle(d, g).points.front().body, "femur_r");
    EXPECT_EQ(muscle(d, g).points.back().body, "calcn_r");
  }
  // about the ankle (dorsiflexion positive): soleus plantarflexes, tibialis anterior
  // dorsiflexes, with the 4.6 and 5.0 cm of the header (0.5 mm); neither spans the knee
  EXPECT_NEAR(momentArm(d, sol, "femur_r", "ankle_angle_r"), -0.046, 5e-4);
  EXPECT_NEAR(momentArm(d, ta, "femur_r", "ankle_angle_r"), 0.050, 5e-4);
  EXPECT_LT(std::abs(momentArm(d, sol, "femur_r", "knee_angle_r")), 1e-9);
  EXPECT_LT(std::abs(momentArm(d, ta, "femur_r", "knee_angle_r")), 1e-9);
  // physiological masses density * F / 0.25 MPa * L_opt, as the header lists them (5 g)
  const std::map<std::string, double> mass = {
      {"soleus_r", 0.75}, {"tib_ant_r", 0.38}, {"med_gas_r", 0.40}, {"lat_gas_r", 0.19}};
  for (const auto& m : d.muscles)
    EXPECT_NEAR(1059.7 * m.max_isometric_force / 0.25e6 * m.optimal_fiber_length, mass.at(m.name),
                5e-3)
        << m.name;
  // tendon slack fitted to this geometry: fibre at its optimal length at the default pose
  for (const auto* m : {&sol, &ta})
    EXPECT_NEAR(polylineLength(d, *m, "femur_r", {}) - m->tendon_slack_length,
                m->optimal_fiber_length * std::cos(m->pennation_angle_at_optimal), 1e-3)
        << m->name;
}

TEST(OsimModels, RunningLegGastrocnemiusWrapsTheCondylesOnlyNearExtension) {
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  ASSERT_EQ(d.wrap_objects.size(), 1u);
  const WrapObjectDesc& w = d.wrap_objects[0];
  EXPECT_EQ(w.name, "gastroc_condyles_r");
  EXPECT_EQ(w.type, "WrapCylinder");
  EXPECT_EQ(w.body, "femur_r");
  EXPECT_EQ(w.quadrant, "-x");
  // behind and near the knee centre, axis mediolateral (z)
  const Vec3 c = w.X_body.topRightCorner<3, 1>();
  EXPECT_LT((c - Vec3(0, -0.4222, 0)).norm(), 0.03);
  EXPECT_LT(c.x(), 0.0);
  EXPECT_LT((w.X_body.block<3, 1>(0, 2) - Vec3::UnitZ()).norm(), 1e-15);
  for (const char* g : {"med_gas_r", "lat_gas_r"}) {
    SCOPED_TRACE(g);
    const auto& m = muscle(d, g);
    ASSERT_EQ(m.wraps.size(), 1u);
    EXPECT_EQ(m.wraps[0].wrap_object, w.name);
    // the origin lies outside the cylinder and on its active (-x) side
    const Vec3 o = m.points.front().location - c;
    EXPECT_GT(o.head<2>().norm(), w.radius);
    EXPECT_LT(o.x(), 0.0);
    // the straight line would cut the cylinder at full extension and at 10 degrees of flexion,
    // not at 25 degrees or deeper: the header's "beyond about 18 degrees"
    for (double deg : {10.0, 0.0, -10.0})
      EXPECT_LT(axisToSegment2d(d, m, "femur_r", {{"knee_angle_r", deg * kPi / 180}}), w.radius)
          << deg;
    for (double deg : {-25.0, -60.0, -110.0})
      EXPECT_GT(axisToSegment2d(d, m, "femur_r", {{"knee_angle_r", deg * kPi / 180}}), w.radius)
          << deg;
  }
}

// ---------------------------------------------------------------------------------------------
// the swing-phase motion

TEST(OsimModels, SwingMotionReadsWithTheModelsCoordinatesInDegrees) {
  const Storage s = readStorage(scenePath("running_leg_swing.mot"));
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  EXPECT_TRUE(s.in_degrees);
  EXPECT_EQ(s.version, 1);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(s.labels, coordinateNames(d));  // every coordinate, in the model's q order
  // 0.4 s at 200 Hz
  ASSERT_EQ(s.numRows(), 81);
  for (int i = 0; i < s.numRows(); ++i) EXPECT_NEAR(s.time[i], 0.005 * i, 1e-12);
  // the reproducing command is in the header
  bool has_command = false;
  for (const auto& [k, v] : s.header)
    has_command |= v.find("awk -f osim_models/tools/running_leg_swing.awk") != std::string::npos;
  EXPECT_TRUE(has_command);
  // within the coordinate ranges (angles converted as OpenSim converts Rotational columns)
  for (int c = 0; c < s.numColumns(); ++c) {
    const auto& cd = d.coordinates[d.findCoordinate(s.labels[c])];
    const double scale = cd.motion_type == MotionType::Rotational ? kPi / 180 : 1.0;
    for (int i = 0; i < s.numRows(); ++i) {
      EXPECT_GE(s.data(i, c) * scale, cd.range_min) << cd.name << " row " << i;
      EXPECT_LE(s.data(i, c) * scale, cd.range_max) << cd.name << " row " << i;
    }
  }
  // the closed forms of the generator, to the 8 printed decimals
  const int hip = s.findColumn("hip_flexion_r"), knee = s.findColumn("knee_angle_r"),
            ankle = s.findColumn("ankle_angle_r"), ty = s.findColumn("pelvis_ty");
  for (int i = 0; i < s.numRows(); ++i) {
    const double sv = s.time[i] / 0.4, a = kPi * sv;
    EXPECT_NEAR(s.data(i, hip), 15 - 25 * std::cos(a) + 8 * std::sin(a), 6e-9);
    EXPECT_NEAR(s.data(i, knee), -(25 - 13 * sv) - 90 * std::sin(a) * std::sin(a), 6e-9);
    EXPECT_NEAR(s.data(i, ankle), -20 + 22 * sv + 15 * std::sin(a), 6e-9);
    EXPECT_NEAR(s.data(i, ty), 0.98 + 0.04 * std::cos(2 * a), 6e-9);
  }
  // swing: knee flexes past 100 degrees mid-swing; toe-off plantarflexed, hip flexes forward
  EXPECT_LT(s.data.col(knee).minCoeff(), -100.0);
  EXPECT_LT(s.data(0, ankle), -15.0);
  EXPECT_GT(s.data(s.numRows() - 1, hip), 30.0);
}

TEST(OsimModels, SwingMotionCrossesTheGastrocnemiusWrapEvent) {
  // unwrapped at toe-off (knee -25 deg), wrapped at touch-down (knee -12 deg): a swing through
  // this scene exercises the Type III event, as the header promises
  const Storage s = readStorage(scenePath("running_leg_swing.mot"));
  const ModelDescription d = readOsimModel(scenePath("running_leg.osim"));
  const double r = d.wrap_objects.at(0).radius;
  const int knee = s.findColumn("knee_angle_r"), ankle = s.findColumn("ankle_angle_r");
  auto at = [&](int row) {
    return Coords{{"knee_angle_r", s.data(row, knee) * kPi / 180},
                  {"ankle_angle_r", s.data(row, ankle) * kPi / 180}};
  };
  for (const char* g : {"med_gas_r", "lat_gas_r"}) {
    const auto& m = muscle(d, g);
    EXPECT_GT(axisToSegment2d(d, m, "femur_r", at(0)), r) << g;
    EXPECT_LT(axisToSegment2d(d, m, "femur_r", at(s.numRows() - 1)), r) << g;
  }
}

TEST(OsimModels, SwingMotionIsReproducedByItsGenerator) {
  if (std::system("command -v awk > /dev/null 2>&1") != 0) GTEST_SKIP() << "awk not found";
  test::TempDir tmp;
  const std::string out = tmp.file("swing.mot");
  const std::string cmd = "cd '" + std::string(REDMAX_SOURCE_DIR) +
                          "' && awk -f osim_models/tools/running_leg_swing.awk > '" + out + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_EQ(readText(out), readText(scenePath("running_leg_swing.mot")));
}

}  // namespace
}  // namespace redmax::osim
