#include "core/dynamics/passive_force_terms.hpp"

#include <algorithm>
#include <cmath>

#include "core/dynamics/body_loads.hpp"

namespace redmax {

namespace {

void checkCoordinate(const Model& model, const std::string& what, int c) {
  if (c < 0 || c >= model.nr())
    throw ModelError(what + ": coordinate index " + std::to_string(c) + " outside the model's " +
                     std::to_string(model.nr()));
}

void checkNonNegative(const std::string& what, const char* property, double v) {
  if (!(v >= 0.0) || !std::isfinite(v))
    throw ModelError(what + ": " + property + " must be finite and >= 0, found " + std::to_string(v));
}

// SimTK::Function::Step's smooth step on [0, 1] (stepUp): 0 below, 1 above
double step01(double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}

// d step01 / dx
double step01Derivative(double x) {
  if (x <= 0.0 || x >= 1.0) return 0.0;
  const double t = x * (1.0 - x);
  return 30.0 * t * t;
}

Vec3 worldPoint(const SkeletonWorkspace& sk, int body, const Vec3& p) {
  return body < 0 ? p : transformPoint(sk.E_wi[body], p);
}

}  // namespace

// ---------------------------------------------------------------------------------------------

CoordinateLimitForceTerm::CoordinateLimitForceTerm(const Model& model, std::vector<Limit> limits)
    : limits_(std::move(limits)) {
  for (const Limit& l : limits_) {
    const std::string what = "CoordinateLimitForce '" + l.name + "'";
    checkCoordinate(model, what, l.coordinate);
    checkNonNegative(what, "upper_stiffness", l.upper_stiffness);
    checkNonNegative(what, "lower_stiffness", l.lower_stiffness);
    checkNonNegative(what, "damping", l.damping);
    if (!(l.transition > 0.0) || !std::isfinite(l.transition))
      throw ModelError(what + ": transition must be positive and finite");
    if (!std::isfinite(l.upper_limit) || !std::isfinite(l.lower_limit))
      throw ModelError(what + ": upper_limit and lower_limit must be finite");
  }
}

double CoordinateLimitForceTerm::force(const Limit& l, double q, double qdot) {
  const double s_up = step01((q - l.upper_limit) / l.transition);
  const double s_lo = step01((l.lower_limit - q) / l.transition);
  return -l.upper_stiffness * s_up * (q - l.upper_limit) + l.lower_stiffness * s_lo * (l.lower_limit - q) -
         l.damping * (s_up + s_lo) * qdot;
}

void CoordinateLimitForceTerm::forceDerivatives(const Limit& l, double q, double qdot, double& dq, double& dqdot) {
  const double s_up = step01((q - l.upper_limit) / l.transition);
  const double s_lo = step01((l.lower_limit - q) / l.transition);
  const double ds_up = step01Derivative((q - l.upper_limit) / l.transition) / l.transition;
  const double ds_lo = -step01Derivative((l.lower_limit - q) / l.transition) / l.transition;
  dq = -l.upper_stiffness * (ds_up * (q - l.upper_limit) + s_up) +
       l.lower_stiffness * (ds_lo * (l.lower_limit - q) - s_lo) - l.damping * (ds_up + ds_lo) * qdot;
  dqdot = -l.damping * (s_up + s_lo);
}

double CoordinateLimitForceTerm::potential(const Limit& l, double q) {
  double K = 0.0, delta = 0.0;
  if (q > l.upper_limit) {
    K = l.upper_stiffness;
    delta = q - l.upper_limit;
  } else if (q < l.lower_limit) {
    K = l.lower_stiffness;
    delta = l.lower_limit - q;
  } else {
    return 0.0;
  }
  const double w = l.transition;
  if (delta >= w) return K * ((-2.0 / 14.0) * w * w + 0.5 * delta * delta);
  // the integral of K step(x) x w^2 dx up to x = delta / w
  const double x = delta / w;
  return K * x * x * x * (2.0 - 2.5 * x + (6.0 / 7.0) * x * x) * (delta * delta);
}

void CoordinateLimitForceTerm::addForce(const Model&, const State& s, const TermContext&, VecX& f) const {
  for (const Limit& l : limits_) f[l.coordinate] += force(l, s.q[l.coordinate], s.qdot[l.coordinate]);
}

double CoordinateLimitForceTerm::potentialEnergy(const Model&, const State& s, const TermContext&) const {
  double V = 0.0;
  for (const Limit& l : limits_) V += potential(l, s.q[l.coordinate]);
  return V;
}

// ---------------------------------------------------------------------------------------------

SpringGeneralizedForceTerm::SpringGeneralizedForceTerm(const Model& model, std::vector<Spring> springs)
    : springs_(std::move(springs)) {
  for (const Spring& sp : springs_) {
    const std::string what = "SpringGeneralizedForce '" + sp.name + "'";
    checkCoordinate(model, what, sp.coordinate);
    checkNonNegative(what, "stiffness", sp.stiffness);
    checkNonNegative(what, "viscosity", sp.viscosity);
    if (!std::isfinite(sp.rest_length)) throw ModelError(what + ": rest_length must be finite");
  }
}

void SpringGeneralizedForceTerm::addForce(const Model&, const State& s, const TermContext&, VecX& f) const {
  for (const Spring& sp : springs_)
    f[sp.coordinate] += -sp.stiffness * (s.q[sp.coordinate] - sp.rest_length) - sp.viscosity * s.qdot[sp.coordinate];
}

double SpringGeneralizedForceTerm::potentialEnergy(const Model&, const State& s, const TermContext&) const {
  double V = 0.0;
  for (const Spring& sp : springs_) {
    const double d = s.q[sp.coordinate] - sp.rest_length;
    V += 0.5 * sp.stiffness * d * d;
  }
  return V;
}

// ---------------------------------------------------------------------------------------------

PointToPointSpringTerm::PointToPointSpringTerm(const Model& model, std::vector<Spring> springs)
    : springs_(std::move(springs)) {
  for (const Spring& sp : springs_) {
    const std::string what = "PointToPointSpring '" + sp.name + "'";
    for (int b : {sp.body1, sp.body2})
      if (b < -1 || b >= model.nb())
        throw ModelError(what + ": body index " + std::to_string(b) + " outside the model");
    if (sp.body1 == sp.body2) throw ModelError(what + ": body1 and body2 are the same body");
    checkNonNegative(what, "stiffness", sp.stiffness);
    checkNonNegative(what, "rest_length", sp.rest_length);
    if (!sp.point1.allFinite() || !sp.point2.allFinite()) throw ModelError(what + ": points must be finite");
  }
}

double PointToPointSpringTerm::length(const SkeletonWorkspace& sk, int k) const {
  const Spring& sp = springs_[static_cast<size_t>(k)];
  return (worldPoint(sk, sp.body2, sp.point2) - worldPoint(sk, sp.body1, sp.point1)).norm();
}

void PointToPointSpringTerm::addForce(const Model& model, const State&, const TermContext& ctx, VecX& f) const {
  for (const Spring& sp : springs_) {
    const Vec3 d = worldPoint(ctx.sk, sp.body2, sp.point2) - worldPoint(ctx.sk, sp.body1, sp.point1);
    const double L = d.norm();
    if (!(L > 0.0)) continue;  // coincident points: no direction, no force (as Simbody)
    const Vec3 F1 = sp.stiffness * (L - sp.rest_length) * (d / L);  // on point 1, towards point 2
    addPointForce(model, ctx.sk, sp.body1, sp.point1, F1, f);
    addPointForce(model, ctx.sk, sp.body2, sp.point2, -F1, f);
  }
}

double PointToPointSpringTerm::potentialEnergy(const Model&, const State&, const TermContext& ctx) const {
  double V = 0.0;
  for (size_t k = 0; k < springs_.size(); ++k) {
    const double e = length(ctx.sk, static_cast<int>(k)) - springs_[k].rest_length;
    V += 0.5 * springs_[k].stiffness * e * e;
  }
  return V;
}

// ---------------------------------------------------------------------------------------------

namespace {

// pose and twist (world angular velocity, world velocity of a body station) of a body; ground
// at rest at the identity
Mat4 poseOf(const SkeletonWorkspace& sk, int body) { return body < 0 ? Mat4(Mat4::Identity()) : sk.E_wi[body]; }
Vec3 omegaOf(const SkeletonWorkspace& sk, int body) {
  return body < 0 ? Vec3(Vec3::Zero()) : Vec3(sk.E_wi[body].topLeftCorner<3, 3>() * sk.phi[body].head<3>());
}
Vec3 stationVelocity(const SkeletonWorkspace& sk, int body, const Vec3& x_i) {
  if (body < 0) return Vec3::Zero();
  const Vec6& p = sk.phi[body];
  return sk.E_wi[body].topLeftCorner<3, 3>() * (p.head<3>().cross(x_i) + p.tail<3>());
}

// W(theta): w_F = W thetadot for body-fixed x-y-z angles (R = Rx(a) Ry(b) Rz(c))
Mat3 bodyXYZRateMatrix(const Vec3& t) {
  const double ca = std::cos(t[0]), sa = std::sin(t[0]), cb = std::cos(t[1]), sb = std::sin(t[1]);
  Mat3 W;
  W << 1, 0, sb, 0, ca, -sa * cb, 0, sa, ca * cb;
  return W;
}

}  // namespace

BushingForceTerm::BushingForceTerm(const Model& model, std::vector<Bushing> bushings) : bushings_(std::move(bushings)) {
  for (const Bushing& b : bushings_) {
    const std::string what = "BushingForce '" + b.name + "'";
    for (int x : {b.body1, b.body2})
      if (x < -1 || x >= model.nb()) throw ModelError(what + ": body index " + std::to_string(x) + " outside the model");
    if (b.body1 == b.body2) throw ModelError(what + ": frame1 and frame2 are fixed to the same body");
    for (int i = 0; i < 6; ++i) {
      checkNonNegative(what, "stiffness", b.stiffness[i]);
      checkNonNegative(what, "damping", b.damping[i]);
    }
  }
}

void BushingForceTerm::calcDeflection(const SkeletonWorkspace& sk, int k, Vec6& q, Vec6* qdot) const {
  const Bushing& b = bushings_[static_cast<size_t>(k)];
  const Mat4 X_GF = poseOf(sk, b.body1) * b.X_1F, X_GM = poseOf(sk, b.body2) * b.X_2M;
  const Mat3 R_GF = X_GF.topLeftCorner<3, 3>();
  const Mat3 R = R_GF.transpose() * X_GM.topLeftCorner<3, 3>();  // R_FM
  const Vec3 d = X_GM.topRightCorner<3, 1>() - X_GF.topRightCorner<3, 1>();
  // body-fixed x-y-z angles of R_FM (Simbody's convertRotationToBodyFixedXYZ)
  q[1] = std::asin(std::clamp(R(0, 2), -1.0, 1.0));
  q[0] = std::atan2(-R(1, 2), R(2, 2));
  q[2] = std::atan2(-R(0, 1), R(0, 0));
  q.tail<3>() = R_GF.transpose() * d;
  if (!qdot) return;
  const Vec3 w1 = omegaOf(sk, b.body1), w2 = omegaOf(sk, b.body2);
  const Vec3 vF = stationVelocity(sk, b.body1, b.X_1F.topRightCorner<3, 1>());
  const Vec3 vM = stationVelocity(sk, b.body2, b.X_2M.topRightCorner<3, 1>());
  qdot->head<3>() = bodyXYZRateMatrix(q.head<3>()).inverse() * (R_GF.transpose() * (w2 - w1));
  // d/dt (R_GF^T d) = R_GF^T (ddot - w1 x d)
  qdot->tail<3>() = R_GF.transpose() * (vM - vF - w1.cross(d));
}

void BushingForceTerm::addForce(const Model& model, const State&, const TermContext& ctx, VecX& f) const {
  const SkeletonWorkspace& sk = ctx.sk;
  for (size_t k = 0; k < bushings_.size(); ++k) {
    const Bushing& b = bushings_[k];
    Vec6 q, qdot;
    calcDeflection(sk, static_cast<int>(k), q, &qdot);
    const Vec6 g = -(b.stiffness.cwiseProduct(q) + b.damping.cwiseProduct(qdot));
    const Mat4 X_GF = poseOf(sk, b.body1) * b.X_1F, X_GM = poseOf(sk, b.body2) * b.X_2M;
    const Mat3 R_GF = X_GF.topLeftCorner<3, 3>();
    const Vec3 d = X_GM.topRightCorner<3, 1>() - X_GF.topRightCorner<3, 1>();
    // the wrenches whose power is g . qdot: a torque tau on body 2 and -tau on body 1 for the
    // angles; F at M's origin on body 2, -F at F's origin on body 1 and -(d x F) on body 1 for
    // the position (from qdot above)
    const Vec3 tau = R_GF * (bodyXYZRateMatrix(q.head<3>()).inverse().transpose() * g.head<3>());
    const Vec3 F = R_GF * g.tail<3>();
    addBodyTorque(model, sk, b.body2, tau, f);
    addBodyTorque(model, sk, b.body1, -tau - d.cross(F), f);
    addPointForce(model, sk, b.body2, b.X_2M.topRightCorner<3, 1>(), F, f);
    addPointForce(model, sk, b.body1, b.X_1F.topRightCorner<3, 1>(), -F, f);
  }
}

double BushingForceTerm::potentialEnergy(const Model&, const State&, const TermContext& ctx) const {
  double V = 0.0;
  for (size_t k = 0; k < bushings_.size(); ++k) {
    Vec6 q;
    calcDeflection(ctx.sk, static_cast<int>(k), q, nullptr);
    V += 0.5 * bushings_[k].stiffness.dot(q.cwiseProduct(q));
  }
  return V;
}

}  // namespace redmax
