#pragma once
// Musculotendon paths as plain data [D Sec. 5.1, 5.3]: an ordered list of path points from the
// origin (first) through via points to the insertion (last). Algorithms that evaluate a path live
// in core/muscles/path_kinematics.hpp; this header only describes it.
//
// Point kinds (OpenSim's GeometryPath, docs/opensim_compatibility.md §6):
//   Fixed        a location fixed in a body frame (or the world, body = -1).
//   Conditional  a Fixed point that belongs to the path only while its coordinate q_k satisfies
//                lo - 1e-5 <= q_k <= hi + 1e-5 (inclusive, OpenSim's tolerance). Without a
//                coordinate (coordinate = -1) it is never active.
//   Moving       each location component is a function of one coordinate, x_b = f(q_k), in the
//                body frame; a component without a function keeps `location`'s value. Its velocity
//                gains a term through q_k, so J_xr gets a column that does not go through J_mr.
//   Node         a free node of a deformable body (core/deformable/, a muscle inserting on soft
//                tissue): its world position is the three System coordinates q[coordinate ..
//                coordinate + 2] (extra coordinates after q_r, System::addExtraCoordinates), so
//                J_xr is the identity in those three columns and Jdot_xr = 0 [D Eq. 4.92]; no J_xm
//                block (no body). Not combined with wrap objects (validatePath refuses).
// Path types (docs/design.md §2): I = two fixed points, III = any wrap object, II = everything else.
// Wrap objects: `wraps` lists the path's PathWraps (surface, body, pose, range) in OpenSim's
// order; core/muscles/wrap/wrap_path.hpp computes the wrapped path. `num_wraps` marks Type III
// paths (it equals wraps.size() when the converter fills both; a path may carry only the count).
//
// Conditional switching: when a conditional point becomes active or inactive the set of path
// points changes, so the polyline changes. The mass points keep their material coordinate (arc
// fraction alpha), so
//   - their positions are continuous across the switch only if, at the switching configuration,
//     the conditional point lies on the segment joining its active neighbours; otherwise they jump
//     by up to the point's distance from that segment (OpenSim places such points close to, but not
//     exactly on, that segment);
//   - their Jacobian J_ar always jumps (the point set and the segment directions change);
//   - so the kinetic and gravitational energy of the mass points jumps at a switch, and no
//     integrator can remove that. tests/core/muscles/conditional_switch_test.cpp measures the size.
// Even without switching, a Type II mass point that slides past a via point changes velocity
// direction abruptly (the polyline has a corner), so J_ar is continuous in q only between such
// passages; its kinetic energy is continuous there only when the via point is fixed in the world.
#include <array>
#include <string>
#include <vector>

#include "core/joints/functions.hpp"
#include "core/geometry/wrap_surface.hpp"
#include "core/skeleton/model.hpp"

namespace redmax {

enum class PathPointKind { Fixed, Conditional, Moving, Node };

/// One path point. Frames: `location` and the moving functions are in the frame of body `body`
/// (the OpenSim body frame), or in the world when body = -1.
struct PathPoint {
  std::string name;
  PathPointKind kind = PathPointKind::Fixed;
  int body = -1;                      // body index, -1 = world (and for Node points)
  Vec3 location = Vec3::Zero();       // body frame; Moving: used for components without a function

  // Conditional: the tested coordinate (reduced index into q, -1 = none: never active) and range.
  // Moving: the driving coordinate (-1 = none: functions evaluated at 0).
  // Node: the first of the node's three coordinates in the System's q (>= the model's nr).
  int coordinate = -1;
  double range_lo = 0.0;              // Conditional only, radians or metres
  double range_hi = 0.0;

  // Moving only: x, y, z component functions of q_coordinate (null = constant location[k]); each
  // takes one argument, or none (a constant), as core/joints/functions.hpp's AxisFunction
  std::array<AxisFunctionPtr, 3> functions;
  // Moving only: evaluate the functions at clamp(q, clamp_lo, clamp_hi) (OpenSim clamps moving
  // points to the coordinate's range). The derivatives are those of the clamped map (zero outside
  // the range), i.e. exact; OpenSim instead differentiates at the unclamped q.
  bool clamp = false;
  double clamp_lo = 0.0;
  double clamp_hi = 0.0;
};

/// A fixed point in body `body` (-1 = world), location in that body's frame.
PathPoint makeFixedPoint(int body, const Vec3& location, std::string name = "");
/// A conditional point, active iff lo - 1e-5 <= q[coordinate] <= hi + 1e-5.
PathPoint makeConditionalPoint(int body, const Vec3& location, int coordinate, double lo, double hi,
                               std::string name = "");
/// A moving point whose x, y, z components are f(q[coordinate]); null functions keep `location`.
PathPoint makeMovingPoint(int body, int coordinate, std::array<AxisFunctionPtr, 3> functions,
                          const Vec3& location = Vec3::Zero(), std::string name = "");

/// A free deformable node whose world position is q[coordinate .. coordinate + 2] (coordinate: the
/// first of its three extra coordinates in the System; DeformableTerm::nodes() gives it).
PathPoint makeNodePoint(int coordinate, std::string name = "");
/// The point's position in the world when it does not depend on a body: a Node point's three
/// coordinates of q (ModelError naming the point when q is too short), else its location.
Vec3 nodeOrWorldPosition(const PathPoint& p, const VecX& q);

/// OpenSim's activity tolerance of conditional path points (docs/opensim_compatibility.md §6)
inline constexpr double kConditionalTolerance = 1e-5;

/// true if the point is in the path at configuration q (Fixed and Moving: always)
bool isPathPointActive(const PathPoint& p, const VecX& q);

/// One wrap object on a path (OpenSim PathWrap + the WrapObject it names). The surface frame s
/// has pose E_bs in body `body` (-1 = world): x_b = E_bs * x_s.
struct PathWrap {
  std::string name;                   // the WrapObject's name
  WrapSurface surface;
  int body = -1;
  Mat4 E_bs = Mat4::Identity();
  WrapMethod method = WrapMethod::Hybrid;
  // OpenSim's 1-based range into `points` (all points, active or not); < 1 = first / last point
  int range_begin = -1;
  int range_end = -1;
};

/// Ordered path points (origin first, insertion last) plus the wrap objects.
struct MusclePath {
  std::vector<PathPoint> points;
  int num_wraps = 0;                  // wrap objects on the path (Type III when > 0)
  std::vector<PathWrap> wraps;        // the wrap objects themselves, in PathWrapSet order
};

/// true when some point of `path` is a Node point (the path then moves with extra coordinates)
bool hasNodePoints(const MusclePath& path);

enum class PathType { I, II, III };
/// I: exactly two fixed points and no wraps; III: any wrap; II otherwise
PathType pathType(const MusclePath& path);
/// "I", "II" or "III"
const char* pathTypeName(PathType t);

/// The indices of the points of `path` active at q (isPathPointActive), in path order, into `active`
/// (cleared first; its capacity is kept, so per-frame callers do not allocate)
void activePathPoints(const MusclePath& path, const VecX& q, std::vector<int>& active);

/// Throws ModelError, naming `muscle_name` and the point, when the path does not fit `model`: fewer
/// than two points, a body or coordinate index out of range, a conditional origin or insertion
/// (the path could lose its ends), a conditional range with lo > hi, non-finite locations, a
/// moving-point function of more than one argument, a Node point whose coordinate is not after the
/// model's nr, a Node point on a path with wrap objects.
void validatePath(const Model& model, const MusclePath& path, const std::string& muscle_name);

}  // namespace redmax
