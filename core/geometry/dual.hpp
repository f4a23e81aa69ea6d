#pragma once
// Forward-mode dual numbers for the wrap geometry (core/geometry/) and the smooth wrap model
// (core/muscles/wrap/smooth.cpp): x = a + b eps with eps^2 = 0. Nesting Dual<Dual<double>> gives
// a second (mixed) directional derivative in b.b: with a.b seeded by a velocity and b.a by an
// input direction, b.a is the partial derivative along that direction and b.b its time derivative
// along the velocity. The elementary functions (dsqrt, dsin, ...) and the 3-vector V3<T> work on
// double and, recursively, on duals, so one function template serves the value and its
// derivatives; with T = double they are plain arithmetic.
#include <array>
#include <cmath>

#include "core/spatial/types.hpp"

namespace redmax::detail {

template <class T>
struct Dual {
  T a{}, b{};
  Dual() = default;
  Dual(double v) : a(v), b(0.0) {}  // a constant
  Dual(const T& a_, const T& b_) : a(a_), b(b_) {}
};

inline double value(double x) { return x; }
template <class T>
double value(const Dual<T>& x) { return value(x.a); }

template <class T> Dual<T> operator+(const Dual<T>& x, const Dual<T>& y) { return {x.a + y.a, x.b + y.b}; }
template <class T> Dual<T> operator-(const Dual<T>& x, const Dual<T>& y) { return {x.a - y.a, x.b - y.b}; }
template <class T> Dual<T> operator-(const Dual<T>& x) { return {-x.a, -x.b}; }
template <class T> Dual<T> operator*(const Dual<T>& x, const Dual<T>& y) { return {x.a * y.a, x.a * y.b + x.b * y.a}; }
template <class T> Dual<T> operator/(const Dual<T>& x, const Dual<T>& y) {
  const T inv = 1.0 / y.a;
  const T q = x.a * inv;
  return {q, (x.b - q * y.b) * inv};
}
template <class T> Dual<T> operator+(const Dual<T>& x, double y) { return {x.a + y, x.b}; }
template <class T> Dual<T> operator+(double y, const Dual<T>& x) { return {x.a + y, x.b}; }
template <class T> Dual<T> operator-(const Dual<T>& x, double y) { return {x.a - y, x.b}; }
template <class T> Dual<T> operator-(double y, const Dual<T>& x) { return {y - x.a, -x.b}; }
template <class T> Dual<T> operator*(const Dual<T>& x, double y) { return {x.a * y, x.b * y}; }
template <class T> Dual<T> operator*(double y, const Dual<T>& x) { return {x.a * y, x.b * y}; }
template <class T> Dual<T> operator/(const Dual<T>& x, double y) { return {x.a / y, x.b / y}; }
template <class T> Dual<T> operator/(double y, const Dual<T>& x) { return Dual<T>{T(y), T(0.0)} / x; }

// elementary functions for double and, recursively, for duals
inline double dsqrt(double x) { return std::sqrt(x); }
inline double dsin(double x) { return std::sin(x); }
inline double dcos(double x) { return std::cos(x); }
inline double dacos(double x) { return std::acos(x); }
inline double dasin(double x) { return std::asin(x); }
inline double datan2(double y, double x) { return std::atan2(y, x); }
template <class T> Dual<T> dsqrt(const Dual<T>& x) {
  const T s = dsqrt(x.a);
  return {s, x.b / (2.0 * s)};
}
template <class T> Dual<T> dsin(const Dual<T>& x) { return {dsin(x.a), dcos(x.a) * x.b}; }
template <class T> Dual<T> dcos(const Dual<T>& x) { return {dcos(x.a), -(dsin(x.a) * x.b)}; }
template <class T> Dual<T> dacos(const Dual<T>& x) { return {dacos(x.a), -(x.b / dsqrt(1.0 - x.a * x.a))}; }
template <class T> Dual<T> dasin(const Dual<T>& x) { return {dasin(x.a), x.b / dsqrt(1.0 - x.a * x.a)}; }
template <class T> Dual<T> datan2(const Dual<T>& y, const Dual<T>& x) {
  return {datan2(y.a, x.a), (x.a * y.b - y.a * x.b) / (x.a * x.a + y.a * y.a)};
}

// 3-vectors of any scalar
template <class T> using V3 = std::array<T, 3>;
template <class T> V3<T> operator+(const V3<T>& u, const V3<T>& v) { return {u[0] + v[0], u[1] + v[1], u[2] + v[2]}; }
template <class T> V3<T> operator-(const V3<T>& u, const V3<T>& v) { return {u[0] - v[0], u[1] - v[1], u[2] - v[2]}; }
template <class T, class S> V3<T> operator*(const S& s, const V3<T>& v) { return {s * v[0], s * v[1], s * v[2]}; }
template <class T> T dot(const V3<T>& u, const V3<T>& v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; }
template <class T> V3<T> cross(const V3<T>& u, const V3<T>& v) {
  return {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
}
template <class T> T norm(const V3<T>& v) { return dsqrt(dot(v, v)); }
template <class T> V3<T> normalize(const V3<T>& v) {
  const T n = norm(v);
  return (1.0 / n) * v;
}
template <class T> Vec3 values(const V3<T>& v) { return Vec3(value(v[0]), value(v[1]), value(v[2])); }
template <class T> V3<T> constant(const Vec3& v) { return {T(v[0]), T(v[1]), T(v[2])}; }
template <class T> V3<T> zAxis() { return {T(0.0), T(0.0), T(1.0)}; }

// rotation of v by angle phi about the unit axis k (Rodrigues)
template <class T> V3<T> rotate(const V3<T>& k, const T& phi, const V3<T>& v) {
  const T c = dcos(phi), s = dsin(phi);
  return c * v + s * cross(k, v) + (dot(k, v) * (1.0 - c)) * k;
}

}  // namespace redmax::detail
