#include "core/joints/euler_joints.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace redmax {

namespace {
constexpr const char* kNames[12] = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX",
                                    "XYX", "XZX", "YXY", "YZY", "ZXZ", "ZYZ"};
}  // namespace

void eulerAxes(EulerSequence seq, int& a, int& b, int& c) {
  const char* n = kNames[static_cast<int>(seq)];
  a = n[0] - 'X';
  b = n[1] - 'X';
  c = n[2] - 'X';
}

bool isProperEuler(EulerSequence seq) { return static_cast<int>(seq) >= 6; }

std::string eulerSequenceName(EulerSequence seq) { return kNames[static_cast<int>(seq)]; }

EulerSequence parseEulerSequence(const std::string& name) {
  std::string up = name;
  std::transform(up.begin(), up.end(), up.begin(), [](unsigned char ch) { return std::toupper(ch); });
  for (int k = 0; k < 12; ++k)
    if (up == kNames[k]) return static_cast<EulerSequence>(k);
  throw JointError("unknown Euler sequence '" + name +
                   "' (expected one of XYZ XZY YXZ YZX ZXY ZYX XYX XZX YXY YZY ZXZ ZYZ)");
}

Mat3 rotationAboutAxis(int axis, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Mat3 R = Mat3::Identity();
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;  // the plane rotated, right-handed
  R(i, i) = c;
  R(i, j) = -s;
  R(j, i) = s;
  R(j, j) = c;
  return R;
}

void SphericalEuler::calcRotation(const Vec3& q, const Vec3& qdot, Mat3& R, Mat3& S,
                                  Mat3& Sdot) const {
  int a, b, c;
  eulerAxes(sequence, a, b, c);
  const Mat3 Ra = rotationAboutAxis(a, q[0]);
  const Mat3 Rb = rotationAboutAxis(b, q[1]);
  const Mat3 Rc = rotationAboutAxis(c, q[2]);
  R = Ra * Rb * Rc;
  const Vec3 ea = Vec3::Unit(a), eb = Vec3::Unit(b), ec = Vec3::Unit(c);
  // columns of R^T dR/dq_k (see the header)
  const Vec3 Rbt_ea = Rb.transpose() * ea;
  S.col(0) = Rc.transpose() * Rbt_ea;
  S.col(1) = Rc.transpose() * eb;
  S.col(2) = ec;
  // time derivatives: only R_b and R_c enter the columns
  Sdot.col(0) = -qdot[2] * ec.cross(Vec3(S.col(0))) - qdot[1] * (Rc.transpose() * eb.cross(Rbt_ea));
  Sdot.col(1) = -qdot[2] * ec.cross(Vec3(S.col(1)));
  Sdot.col(2).setZero();
}

void SphericalEuler::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  Mat3 R, S, Sd;
  calcRotation(Vec3(q[0], q[1], q[2]), Vec3(qdot[0], qdot[1], qdot[2]), R, S, Sd);
  out.resize(3);
  out.Q = makeE(R, Vec3::Zero());
  out.S.topRows<3>() = S;
  out.Sdot.topRows<3>() = Sd;
}

double SphericalEuler::gimbalDistance(const VecJ& q) const {
  return isProperEuler(sequence) ? std::abs(std::sin(q[1])) : std::abs(std::cos(q[1]));
}

}  // namespace redmax
