#include "core/dynamics/contact_force_terms.hpp"

#include <algorithm>
#include <cmath>

#include "core/dynamics/body_loads.hpp"

namespace redmax {

namespace {

Mat4 surfacePose(const SkeletonWorkspace& sk, const ContactSurface& s) {
  return s.body < 0 ? s.X_body : Mat4(sk.E_wi[s.body] * s.X_body);
}

// the body-fixed point of `body` that is at world point x now: its station and world velocity
Vec3 stationAt(const SkeletonWorkspace& sk, int body, const Vec3& x_w) {
  if (body < 0) return x_w;
  const Mat4& E = sk.E_wi[body];
  return E.topLeftCorner<3, 3>().transpose() * (x_w - E.topRightCorner<3, 1>());
}
Vec3 velocityAt(const SkeletonWorkspace& sk, int body, const Vec3& station) {
  return body < 0 ? Vec3(Vec3::Zero()) : pointVelocity(sk, body, station);
}

// a force on surface 2's body at x_w and its opposite on surface 1's body
void applyPair(const Model& model, const SkeletonWorkspace& sk, int body1, int body2, const Vec3& x_w,
               const Vec3& force_on_2, VecX& f) {
  addPointForce(model, sk, body2, stationAt(sk, body2, x_w), force_on_2, f);
  addPointForce(model, sk, body1, stationAt(sk, body1, x_w), -force_on_2, f);
}

void checkSurface(const Model& model, const std::string& what, const ContactSurface& s) {
  if (s.body < -1 || s.body >= model.nb())
    throw ModelError(what + ": body index " + std::to_string(s.body) + " of '" + s.name + "' outside the model");
  if (!s.X_body.allFinite()) throw ModelError(what + ": the pose of '" + s.name + "' is not finite");
  if (s.shape == ContactShape::Sphere && !(s.radius > 0.0 && std::isfinite(s.radius)))
    throw ModelError(what + ": sphere '" + s.name + "' needs a positive finite radius");
}

void checkCoefficient(const std::string& what, const char* name, double v) {
  if (!(v >= 0.0) || !std::isfinite(v))
    throw ModelError(what + ": " + name + " must be finite and >= 0, found " + std::to_string(v));
}

// 2 u1 u2 / (u1 + u2), 0 when both are 0 (Simbody)
double combine(double u1, double u2) { return u1 + u2 > 0.0 ? 2.0 * u1 * u2 / (u1 + u2) : 0.0; }

}  // namespace

void ContactForceTerm::addForce(const Model& model, const State&, const TermContext& ctx, VecX& f) const {
  evaluate(ctx.sk, nullptr, nullptr, &model, &f);
}

double ContactForceTerm::potentialEnergy(const Model&, const State&, const TermContext& ctx) const {
  double V = 0.0;
  evaluate(ctx.sk, nullptr, &V, nullptr, nullptr);
  return V;
}

void ContactForceTerm::contacts(const SkeletonWorkspace& sk, std::vector<ContactReport>& out) const {
  evaluate(sk, &out, nullptr, nullptr, nullptr);
}

ContactSummary ContactForceTerm::summary(const SkeletonWorkspace& sk) const {
  std::vector<ContactReport> r;
  contacts(sk, r);
  ContactSummary s;
  for (const ContactReport& c : r) {
    if (!c.active) continue;
    ++s.active;
    s.max_penetration = std::max(s.max_penetration, c.penetration);
    const double rel = c.radius > 0.0 ? c.penetration / c.radius : 0.0;
    if (rel > s.max_relative || s.deepest.empty()) {
      s.max_relative = std::max(s.max_relative, rel);
      s.deepest = c.name;
    }
  }
  return s;
}

// ---------------------------------------------------------------------------------------------

double HuntCrossleyForceTerm::hertzForce(double k1, double k2, double R, double d) {
  if (!(d > 0.0)) return 0.0;
  const double a = std::pow(k1, 2.0 / 3.0), b = std::pow(k2, 2.0 / 3.0);
  const double k = a * (b / (a + b));
  return (4.0 / 3.0) * k * d * std::sqrt(R * k * d);
}

double HuntCrossleyForceTerm::frictionCoefficient(double us, double ud, double uv, double vt, double vs) {
  const double vrel = vs / vt;
  return std::min(vrel, 1.0) * (ud + 2.0 * (us - ud) / (1.0 + vrel * vrel)) + uv * vs;
}

HuntCrossleyForceTerm::HuntCrossleyForceTerm(const Model& model, std::vector<Force> forces) : forces_(std::move(forces)) {
  for (size_t fi = 0; fi < forces_.size(); ++fi) {
    const Force& F = forces_[fi];
    const std::string what = "HuntCrossleyForce '" + F.name + "'";
    if (F.materials.size() != F.surfaces.size()) throw ModelError(what + ": one material per surface is needed");
    if (!(F.transition_velocity > 0.0) || !std::isfinite(F.transition_velocity))
      throw ModelError(what + ": transition_velocity must be positive and finite");
    for (size_t i = 0; i < F.surfaces.size(); ++i) {
      checkSurface(model, what, F.surfaces[i]);
      const Material& m = F.materials[i];
      if (!(m.stiffness > 0.0) || !std::isfinite(m.stiffness))
        throw ModelError(what + ": the stiffness of '" + F.surfaces[i].name + "' must be positive and finite");
      checkCoefficient(what, "dissipation", m.dissipation);
      checkCoefficient(what, "static_friction", m.static_friction);
      checkCoefficient(what, "dynamic_friction", m.dynamic_friction);
      checkCoefficient(what, "viscous_friction", m.viscous_friction);
    }
    // every pair of the set on different bodies that Simbody has a point-contact algorithm for:
    // half-space - sphere (the half-space first) and sphere - sphere (set order)
    for (int i = 0; i < static_cast<int>(F.surfaces.size()); ++i)
      for (int j = i + 1; j < static_cast<int>(F.surfaces.size()); ++j) {
        const ContactSurface &a = F.surfaces[i], &b = F.surfaces[j];
        if (a.body == b.body) continue;
        if (a.shape == ContactShape::HalfSpace && b.shape == ContactShape::HalfSpace) continue;
        if (b.shape == ContactShape::HalfSpace)
          pairs_.push_back({static_cast<int>(fi), j, i});
        else
          pairs_.push_back({static_cast<int>(fi), i, j});
      }
  }
}

void HuntCrossleyForceTerm::evaluate(const SkeletonWorkspace& sk, std::vector<ContactReport>* out, double* V,
                                     const Model* model, VecX* f) const {
  for (const Pair& p : pairs_) {
    const Force& F = forces_[static_cast<size_t>(p.force)];
    const ContactSurface &s1 = F.surfaces[static_cast<size_t>(p.i)], &s2 = F.surfaces[static_cast<size_t>(p.j)];
    const Material &m1 = F.materials[static_cast<size_t>(p.i)], &m2 = F.materials[static_cast<size_t>(p.j)];
    const Mat4 X1 = surfacePose(sk, s1), X2 = surfacePose(sk, s2);
    const Vec3 c2 = X2.topRightCorner<3, 1>();
    // depth, normal (from 1 into 2), contact point and effective radius (Simbody's
    // CollisionDetectionAlgorithm: the point halfway through the overlap)
    double depth = 0.0, R = 0.0;
    Vec3 n, x;
    if (s1.shape == ContactShape::HalfSpace) {
      const Vec3 local = X1.topLeftCorner<3, 3>().transpose() * (c2 - X1.topRightCorner<3, 1>());
      depth = s2.radius + local[0];
      n = -X1.topLeftCorner<3, 3>().col(0);
      x = X1.topRightCorner<3, 1>() + X1.topLeftCorner<3, 3>() * Vec3(depth / 2.0, local[1], local[2]);
      R = s2.radius;
    } else {
      const Vec3 c1 = X1.topRightCorner<3, 1>();
      const Vec3 delta = c2 - c1;
      const double dist = delta.norm();
      if (!(dist > 0.0)) continue;  // concentric: no direction (as Simbody)
      depth = s1.radius + s2.radius - dist;
      n = delta / dist;
      x = c1 + (s1.radius - depth / 2.0) * n;
      R = s1.radius * s2.radius / (s1.radius + s2.radius);
    }
    const double rmin = s1.shape == ContactShape::HalfSpace ? s2.radius : std::min(s1.radius, s2.radius);
    ContactReport rep;
    rep.name = F.name + ": " + s1.name + " - " + s2.name;
    rep.penetration = depth;
    rep.radius = rmin;
    rep.body1 = s1.body;
    rep.body2 = s2.body;
    if (!(depth > 0.0)) {
      if (out) out->push_back(rep);
      continue;
    }
    rep.active = true;
    // the point moves towards the softer surface
    const double a = std::pow(m1.stiffness, 2.0 / 3.0), b = std::pow(m2.stiffness, 2.0 / 3.0);
    const double s1w = b / (a + b), s2w = 1.0 - s1w;
    x += depth * (0.5 - s1w) * n;
    const double k = a * s1w;
    const double c = m1.dissipation * s1w + m2.dissipation * s2w;
    const double fH = (4.0 / 3.0) * k * depth * std::sqrt(R * k * depth);
    if (V) *V += 0.4 * fH * depth;
    rep.point_w = x;
    rep.normal_w = n;
    rep.stiffness = 1.5 * fH / depth;
    // relative velocity of the material points at x (1 relative to 2): v_n > 0 while approaching
    const Vec3 st1 = stationAt(sk, s1.body, x), st2 = stationAt(sk, s2.body, x);
    const Vec3 v = velocityAt(sk, s1.body, st1) - velocityAt(sk, s2.body, st2);
    const double vn = v.dot(n);
    const Vec3 vt = v - vn * n;
    const double fn = fH * (1.0 + 1.5 * c * vn);
    // no pull: a separating contact whose dissipation exceeds its elastic force gives nothing
    // (Simbody leaves the loop there, dropping the contacts after it; here only this one)
    if (fn > 0.0) {
      Vec3 force = fn * n;
      const double vs = vt.norm();
      if (vs != 0.0) {
        const double us = combine(m1.static_friction, m2.static_friction);
        const double ud = combine(m1.dynamic_friction, m2.dynamic_friction);
        const double uv = combine(m1.viscous_friction, m2.viscous_friction);
        force += fn * frictionCoefficient(us, ud, uv, F.transition_velocity, vs) * (vt / vs);
      }
      rep.force_w = force;
      if (f) applyPair(*model, sk, s1.body, s2.body, x, force, *f);
    }
    if (out) out->push_back(rep);
  }
}

// ---------------------------------------------------------------------------------------------

SmoothSphereHalfSpaceForceTerm::SmoothSphereHalfSpaceForceTerm(const Model& model, std::vector<Contact> contacts)
    : contacts_(std::move(contacts)) {
  for (const Contact& c : contacts_) {
    const std::string what = "SmoothSphereHalfSpaceForce '" + c.name + "'";
    if (c.sphere.shape != ContactShape::Sphere || c.half_space.shape != ContactShape::HalfSpace)
      throw ModelError(what + ": needs a sphere and a half-space");
    checkSurface(model, what, c.sphere);
    checkSurface(model, what, c.half_space);
    if (c.sphere.body == c.half_space.body) throw ModelError(what + ": the sphere and the half-space are on one body");
    checkCoefficient(what, "stiffness", c.stiffness);
    checkCoefficient(what, "dissipation", c.dissipation);
    checkCoefficient(what, "static_friction", c.static_friction);
    checkCoefficient(what, "dynamic_friction", c.dynamic_friction);
    checkCoefficient(what, "viscous_friction", c.viscous_friction);
    checkCoefficient(what, "constant_contact_force", c.constant_contact_force);
    checkCoefficient(what, "hertz_smoothing", c.hertz_smoothing);
    checkCoefficient(what, "hunt_crossley_smoothing", c.hunt_crossley_smoothing);
    if (!(c.transition_velocity > 0.0) || !std::isfinite(c.transition_velocity))
      throw ModelError(what + ": transition_velocity must be positive and finite");
  }
}

void SmoothSphereHalfSpaceForceTerm::evaluate(const SkeletonWorkspace& sk, std::vector<ContactReport>* out,
                                              double* V, const Model* model, VecX* f) const {
  for (const Contact& c : contacts_) {
    const Mat4 Xs = surfacePose(sk, c.sphere), Xh = surfacePose(sk, c.half_space);
    const double R = c.sphere.radius;
    const Vec3 centre = Xs.topRightCorner<3, 1>();
    // the normal points into the half-space (its frame's +x)
    const Vec3 n = Xh.topLeftCorner<3, 3>().col(0);
    const double x = R - (centre - Xh.topRightCorner<3, 1>()).dot(-n);
    const Vec3 point = centre + R * n - 0.5 * x * n;
    const Vec3 st1 = stationAt(sk, c.sphere.body, point), st2 = stationAt(sk, c.half_space.body, point);
    const Vec3 v = velocityAt(sk, c.sphere.body, st1) - velocityAt(sk, c.half_space.body, st2);
    const double vn = v.dot(n);
    const Vec3 vt = v - vn * n;
    const double cf = c.constant_contact_force;
    const double k = 0.5 * std::pow(c.stiffness, 2.0 / 3.0);
    const double fh = (4.0 / 3.0) * k * std::sqrt(R * k) * std::pow(std::sqrt(x * x + cf), 1.5) *
                      (0.5 + 0.5 * std::tanh(c.hertz_smoothing * x));
    if (V) *V += 0.4 * fh * x;
    // zero dissipation: the switch 2/(3c) is infinitely far, the factor is 1
    const double sw = c.dissipation > 0.0
                          ? 0.5 + 0.5 * std::tanh(c.hunt_crossley_smoothing * (vn + 2.0 / (3.0 * c.dissipation)))
                          : 1.0;
    const double fn = fh * (1.0 + 1.5 * c.dissipation * vn) * sw;
    const double vs = std::sqrt(vt.squaredNorm() + cf);
    Vec3 force = fn * n;
    if (vs > 0.0)
      force += fn *
               HuntCrossleyForceTerm::frictionCoefficient(c.static_friction, c.dynamic_friction, c.viscous_friction,
                                                          c.transition_velocity, vs) *
               (vt / vs);
    // Simbody applies -force to the sphere and +force to the half-space
    if (f) applyPair(*model, sk, c.sphere.body, c.half_space.body, point, force, *f);
    if (out) {
      ContactReport rep;
      rep.name = c.name + ": " + c.half_space.name + " - " + c.sphere.name;
      rep.penetration = x;
      rep.radius = R;
      rep.active = x > 0.0;
      rep.point_w = point;
      rep.force_w = -force;
      // surface 1 is the half-space: the normal from it into the sphere is -n
      rep.normal_w = -n;
      rep.body1 = c.half_space.body;
      rep.body2 = c.sphere.body;
      rep.stiffness = 1.5 * fh / std::max(std::abs(x), std::sqrt(cf) + 1e-12);
      out->push_back(rep);
    }
  }
}

}  // namespace redmax
