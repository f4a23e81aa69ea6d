#include "core/joints/spherical_exp.hpp"

#include <cmath>
#include <numbers>

namespace redmax {

namespace {

// b, c of the header and beta = b'/th, gamma = c'/th
struct ExpCoefficients {
  double b, c, beta, gamma;
};

ExpCoefficients expCoefficients(double th2) {
  ExpCoefficients k;
  if (th2 < 1e-2) {
    // th < 0.1: the closed forms lose ~eps/th^2 to cancellation; these series are exact to
    // round-off there (next terms are below 1e-16 relative)
    const double t2 = th2, t4 = t2 * t2, t6 = t4 * t2, t8 = t4 * t4;
    k.b = 0.5 - t2 / 24.0 + t4 / 720.0 - t6 / 40320.0 + t8 / 3628800.0;
    k.c = 1.0 / 6.0 - t2 / 120.0 + t4 / 5040.0 - t6 / 362880.0 + t8 / 39916800.0;
    k.beta = -1.0 / 12.0 + t2 / 180.0 - t4 / 6720.0 + t6 / 453600.0 - t8 / 47900160.0;
    k.gamma = -1.0 / 60.0 + t2 / 1260.0 - t4 / 60480.0 + t6 / 4989600.0;
    return k;
  }
  const double th = std::sqrt(th2);
  const double s = std::sin(th), co = std::cos(th);
  const double th3 = th2 * th, th4 = th2 * th2;
  k.b = (1.0 - co) / th2;
  k.c = (th - s) / th3;
  k.beta = (th * s - 2.0 * (1.0 - co)) / th4;
  k.gamma = ((1.0 - co) * th - 3.0 * (th - s)) / (th4 * th);
  return k;
}

Mat3 rightJacobian(const Vec3& q, const ExpCoefficients& k) {
  const Mat3 W = skew(q);
  return Mat3::Identity() - k.b * W + k.c * W * W;
}

}  // namespace

void SphericalExp::calcRotation(const Vec3& q, const Vec3& qdot, Mat3& R, Mat3& S, Mat3& Sdot) {
  const ExpCoefficients k = expCoefficients(q.squaredNorm());
  const Mat3 W = skew(q);
  const Mat3 Wd = skew(qdot);
  const double qqd = q.dot(qdot);
  R = expSO3(q);
  S = Mat3::Identity() - k.b * W + k.c * W * W;
  Sdot = -k.beta * qqd * W - k.b * Wd + k.gamma * qqd * W * W + k.c * (Wd * W + W * Wd);
}

void SphericalExp::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  Mat3 R, S, Sd;
  calcRotation(Vec3(q[0], q[1], q[2]), Vec3(qdot[0], qdot[1], qdot[2]), R, S, Sd);
  out.resize(3);
  out.Q = makeE(R, Vec3::Zero());
  out.S.topRows<3>() = S;
  out.Sdot.topRows<3>() = Sd;
}

bool SphericalExp::reparameterizeRotation(Vec3& q, Vec3& qdot) {
  const double th = q.norm();
  if (!(th > kReparameterizeAbove)) return false;
  const Mat3 S_prev = rightJacobian(q, expCoefficients(th * th));
  // same rotation: exp([q]) = exp([q - 2 pi q/|q|])  [D Sec. 4.5.8, Grassia]
  const Vec3 q_new = (1.0 - 2.0 * std::numbers::pi / th) * q;
  const Mat3 S_new = rightJacobian(q_new, expCoefficients(q_new.squaredNorm()));
  // same body angular velocity: S_new qdot_new = S_prev qdot_prev
  qdot = S_new.partialPivLu().solve(S_prev * qdot);
  q = q_new;
  return true;
}

double SphericalExp::rotationSingularityDistance(const Vec3& q) {
  const double half = 0.5 * q.norm();
  return half < 1e-8 ? 1.0 : std::abs(std::sin(half) / half);
}

double SphericalExp::singularityDistance(const VecJ& q) const {
  return rotationSingularityDistance(Vec3(q[0], q[1], q[2]));
}

bool SphericalExp::reparameterize(VecJ& q, VecJ& qdot) const {
  Vec3 r(q[0], q[1], q[2]), rd(qdot[0], qdot[1], qdot[2]);
  if (!reparameterizeRotation(r, rd)) return false;
  q.head<3>() = r;
  qdot.head<3>() = rd;
  return true;
}

}  // namespace redmax
