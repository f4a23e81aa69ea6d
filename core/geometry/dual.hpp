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

// Jet<N>: value v, its time derivative t along a velocity, N partial derivatives g and their time
// derivatives gt, all carried in one pass. It holds what N passes of Dual<Dual<double>> (one per
// input direction, each seeded with the same velocity) hold, without recomputing the value and
// its time derivative in every pass, so that J (3 x N) and Jdot come out of one evaluation
// (the smooth wrap model, core/muscles/wrap/smooth.cpp). Elementary functions by their closed
// first and second derivatives.
template <int N>
struct Jet {
  double v = 0.0, t = 0.0;
  std::array<double, N> g{}, gt{};
  Jet() = default;
  Jet(double x) : v(x) {}  // a constant
};

template <int N> double value(const Jet<N>& x) { return x.v; }

namespace jet_impl {
// f(x) from f(v), f'(v), f''(v): the chain rule to second (mixed) order
template <int N> Jet<N> chain(const Jet<N>& x, double f, double fp, double fpp) {
  Jet<N> y;
  y.v = f;
  y.t = fp * x.t;
  const double c = fpp * x.t;
  for (int i = 0; i < N; ++i) {
    y.g[i] = fp * x.g[i];
    y.gt[i] = fp * x.gt[i] + c * x.g[i];
  }
  return y;
}
}  // namespace jet_impl

template <int N> Jet<N> operator+(const Jet<N>& x, const Jet<N>& y) {
  Jet<N> z;
  z.v = x.v + y.v;
  z.t = x.t + y.t;
  for (int i = 0; i < N; ++i) z.g[i] = x.g[i] + y.g[i], z.gt[i] = x.gt[i] + y.gt[i];
  return z;
}
template <int N> Jet<N> operator-(const Jet<N>& x, const Jet<N>& y) {
  Jet<N> z;
  z.v = x.v - y.v;
  z.t = x.t - y.t;
  for (int i = 0; i < N; ++i) z.g[i] = x.g[i] - y.g[i], z.gt[i] = x.gt[i] - y.gt[i];
  return z;
}
template <int N> Jet<N> operator*(const Jet<N>& x, double s) {
  Jet<N> z;
  z.v = x.v * s;
  z.t = x.t * s;
  for (int i = 0; i < N; ++i) z.g[i] = x.g[i] * s, z.gt[i] = x.gt[i] * s;
  return z;
}
template <int N> Jet<N> operator*(double s, const Jet<N>& x) { return x * s; }
template <int N> Jet<N> operator-(const Jet<N>& x) { return x * -1.0; }
template <int N> Jet<N> operator+(const Jet<N>& x, double y) {
  Jet<N> z = x;
  z.v += y;
  return z;
}
template <int N> Jet<N> operator+(double y, const Jet<N>& x) { return x + y; }
template <int N> Jet<N> operator-(const Jet<N>& x, double y) { return x + (-y); }
template <int N> Jet<N> operator-(double y, const Jet<N>& x) { return (-x) + y; }
template <int N> Jet<N> operator/(const Jet<N>& x, double y) {
  Jet<N> z;  // divided, not multiplied by 1 / y: values bit for bit those of Dual (same branch choices)
  z.v = x.v / y;
  z.t = x.t / y;
  for (int i = 0; i < N; ++i) z.g[i] = x.g[i] / y, z.gt[i] = x.gt[i] / y;
  return z;
}
template <int N> Jet<N> operator*(const Jet<N>& x, const Jet<N>& y) {
  Jet<N> z;
  z.v = x.v * y.v;
  z.t = x.v * y.t + x.t * y.v;
  for (int i = 0; i < N; ++i) {
    z.g[i] = x.v * y.g[i] + x.g[i] * y.v;
    z.gt[i] = (x.v * y.gt[i] + x.t * y.g[i]) + (x.g[i] * y.t + x.gt[i] * y.v);
  }
  return z;
}
template <int N> Jet<N> operator/(const Jet<N>& x, const Jet<N>& y) {
  const double inv = 1.0 / y.v;
  Jet<N> q;
  q.v = x.v * inv;
  q.t = (x.t - q.v * y.t) * inv;
  for (int i = 0; i < N; ++i) {
    q.g[i] = (x.g[i] - q.v * y.g[i]) * inv;
    q.gt[i] = (x.gt[i] - q.t * y.g[i] - q.v * y.gt[i] - q.g[i] * y.t) * inv;
  }
  return q;
}
template <int N> Jet<N> operator/(double s, const Jet<N>& y) {
  const double q = s * (1.0 / y.v);  // s / y as Dual computes it; f' = -q / y, f'' = 2 q / y^2
  return jet_impl::chain(y, q, -q / y.v, 2.0 * q / (y.v * y.v));
}

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

template <int N> Jet<N> dsqrt(const Jet<N>& x) {
  const double s = std::sqrt(x.v);
  return jet_impl::chain(x, s, 0.5 / s, -0.25 / (s * x.v));
}
template <int N> Jet<N> dsin(const Jet<N>& x) {
  const double s = std::sin(x.v), c = std::cos(x.v);
  return jet_impl::chain(x, s, c, -s);
}
template <int N> Jet<N> dcos(const Jet<N>& x) {
  const double s = std::sin(x.v), c = std::cos(x.v);
  return jet_impl::chain(x, c, -s, -c);
}
template <int N> Jet<N> dasin(const Jet<N>& x) {
  const double r = 1.0 / std::sqrt(1.0 - x.v * x.v);
  return jet_impl::chain(x, std::asin(x.v), r, x.v * r * r * r);
}
template <int N> Jet<N> dacos(const Jet<N>& x) {
  const double r = 1.0 / std::sqrt(1.0 - x.v * x.v);
  return jet_impl::chain(x, std::acos(x.v), -r, -x.v * r * r * r);
}
template <int N> Jet<N> datan2(const Jet<N>& y, const Jet<N>& x) {
  // partials of atan2(y, x) and their second derivatives, d = x^2 + y^2
  const double d = x.v * x.v + y.v * y.v, d2 = d * d;
  const double fy = x.v / d, fx = -y.v / d;
  const double fxx = 2.0 * x.v * y.v / d2, fyy = -fxx, fxy = (y.v * y.v - x.v * x.v) / d2;
  const double cx = fxx * x.t + fxy * y.t, cy = fxy * x.t + fyy * y.t;
  Jet<N> z;
  z.v = std::atan2(y.v, x.v);
  z.t = fx * x.t + fy * y.t;
  for (int i = 0; i < N; ++i) {
    z.g[i] = fx * x.g[i] + fy * y.g[i];
    z.gt[i] = fx * x.gt[i] + fy * y.gt[i] + cx * x.g[i] + cy * y.g[i];
  }
  return z;
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
