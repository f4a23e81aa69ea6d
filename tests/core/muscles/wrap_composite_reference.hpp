#pragma once
// The exact library's path over several surfaces on one segment, converged (issue 22's reference
// for the smooth composition, core/muscles/wrap/smooth_composite.hpp): OpenSim's passes (each
// surface wrapped, calcWrap, on the segment between the previous surface's exit and the next
// surface's entry) repeated until the tangent points stop moving (1e-14 m, above its round-off), in a given order along
// the segment. Each surface as the library wraps one object (WrapOptions::single_wrap: closed-form
// tangent points; OpenSim's multi-object cylinder adds its 2 mm tangency correction, measured
// separately), the geometric path p1 -> r1 -> arc -> r2 -> ... -> p2.
#include <algorithm>
#include <vector>

#include "core/geometry/wrap_surface.hpp"
#include "core/muscles/wrap/smooth_composite.hpp"

namespace redmax::test {

struct ConvergedLibraryPath {
  bool converged = false;
  std::vector<bool> wraps;         ///< per surface (caller's order)
  std::vector<WrapResult> result;  ///< per surface (caller's order), its frame
  double length = 0.0;
  int passes = 0;
  double last_moved = 0.0;  ///< the last pass's largest move of a tangent point (m)
  std::vector<Vec3> points;  ///< p1, (r1, r2 per wrapping surface, path order), p2 (common frame)
  std::vector<int> arc_of;   ///< per piece: the surface whose arc it is, or -1 (straight)
};

inline ConvergedLibraryPath convergeLibraryPath(const std::vector<CompositeWrapSurface>& s, const std::vector<int>& order,
                                                const Vec3& p1, const Vec3& p2, int max_passes = 2000) {
  const int K = static_cast<int>(order.size());
  auto local = [&](int k, const Vec3& x) { return Vec3(s[k].R.transpose() * (x - s[k].p)); };
  auto common = [&](int k, const Vec3& x) { return Vec3(s[k].R * x + s[k].p); };
  ConvergedLibraryPath out;
  out.wraps.assign(s.size(), false);
  out.result.assign(s.size(), WrapResult{});
  std::vector<Vec3> e(K, p1), a(K, p2);  // exit and entry of each surface (path order)
  for (int pass = 0; pass < max_passes; ++pass) {
    double moved = 0.0;
    for (int m = 0; m < K; ++m) {
      const int k = order[m];
      const Vec3 from = m == 0 ? p1 : e[m - 1];
      const Vec3 to = m == K - 1 ? p2 : a[m + 1];
      const WrapResult r = calcWrap(*s[k].surface, local(k, from), local(k, to));
      const Vec3 en = r.wraps() ? common(k, r.r1) : to, ex = r.wraps() ? common(k, r.r2) : from;
      moved = std::max({moved, (en - a[m]).norm(), (ex - e[m]).norm()});
      a[m] = en;
      e[m] = ex;
      out.wraps[k] = r.wraps();
      out.result[k] = r;
    }
    out.passes = pass + 1;
    out.last_moved = moved;
    if (moved < 1e-14) {  // the construction's round-off at coordinates of 0.5 m: moves of 2e-15 m
      out.converged = true;
      break;
    }
  }
  out.points = {p1};
  out.arc_of.clear();
  for (int m = 0; m < K; ++m) {
    const int k = order[m];
    if (!out.wraps[k]) continue;
    out.points.push_back(common(k, out.result[k].r1));
    out.arc_of.push_back(-1);
    out.points.push_back(common(k, out.result[k].r2));
    out.arc_of.push_back(k);
  }
  out.points.push_back(p2);
  out.arc_of.push_back(-1);
  out.length = 0.0;
  for (size_t i = 0; i + 1 < out.points.size(); ++i)
    out.length += out.arc_of[i] >= 0 ? out.result[out.arc_of[i]].arcLength() : (out.points[i + 1] - out.points[i]).norm();
  return out;
}

/// The point at fraction alpha of the converged path's geometric length.
inline Vec3 convergedLibraryPoint(const std::vector<CompositeWrapSurface>& s, const ConvergedLibraryPath& p,
                                  double alpha) {
  double rest = std::clamp(alpha, 0.0, 1.0) * p.length;
  for (size_t i = 0; i + 1 < p.points.size(); ++i) {
    const int k = p.arc_of[i];
    const double len = k >= 0 ? p.result[k].arcLength() : (p.points[i + 1] - p.points[i]).norm();
    if (rest > len && i + 2 < p.points.size()) {
      rest -= len;
      continue;
    }
    const double f = len > 0.0 ? std::clamp(rest / len, 0.0, 1.0) : 0.0;
    if (k >= 0) return s[k].R * p.result[k].arcPoint(f) + s[k].p;
    return p.points[i] + f * (p.points[i + 1] - p.points[i]);
  }
  return p.points.back();
}

}  // namespace redmax::test
