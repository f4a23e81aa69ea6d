// The dual numbers of core/geometry/dual.hpp: first derivatives of the elementary functions and
// of vector expressions against closed forms, and the nested dual's mixed second derivative.
#include <gtest/gtest.h>

#include <cmath>

#include "core/geometry/dual.hpp"

namespace redmax::detail {
namespace {

using D = Dual<double>;
using D2 = Dual<Dual<double>>;

TEST(Dual, ElementaryFunctionDerivatives) {
  const double x = 0.37;
  const D dx{x, 1.0};
  EXPECT_NEAR(dsqrt(dx).b, 0.5 / std::sqrt(x), 1e-15);
  EXPECT_NEAR(dsin(dx).b, std::cos(x), 1e-15);
  EXPECT_NEAR(dcos(dx).b, -std::sin(x), 1e-15);
  EXPECT_NEAR(dacos(dx).b, -1.0 / std::sqrt(1.0 - x * x), 1e-15);
  EXPECT_NEAR(dasin(dx).b, 1.0 / std::sqrt(1.0 - x * x), 1e-15);
  const D y{0.8, 0.0};
  // d/dx atan2(y, x) = -y / (x^2 + y^2); d/dy = x / (x^2 + y^2)
  EXPECT_NEAR(datan2(y, dx).b, -0.8 / (x * x + 0.64), 1e-15);
  EXPECT_NEAR(datan2(D{0.8, 1.0}, D{x, 0.0}).b, x / (x * x + 0.64), 1e-15);
  EXPECT_NEAR((dx / (2.0 + dx)).b, 2.0 / ((2.0 + x) * (2.0 + x)), 1e-15);
  EXPECT_EQ(value(dx * dx), x * x);
}

TEST(Dual, NestedDualGivesTheMixedSecondDerivative) {
  // f(x, y) = x^2 sin(y): b.a = df/dx along e_x, a.b = df/dy along the "velocity" e_y,
  // b.b = d2f / dx dy = 2 x cos(y)
  const double x = 1.3, y = 0.4;
  const D2 X{D{x, 0.0}, D{1.0, 0.0}};
  const D2 Y{D{y, 1.0}, D{0.0, 0.0}};
  const D2 f = X * X * dsin(Y);
  EXPECT_NEAR(f.a.a, x * x * std::sin(y), 1e-15);
  EXPECT_NEAR(f.b.a, 2.0 * x * std::sin(y), 1e-15);
  EXPECT_NEAR(f.a.b, x * x * std::cos(y), 1e-15);
  EXPECT_NEAR(f.b.b, 2.0 * x * std::cos(y), 1e-15);
}

TEST(Dual, VectorsAndRotation) {
  // |v| along v's own direction grows at rate 1; a rotation by phi about z moves (1, 0, 0) at
  // (0, 1, 0) per radian at phi = 0
  const V3<D> v{D{3.0, 0.6}, D{4.0, 0.8}, D{0.0, 0.0}};
  EXPECT_NEAR(norm(v).a, 5.0, 1e-15);
  EXPECT_NEAR(norm(v).b, 1.0, 1e-15);
  const V3<D> r = rotate(zAxis<D>(), D{0.0, 1.0}, constant<D>(Vec3(1.0, 0.0, 0.0)));
  EXPECT_NEAR(r[0].b, 0.0, 1e-15);
  EXPECT_NEAR(r[1].b, 1.0, 1e-15);
  EXPECT_EQ(values(cross(constant<double>(Vec3::UnitX()), constant<double>(Vec3::UnitY()))), Vec3::UnitZ());
}

}  // namespace
}  // namespace redmax::detail
