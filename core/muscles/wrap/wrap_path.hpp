#pragma once
// A whole musculotendon path with wrap objects, as OpenSim's GeometryPath computes it
// (computePath + applyWrapObjects + calcLengthAfterPathComputation; docs/opensim_compatibility.md §6):
//   1. the active path points, in order;
//   2. each PathWrap in order: its previous tangent points are removed; every segment of the
//      current path between the first active point at/after range_begin and the last active point
//      at/before range_end is tried (except a segment joining the two tangent points of one
//      surface); the first MandatoryWrap wins at once, otherwise the Wrapped segment whose
//      |P1 r1| + l + |r2 P2| - |P1 P2| is smallest; the two tangent points are inserted before the
//      segment's end point;
//   3. with two or more wrap objects, up to 8 passes until the length changes by < 0.5 mm; after
//      pass 1, if object 0 gave NoWrap and object 1 InsideRadius, their order is swapped;
//   4. length = sum of straight segments, except between the two tangent points of one surface,
//      where the surface length l is added (OpenSim's sphere quirk included: l may be negative).
// OpenSim quirk, reproduced in `length`: a tangent point's ground position is cached the first
// time it is used in one evaluation (Point::getLocationInGround) and is not refreshed when a later
// pass moves the point, so from the second pass on the straight segments touching it, and the
// length changes of step 2, use its first position. Without this, subject_walk_armless's med_gas
// (two cylinders) differs from OpenSim by up to 5.6 mm; with it, by < 1e-9 m. The points in
// WrappedPath::points are the current (geometric) positions.
// Points are taken to the surface frame through the world: x_s = E_bs^-1 E_wb^-1 E_wc x_c.
#include <vector>

#include "core/muscles/path.hpp"
#include "core/geometry/wrap_surface.hpp"

namespace redmax {

/// One point of the wrapped path.
struct WrappedPathPoint {
  int point = -1;            ///< index into MusclePath::points, or -1 for a tangent point
  int wrap = -1;             ///< tangent point: index into MusclePath::wraps
  int which = 0;             ///< tangent point: 1 (r1) or 2 (r2)
  Vec3 x_w = Vec3::Zero();   ///< position in the world
};

/// The wrapped path at one configuration.
struct WrappedPath {
  std::vector<WrappedPathPoint> points;  ///< origin ... insertion, tangent points inserted
  std::vector<WrapResult> results;       ///< per wrap object (frame s); NoWrap when unused
  std::vector<bool> used;                ///< per wrap object: its tangent points are in `points`
  double length = 0.0;                   ///< total path length (m), OpenSim's definition
  /// length of the final points' straight segments and arcs (m): what calcWrappedPathPointWorld
  /// walks; differs from `length` by OpenSim's stale positions and the sphere's sign quirk
  double geometric_length = 0.0;
};

/// The wrapped path at configuration q with body poses E_wi (calcBodyPoses). A path without
/// wraps gives the polyline through the active points.
WrappedPath calcWrappedPath(const Model& model, const MusclePath& path, const VecX& q,
                            const std::vector<Mat4>& E_wi);

/// The same from the path's inputs alone: the active points `active` (indices into path.points,
/// in order) at world positions x_w, and every wrap surface's pose E_ws (world, one per
/// path.wraps). calcWrappedPath is this with the inputs taken from q and E_wi; engines that move
/// the points and surfaces themselves (core/muscles/path_map.hpp) call it. Throws
/// std::invalid_argument for sizes that do not fit or an index out of range.
WrappedPath calcWrappedPathAt(const MusclePath& path, const std::vector<int>& active, const std::vector<Vec3>& x_w,
                              const std::vector<Mat4>& E_ws);

/// The world position of the point at fraction alpha in [0, 1] of the wrapped path's geometric
/// length (straight segments and surface arcs; a sphere's negative length counts as its arc).
Vec3 calcWrappedPathPointWorld(const MusclePath& path, const WrappedPath& wp,
                               const std::vector<Mat4>& E_wi, double alpha);
/// The same with the surfaces' world poses E_ws (one per wrap object) instead of the body poses.
Vec3 calcWrappedPathPointAt(const WrappedPath& wp, const std::vector<Mat4>& E_ws, double alpha);

}  // namespace redmax
