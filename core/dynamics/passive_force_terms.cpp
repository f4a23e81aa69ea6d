#include "core/dynamics/passive_force_terms.hpp"

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

}  // namespace redmax
