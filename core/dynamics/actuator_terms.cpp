#include "core/dynamics/actuator_terms.hpp"

#include <cmath>

#include "core/dynamics/body_loads.hpp"

namespace redmax {

namespace {

void checkBody(const Model& model, const std::string& what, int body, bool ground_allowed) {
  if (body >= model.nb() || body < (ground_allowed ? -1 : 0))
    throw ModelError(what + ": body index " + std::to_string(body) + " outside the model's " +
                     std::to_string(model.nb()) + " bodies");
}

// SimTK::UnitVec3 of a vector that must be usable as a direction
Vec3 unit(const std::string& what, const Vec3& v) {
  const double n = v.norm();
  if (!(n > 0.0) || !std::isfinite(n)) throw ModelError(what + " must be a non-zero, finite vector");
  return v / n;
}

template <class A>
std::vector<std::string> namesOf(const std::vector<A>& actuators) {
  std::vector<std::string> names;
  for (const A& a : actuators) names.push_back(a.name);
  return names;
}

}  // namespace

PointActuatorTerm::PointActuatorTerm(const Model& model, std::vector<Actuator> actuators)
    : actuators_(std::move(actuators)) {
  for (Actuator& a : actuators_) {
    checkBody(model, "PointActuator '" + a.name + "'", a.body, false);
    a.direction = unit("PointActuator '" + a.name + "': direction", a.direction);
    if (!a.point.allFinite()) throw ModelError("PointActuator '" + a.name + "': point is not finite");
  }
}

void PointActuatorTerm::calcPointAndDirection(const SkeletonWorkspace& sk, int k, Vec3& point_i,
                                              Vec3& direction_w) const {
  const Actuator& a = actuators_[static_cast<size_t>(k)];
  const Mat4& E = sk.E_wi[a.body];
  direction_w = a.force_is_global ? a.direction : Vec3(E.topLeftCorner<3, 3>() * a.direction);
  point_i = a.point_is_global ? transformPoint(inverseE(E), a.point) : a.point;
}

void PointActuatorTerm::addActuation(const Model& model, const SkeletonWorkspace& sk, int k, double force,
                                     VecX& f) const {
  Vec3 p, d;
  calcPointAndDirection(sk, k, p, d);
  addPointForce(model, sk, actuators_[static_cast<size_t>(k)].body, p, force * d, f);
}

void PointActuatorTerm::addForce(const Model& model, const State&, const TermContext& ctx, VecX& f) const {
  for (size_t k = 0; k < actuators_.size(); ++k) {
    const double u = ctx.control(static_cast<int>(k));
    if (u != 0.0) addActuation(model, ctx.sk, static_cast<int>(k), u * actuators_[k].optimal_force, f);
  }
}

std::vector<std::string> PointActuatorTerm::controlNames() const { return namesOf(actuators_); }

TorqueActuatorTerm::TorqueActuatorTerm(const Model& model, std::vector<Actuator> actuators)
    : actuators_(std::move(actuators)) {
  for (Actuator& a : actuators_) {
    checkBody(model, "TorqueActuator '" + a.name + "'", a.body_a, true);
    checkBody(model, "TorqueActuator '" + a.name + "'", a.body_b, true);
    a.axis = unit("TorqueActuator '" + a.name + "': axis", a.axis);
  }
}

Vec3 TorqueActuatorTerm::axisInWorld(const SkeletonWorkspace& sk, int k) const {
  const Actuator& a = actuators_[static_cast<size_t>(k)];
  if (a.torque_is_global || a.body_a < 0) return a.axis;
  return sk.E_wi[a.body_a].topLeftCorner<3, 3>() * a.axis;
}

void TorqueActuatorTerm::addActuation(const Model& model, const SkeletonWorkspace& sk, int k, double torque,
                                      VecX& f) const {
  const Actuator& a = actuators_[static_cast<size_t>(k)];
  const Vec3 T = torque * axisInWorld(sk, k);
  addBodyTorque(model, sk, a.body_a, T, f);
  addBodyTorque(model, sk, a.body_b, -T, f);
}

void TorqueActuatorTerm::addForce(const Model& model, const State&, const TermContext& ctx, VecX& f) const {
  for (size_t k = 0; k < actuators_.size(); ++k) {
    const double u = ctx.control(static_cast<int>(k));
    if (u != 0.0) addActuation(model, ctx.sk, static_cast<int>(k), u * actuators_[k].optimal_force, f);
  }
}

std::vector<std::string> TorqueActuatorTerm::controlNames() const { return namesOf(actuators_); }

}  // namespace redmax
