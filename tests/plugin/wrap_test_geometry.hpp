#pragma once
// Test geometry shared by the plugin tests: the pose of a wrap surface that a given straight segment
// wraps (tests/plugin/general_path_map_test.cpp and muscle_inertia_test.cpp,
// tests/opensim_matter/matter_muscle_inertia_test.cpp).
#include <cmath>

#include "core/spatial/se3.hpp"

namespace redmax::test {

/// world pose E_ws of a surface of radius 0.03 m that the segment a -> b (world, m) wraps. The
/// centre is 0.012 m (0.4 radius) off the segment's midpoint along o = unit(u x side) (u the
/// segment's direction), so the line passes at 0.4 radius from the centre or axis (through them,
/// round-off would pick the side of the wrap); the axis z is o x u tilted 0.3 rad towards the
/// line, so the ends lie at different heights (a line exactly across the axis keeps the path in one
/// plane, where the smooth cylinder's J disagrees with differences of its own positions); the frame
/// is then turned by `turn` rad about z.
inline Mat4 surfacePoseAcross(const Vec3& a, const Vec3& b, const Vec3& side, double turn) {
  const Vec3 u = (b - a).normalized();
  const Vec3 o = u.cross(side).normalized();
  const Vec3 z = std::cos(0.3) * o.cross(u) + std::sin(0.3) * u;
  Mat3 R0;
  R0 << o, z.cross(o), z;  // right-handed
  Mat4 E = Mat4::Identity();
  E.topLeftCorner<3, 3>() = R0 * expSO3(Vec3(0.0, 0.0, turn));
  E.topRightCorner<3, 1>() = 0.5 * (a + b) + 0.012 * o;
  return E;
}

}  // namespace redmax::test
