#include "validation/scenes/humanoid.hpp"

#include <string>

#include "core/joints/joint.hpp"

namespace redmax::scenes {

namespace {

// solid cylinder of mass m, length L along the body y axis, radius r; COM at com
Mat3 cylinderInertia(double m, double L, double r) {
  Mat3 I = Mat3::Zero();
  I(0, 0) = I(2, 2) = m * (3.0 * r * r + L * L) / 12.0;
  I(1, 1) = 0.5 * m * r * r;
  return I;
}

// a segment hanging from its proximal joint (at the body origin) along -y
struct Segment {
  double mass, length, radius;
};

}  // namespace

Model humanoid() {
  ModelBuilder b("humanoid");
  b.setGravity(Vec3(0.0, -9.80665, 0.0));
  // frame that turns the Universal's first axis (x) onto the body z axis (flexion), second onto x
  const Mat3 R_flex = (Mat3() << 0, 1, 0, 0, 0, 1, 1, 0, 0).finished();
  const Mat4 E_flex = makeE(R_flex, Vec3::Zero());
  auto at = [](double x, double y, double z) { return makeTranslation(Vec3(x, y, z)); };
  auto hang = [&](const std::string& name, const Segment& s, int parent, const std::string& joint,
                  Joint j, const Mat4& E_pf, const Mat4& E_bm = Mat4::Identity()) {
    return b.addBody(name, s.mass, Vec3(0.0, -0.45 * s.length, 0.0),
                     cylinderInertia(s.mass, s.length, s.radius), parent, joint, std::move(j), E_pf, E_bm);
  };

  // pelvis: origin between the hip joints, free on the world (OpenSim layout)
  const int pelvis = b.addBody("pelvis", 11.0, Vec3(-0.03, 0.05, 0.0),
                               Vec3(0.10, 0.09, 0.08).asDiagonal().toDenseMatrix(), -1,
                               "ground_pelvis", Free3D::opensim());
  b.setCoordinateNames(pelvis, {"pelvis_tilt", "pelvis_list", "pelvis_rotation", "pelvis_tx",
                                "pelvis_ty", "pelvis_tz"});
  b.coordinate(pelvis, 4).default_value = 0.94;

  // trunk: torso up from the lumbar joint, head on a universal neck
  const int torso = b.addBody("torso", 26.0, Vec3(-0.02, 0.25, 0.0), cylinderInertia(26.0, 0.55, 0.15),
                              pelvis, "lumbar", SphericalEuler{}, at(-0.05, 0.10, 0.0));
  b.setCoordinateNames(torso, {"lumbar_extension", "lumbar_bending", "lumbar_rotation"});
  const int head = b.addBody("head", 5.0, Vec3(0.02, 0.12, 0.0), cylinderInertia(5.0, 0.22, 0.09), torso,
                             "neck", Universal{}, at(0.0, 0.50, 0.0) * E_flex, E_flex);
  b.setCoordinateNames(head, {"neck_flexion", "neck_bending"});

  for (int side = 0; side < 2; ++side) {
    const std::string s = side == 0 ? "_r" : "_l";
    const double z = side == 0 ? 1.0 : -1.0;
    // arm
    const int ua = hang("upper_arm" + s, {2.0, 0.30, 0.045}, torso, "shoulder" + s, SphericalEuler{},
                        at(0.0, 0.42, 0.19 * z));
    b.setCoordinateNames(ua, {"arm_flex" + s, "arm_add" + s, "arm_rot" + s});
    const int fa = hang("forearm" + s, {1.2, 0.27, 0.035}, ua, "elbow" + s, Revolute{Vec3::UnitZ()},
                        at(0.0, -0.30, 0.0));
    b.setCoordinateNames(fa, {"elbow_flex" + s});
    const int hd = hang("hand" + s, {0.45, 0.18, 0.03}, fa, "wrist" + s, Universal{},
                        at(0.0, -0.27, 0.0) * E_flex, E_flex);
    b.setCoordinateNames(hd, {"wrist_flex" + s, "wrist_dev" + s});
    // leg
    const int th = hang("thigh" + s, {9.0, 0.42, 0.07}, pelvis, "hip" + s, SphericalEuler{},
                        at(0.0, -0.07, 0.09 * z));
    b.setCoordinateNames(th, {"hip_flexion" + s, "hip_adduction" + s, "hip_rotation" + s});
    const int sh = hang("shank" + s, {3.7, 0.43, 0.05}, th, "knee" + s, Revolute{Vec3::UnitZ()},
                        at(0.0, -0.42, 0.0));
    b.setCoordinateNames(sh, {"knee_angle" + s});
    const int ft = b.addBody("foot" + s, 1.1, Vec3(0.08, -0.04, 0.0), cylinderInertia(1.1, 0.20, 0.04),
                             sh, "ankle" + s, Universal{}, at(0.0, -0.43, 0.0) * E_flex, E_flex);
    b.setCoordinateNames(ft, {"ankle_angle" + s, "subtalar_angle" + s});
    const int to = b.addBody("toes" + s, 0.2, Vec3(0.03, 0.0, 0.0), cylinderInertia(0.2, 0.06, 0.02), ft,
                             "mtp" + s, Revolute{Vec3::UnitZ()}, at(0.16, -0.05, 0.0));
    b.setCoordinateNames(to, {"mtp_angle" + s});
  }
  return b.finalize();
}

Model limbChain(int n) {
  if (n < 1) throw ModelError("limbChain: need at least one link, got " + std::to_string(n));
  ModelBuilder b("limb_chain_" + std::to_string(n));
  b.setGravity(Vec3(0.0, -9.80665, 0.0));
  const double L = 0.3, m = 1.0, r = 0.03;
  int parent = -1;
  for (int i = 0; i < n; ++i) {
    const Mat4 E_pf = parent < 0 ? Mat4::Identity() : makeTranslation(Vec3(0.0, -L, 0.0));
    const Vec3 axis = i % 2 == 0 ? Vec3::UnitZ() : Vec3::UnitX();
    parent = b.addBody("link" + std::to_string(i), m, Vec3(0.0, -0.45 * L, 0.0), cylinderInertia(m, L, r), parent,
                       "hinge" + std::to_string(i), Revolute{axis}, E_pf);
  }
  return b.finalize();
}

}  // namespace redmax::scenes
