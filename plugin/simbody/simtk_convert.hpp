#pragma once
// Conversions between redmax's Eigen types and SimTK's, header-only so that they compile against
// any Simbody (Debian's 3.7 in redmax_simbody, OpenSim's in libredmax_opensim).
#include "plugin/simbody/simbody_include.hpp"

#include "core/spatial/types.hpp"

namespace redmax::simbody {

inline SimTK::Vec3 toSimTKVec3(const Vec3& v) { return SimTK::Vec3(v.x(), v.y(), v.z()); }
inline Vec3 fromSimTKVec3(const SimTK::Vec3& v) { return Vec3(v[0], v[1], v[2]); }

/// E (4x4 homogeneous) as a SimTK::Transform; the rotation is trusted as orthonormal (to
/// round-off) instead of re-fitted. Built by the element constructor: GCC 12 reports row-by-row
/// writes into a Mat33 as out of bounds (-Warray-bounds, a false positive).
inline SimTK::Transform toTransform(const Mat4& E) {
  const SimTK::Mat33 R(E(0, 0), E(0, 1), E(0, 2), E(1, 0), E(1, 1), E(1, 2), E(2, 0), E(2, 1), E(2, 2));
  return SimTK::Transform(SimTK::Rotation(R, true), SimTK::Vec3(E(0, 3), E(1, 3), E(2, 3)));
}

}  // namespace redmax::simbody
