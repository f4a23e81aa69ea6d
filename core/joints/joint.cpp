#include "core/joints/joint.hpp"

namespace redmax {

namespace {
template <class T>
concept HasReparameterize = requires(const T& j, VecJ& q, VecJ& qd) {
  { j.reparameterize(q, qd) } -> std::convertible_to<bool>;
};
template <class T>
concept HasSingularityDistance = requires(const T& j, const VecJ& q) {
  { j.singularityDistance(q) } -> std::convertible_to<double>;
};
template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
// clang 14 has no aggregate CTAD (P1816): the guide lets the fuzz build (build-fuzz-clang) compile
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;
}  // namespace

int Joint::nq() const {
  return std::visit([](const auto& j) { return j.nq(); }, v);
}

void Joint::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  std::visit([&](const auto& j) { j.calc(q, qdot, out); }, v);
}

bool Joint::reparameterize(VecJ& q, VecJ& qdot) const {
  return std::visit(
      [&](const auto& j) -> bool {
        if constexpr (HasReparameterize<std::decay_t<decltype(j)>>) {
          return j.reparameterize(q, qdot);
        } else {
          return false;
        }
      },
      v);
}

double Joint::singularityDistance(const VecJ& q) const {
  return std::visit(
      [&](const auto& j) -> double {
        if constexpr (HasSingularityDistance<std::decay_t<decltype(j)>>) {
          return j.singularityDistance(q);
        } else {
          return 1.0;
        }
      },
      v);
}

std::string Joint::typeName() const {
  return std::visit(Overloaded{[](const Fixed&) { return std::string("fixed"); },
                               [](const Revolute&) { return std::string("revolute"); },
                               [](const Prismatic&) { return std::string("prismatic"); },
                               [](const Planar&) { return std::string("planar"); },
                               [](const Translational&) { return std::string("translational"); },
                               [](const SphericalEuler&) { return std::string("spherical_euler"); },
                               [](const Universal&) { return std::string("universal"); },
                               [](const SphericalExp&) { return std::string("spherical_exp"); },
                               [](const Composite&) { return std::string("composite"); },
                               [](const Free2D&) { return std::string("free2d"); },
                               [](const Free3D&) { return std::string("free3d"); },
                               [](const SplineCurve&) { return std::string("spline_curve"); },
                               [](const SplineSurface&) { return std::string("spline_surface"); },
                               [](const FunctionBased&) { return std::string("function_based"); },
                               [](const Ellipsoid&) { return std::string("ellipsoid"); },
                               [](const Reversed& r) { return "reversed_" + r.inner->typeName(); }},
                    v);
}

}  // namespace redmax
