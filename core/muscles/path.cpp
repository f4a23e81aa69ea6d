#include "core/muscles/path.hpp"

#include <cmath>

namespace redmax {

namespace {

std::string pointLabel(const MusclePath& path, int k) {
  const std::string& n = path.points[k].name;
  return "path point " + std::to_string(k) + (n.empty() ? "" : " ('" + n + "')");
}

}  // namespace

PathPoint makeFixedPoint(int body, const Vec3& location, std::string name) {
  PathPoint p;
  p.name = std::move(name);
  p.kind = PathPointKind::Fixed;
  p.body = body;
  p.location = location;
  return p;
}

PathPoint makeConditionalPoint(int body, const Vec3& location, int coordinate, double lo, double hi,
                               std::string name) {
  PathPoint p = makeFixedPoint(body, location, std::move(name));
  p.kind = PathPointKind::Conditional;
  p.coordinate = coordinate;
  p.range_lo = lo;
  p.range_hi = hi;
  return p;
}

PathPoint makeMovingPoint(int body, int coordinate, std::array<AxisFunctionPtr, 3> functions,
                          const Vec3& location, std::string name) {
  PathPoint p = makeFixedPoint(body, location, std::move(name));
  p.kind = PathPointKind::Moving;
  p.coordinate = coordinate;
  p.functions = std::move(functions);
  return p;
}

PathPoint makeNodePoint(int coordinate, std::string name) {
  PathPoint p = makeFixedPoint(-1, Vec3::Zero(), std::move(name));
  p.kind = PathPointKind::Node;
  p.coordinate = coordinate;
  return p;
}

bool hasNodePoints(const MusclePath& path) {
  for (const PathPoint& p : path.points)
    if (p.kind == PathPointKind::Node) return true;
  return false;
}

Vec3 nodeOrWorldPosition(const PathPoint& p, const VecX& q) {
  if (p.kind != PathPointKind::Node) return p.location;
  if (p.coordinate < 0 || p.coordinate + 3 > q.size())
    throw ModelError("path point '" + p.name + "': node coordinates " + std::to_string(p.coordinate) + ".." +
                     std::to_string(p.coordinate + 2) + " are not in the state (" + std::to_string(q.size()) +
                     " coordinates)");
  return q.segment<3>(p.coordinate);
}

bool isPathPointActive(const PathPoint& p, const VecX& q) {
  if (p.kind != PathPointKind::Conditional) return true;
  if (p.coordinate < 0) return false;  // OpenSim: an unconnected coordinate is never active
  const double v = q[p.coordinate];
  return p.range_lo - kConditionalTolerance <= v && v <= p.range_hi + kConditionalTolerance;
}

void activePathPoints(const MusclePath& path, const VecX& q, std::vector<int>& active) {
  active.clear();
  for (int k = 0; k < static_cast<int>(path.points.size()); ++k)
    if (isPathPointActive(path.points[k], q)) active.push_back(k);
}

PathType pathType(const MusclePath& path) {
  if (path.num_wraps > 0 || !path.wraps.empty()) return PathType::III;
  if (path.points.size() == 2 && path.points[0].kind == PathPointKind::Fixed &&
      path.points[1].kind == PathPointKind::Fixed)
    return PathType::I;
  return PathType::II;
}

const char* pathTypeName(PathType t) {
  switch (t) {
    case PathType::I: return "I";
    case PathType::II: return "II";
    case PathType::III: return "III";
  }
  return "?";
}

void validatePath(const Model& model, const MusclePath& path, const std::string& muscle_name) {
  const std::string who = "muscle '" + muscle_name + "': ";
  const int np = static_cast<int>(path.points.size());
  if (np < 2)
    throw ModelError(who + "a path needs at least two points (origin and insertion), got " + std::to_string(np));
  if (path.num_wraps < 0) throw ModelError(who + "negative number of wrap objects");
  for (const PathWrap& w : path.wraps) {
    const std::string where = who + "wrap object '" + w.name + "': ";
    if (w.body < -1 || w.body >= model.nb())
      throw ModelError(where + "body index " + std::to_string(w.body) + " is not a body of model '" +
                       model.name() + "' (" + std::to_string(model.nb()) + " bodies; -1 = world)");
    if (!w.E_bs.allFinite()) throw ModelError(where + "non-finite pose");
    const WrapSurface& s = w.surface;
    const bool ok = s.type == WrapType::Cylinder    ? (s.radius > 0.0 && s.length >= 0.0)
                    : s.type == WrapType::Sphere    ? s.radius > 0.0
                    : s.type == WrapType::Ellipsoid ? (s.dimensions.array() > 0.0).all()
                                                    : (s.inner_radius > 0.0 && s.outer_radius > 0.0);
    if (!ok) throw ModelError(where + "surface dimensions must be positive");
    if (s.quadrant_sign != 0 && (s.quadrant_axis < 0 || s.quadrant_axis > 2))
      throw ModelError(where + "quadrant axis must be 0, 1 or 2");
  }
  for (int k = 0; k < np; ++k) {
    const PathPoint& p = path.points[k];
    const std::string where = who + pointLabel(path, k) + ": ";
    if (p.body < -1 || p.body >= model.nb())
      throw ModelError(where + "body index " + std::to_string(p.body) + " is not a body of model '" +
                       model.name() + "' (" + std::to_string(model.nb()) + " bodies; -1 = world)");
    if (!p.location.allFinite()) throw ModelError(where + "non-finite location");
    if (p.kind == PathPointKind::Node) {
      // the node's coordinates follow q_r (System::addExtraCoordinates); the model cannot bound them
      if (p.coordinate < model.nr() || p.body != -1)
        throw ModelError(where + "a node point needs its first coordinate after the model's " +
                         std::to_string(model.nr()) + " (got " + std::to_string(p.coordinate) + ") and no body");
      if (path.num_wraps > 0 || !path.wraps.empty())
        throw ModelError(where + "node points on a path with wrap objects are not supported (the wrap "
                         "constructions take end points in a body frame)");
    }
    const bool needs_coord = p.kind == PathPointKind::Conditional || p.kind == PathPointKind::Moving;
    if (needs_coord && (p.coordinate < -1 || p.coordinate >= model.nr()))
      throw ModelError(where + "coordinate index " + std::to_string(p.coordinate) + " out of range (" +
                       std::to_string(model.nr()) + " coordinates; -1 = none)");
    if (p.kind == PathPointKind::Conditional) {
      if (k == 0 || k == np - 1)
        throw ModelError(where + "the " + std::string(k == 0 ? "origin" : "insertion") +
                         " cannot be a conditional point (the path would lose its end)");
      if (!std::isfinite(p.range_lo) || !std::isfinite(p.range_hi) || p.range_lo > p.range_hi)
        throw ModelError(where + "conditional range [" + std::to_string(p.range_lo) + ", " +
                         std::to_string(p.range_hi) + "] is not a finite interval with lo <= hi");
    }
    if (p.kind == PathPointKind::Moving && p.clamp &&
        (!std::isfinite(p.clamp_lo) || !std::isfinite(p.clamp_hi) || p.clamp_lo > p.clamp_hi))
      throw ModelError(where + "moving-point clamp range is not a finite interval with lo <= hi");
    if (p.kind == PathPointKind::Moving)
      for (int c = 0; c < 3; ++c)
        if (p.functions[c] && p.functions[c]->numArgs() > 1)
          throw ModelError(where + "moving-point " + "xyz"[c] + " function (" + p.functions[c]->typeName() +
                           ") takes " + std::to_string(p.functions[c]->numArgs()) +
                           " arguments; a path point depends on one coordinate");
  }
}

}  // namespace redmax
