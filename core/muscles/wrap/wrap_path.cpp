#include "core/muscles/wrap/wrap_path.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/muscles/path_kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {
namespace {

// pose of wrap surface k in the world
Mat4 surfacePose(const PathWrap& w, const std::vector<Mat4>& E_wi) {
  return w.body >= 0 ? Mat4(E_wi[w.body] * w.E_bs) : w.E_bs;
}

Vec3 applyPose(const Mat4& E, const Vec3& x) {
  return E.topLeftCorner<3, 3>() * x + E.topRightCorner<3, 1>();
}

Vec3 applyInverse(const Mat4& E, const Vec3& x) {
  return E.topLeftCorner<3, 3>().transpose() * (x - E.topRightCorner<3, 1>());
}

struct Entry {
  int point = -1;  // path point index, or -1
  int wrap = -1;   // tangent point of this wrap
  int which = 0;   // 1 or 2
};

// OpenSim's algorithm on the path's inputs: each point's activity and world position, each wrap
// surface's pose (the only ways q and the body poses enter)
class PathWrapper {
 public:
  PathWrapper(const MusclePath& path, std::vector<bool> active, std::vector<Vec3> point_w, std::vector<Mat4> E_ws)
      : path_(path), E_ws_(std::move(E_ws)), point_w_(std::move(point_w)), active_(std::move(active)) {
    const int nw = static_cast<int>(path.wraps.size());
    results_.assign(nw, WrapResult{});
    used_.assign(nw, false);
    ground_cache_.assign(nw, {});
  }

  Vec3 world(const Entry& e) const {
    if (e.point >= 0) return point_w_[e.point];
    const WrapResult& r = results_[e.wrap];
    return applyPose(E_ws_[e.wrap], e.which == 1 ? r.r1 : r.r2);
  }

  // OpenSim's Point::getLocationInGround: a tangent point's ground position is cached at its
  // first use in one evaluation and not refreshed when a later pass moves the point (the cache
  // depends on the state's position stage only), so lengths and length changes of later passes
  // use the first position; the wrap geometry itself always uses the current one
  Vec3 worldCached(const Entry& e) {
    if (e.point >= 0) return point_w_[e.point];
    auto& c = ground_cache_[e.wrap][e.which - 1];
    if (!c.valid) {
      c.x = world(e);
      c.valid = true;
    }
    return c.x;
  }

  // OpenSim's calcLengthAfterPathComputation
  double length() {
    double l = 0.0;
    for (size_t i = 1; i < path_entries_.size(); ++i) {
      const Entry &a = path_entries_[i - 1], &b = path_entries_[i];
      if (a.wrap >= 0 && b.wrap >= 0 && a.wrap == b.wrap)
        l += results_[b.wrap].length;  // the surface length sits on the second tangent point
      else
        l += (worldCached(a) - worldCached(b)).norm();
    }
    return l;
  }

  void removeWrapPoints(int k) {
    for (size_t j = 0; j < path_entries_.size(); ++j)
      if (path_entries_[j].wrap == k && path_entries_[j].which == 1) {
        path_entries_.erase(path_entries_.begin() + j, path_entries_.begin() + std::min(j + 2, path_entries_.size()));
        break;
      }
    used_[k] = false;
  }

  // one PathWrap over its range; returns the code of the last segment tried (OpenSim's result[i]),
  // or nothing (false) when its range has no active point (OpenSim then stops wrapping)
  bool applyWrap(int k, WrapCode& code) {
    const PathWrap& w = path_.wraps[k];
    code = WrapCode::NoWrap;
    removeWrapPoints(k);
    if (!w.surface.active) return true;
    const int np = static_cast<int>(path_.points.size());
    const int wrap_start = w.range_begin < 1 ? 0 : w.range_begin - 1;
    const int wrap_end = w.range_end < 1 ? np - 1 : w.range_end - 1;
    int jfwd = wrap_start;
    for (; jfwd <= wrap_end; ++jfwd)
      if (jfwd >= 0 && jfwd < np && active_[jfwd]) break;
    if (jfwd > wrap_end) return false;
    int jrev = wrap_end;
    for (; jrev >= wrap_start; --jrev)
      if (jrev >= 0 && jrev < np && active_[jrev]) break;
    if (jrev < wrap_start) return false;
    int start = -1, end = -1;
    for (size_t j = 0; j < path_entries_.size(); ++j) {
      if (path_entries_[j].point == jfwd) start = static_cast<int>(j);
      if (path_entries_[j].point == jrev) end = static_cast<int>(j);
    }
    if (start < 0 || end < 0) return false;

    WrapOptions opt;
    opt.method = w.method;
    opt.single_wrap = path_.wraps.size() == 1;
    bool have_best = false;
    WrapResult best;
    int best_end = -1;
    double min_change = std::numeric_limits<double>::infinity();
    for (int pt1 = start; pt1 < end; ++pt1) {
      const int pt2 = pt1 + 1;
      const Entry &e1 = path_entries_[pt1], &e2 = path_entries_[pt2];
      if (e1.wrap >= 0 && e2.wrap >= 0 && e1.wrap == e2.wrap) continue;
      const Vec3 x1 = applyInverse(E_ws_[k], world(e1));
      const Vec3 x2 = applyInverse(E_ws_[k], world(e2));
      WrapResult wr = calcWrap(w.surface, x1, x2, opt);
      code = wr.code;
      if (wr.code == WrapCode::MandatoryWrap) {
        // the segment crosses the surface: it must be this one (the first such segment)
        best = std::move(wr);
        best_end = pt2;
        have_best = true;
        break;
      }
      if (wr.code == WrapCode::Wrapped) {
        // OpenSim's calcPathLengthChange, with its ground positions of the segment's ends
        const Vec3 c1 = worldCached(e1), c2 = worldCached(e2);
        const Vec3 r1_w = applyPose(E_ws_[k], wr.r1), r2_w = applyPose(E_ws_[k], wr.r2);
        const double change = (r1_w - c1).norm() + wr.length + (c2 - r2_w).norm() - (c2 - c1).norm();
        if (change < min_change) {
          best = std::move(wr);
          best_end = pt2;
          have_best = true;
          min_change = change;
        }
      }
    }
    if (have_best) {
      results_[k] = std::move(best);
      used_[k] = true;
      path_entries_.insert(path_entries_.begin() + best_end, {Entry{-1, k, 1}, Entry{-1, k, 2}});
    } else {
      results_[k] = WrapResult{};
    }
    return true;
  }

  WrappedPath run() {
    for (size_t i = 0; i < path_.points.size(); ++i)
      if (active_[i]) path_entries_.push_back(Entry{static_cast<int>(i), -1, 0});
    const int nw = static_cast<int>(path_.wraps.size());
    if (nw > 0) {
      std::vector<int> order(nw);
      std::vector<WrapCode> result(nw, WrapCode::NoWrap);
      for (int i = 0; i < nw; ++i) order[i] = i;
      // one pass for one object; up to 8 passes until the length settles within 0.5 mm
      const int max_iterations = nw < 2 ? 1 : 8;
      double last_length = std::numeric_limits<double>::infinity();
      bool stop = false;
      for (int kk = 0; kk < max_iterations && !stop; ++kk) {
        for (int i = 0; i < nw; ++i) {
          if (!applyWrap(order[i], result[i])) {
            stop = true;
            break;
          }
        }
        if (stop) break;
        const double l = length();
        if (std::abs(l - last_length) < 0.0005) break;
        last_length = l;
        if (kk == 0 && nw > 1 && result[0] == WrapCode::NoWrap &&
            result[1] == WrapCode::InsideRadius) {
          // OpenSim retries with the first two objects swapped
          order[0] = 1;
          order[1] = 0;
          removeWrapPoints(0);
        }
      }
    }
    WrappedPath out;
    out.length = length();
    for (const Entry& e : path_entries_) out.points.push_back(WrappedPathPoint{e.point, e.wrap, e.which, world(e)});
    out.results = results_;
    out.used = used_;
    for (size_t i = 0; i + 1 < out.points.size(); ++i) {
      const auto &a = out.points[i], &b = out.points[i + 1];
      out.geometric_length += (a.wrap >= 0 && a.wrap == b.wrap) ? results_[a.wrap].arcLength()
                                                                : (b.x_w - a.x_w).norm();
    }
    return out;
  }

 private:
  const MusclePath& path_;
  std::vector<Mat4> E_ws_;
  std::vector<Vec3> point_w_;
  std::vector<bool> active_;
  std::vector<WrapResult> results_;
  std::vector<bool> used_;
  std::vector<Entry> path_entries_;
  struct CachedPoint {
    bool valid = false;
    Vec3 x = Vec3::Zero();
  };
  std::vector<std::array<CachedPoint, 2>> ground_cache_;
};

}  // namespace

WrappedPath calcWrappedPath(const Model& model, const MusclePath& path, const VecX& q,
                            const std::vector<Mat4>& E_wi) {
  (void)model;
  const size_t np = path.points.size();
  std::vector<bool> active(np);
  std::vector<Vec3> point_w(np);
  for (size_t i = 0; i < np; ++i) {
    const PathPoint& p = path.points[i];
    active[i] = isPathPointActive(p, q);
    Vec3 x_b, dx, ddx;
    calcPointLocation(p, q, x_b, dx, ddx);
    point_w[i] = p.body >= 0 ? applyPose(E_wi[p.body], x_b) : x_b;
  }
  std::vector<Mat4> E_ws(path.wraps.size());
  for (size_t k = 0; k < E_ws.size(); ++k) E_ws[k] = surfacePose(path.wraps[k], E_wi);
  PathWrapper w(path, std::move(active), std::move(point_w), std::move(E_ws));
  return w.run();
}

WrappedPath calcWrappedPathAt(const MusclePath& path, const std::vector<int>& active, const std::vector<Vec3>& x_w,
                              const std::vector<Mat4>& E_ws) {
  const size_t np = path.points.size();
  if (active.size() != x_w.size() || E_ws.size() != path.wraps.size())
    throw std::invalid_argument("calcWrappedPathAt: " + std::to_string(active.size()) + " active points with " +
                                std::to_string(x_w.size()) + " positions, " + std::to_string(E_ws.size()) +
                                " surface poses for " + std::to_string(path.wraps.size()) + " wrap objects");
  std::vector<bool> on(np, false);
  std::vector<Vec3> point_w(np, Vec3::Zero());
  for (size_t i = 0; i < active.size(); ++i) {
    if (active[i] < 0 || active[i] >= static_cast<int>(np))
      throw std::invalid_argument("calcWrappedPathAt: active index " + std::to_string(active[i]) + " of " +
                                  std::to_string(np) + " points");
    on[active[i]] = true;
    point_w[active[i]] = x_w[i];
  }
  PathWrapper w(path, std::move(on), std::move(point_w), E_ws);
  return w.run();
}

Vec3 calcWrappedPathPointWorld(const MusclePath& path, const WrappedPath& wp,
                               const std::vector<Mat4>& E_wi, double alpha) {
  std::vector<Mat4> E_ws(path.wraps.size());
  for (size_t k = 0; k < E_ws.size(); ++k) E_ws[k] = surfacePose(path.wraps[k], E_wi);
  return calcWrappedPathPointAt(wp, E_ws, alpha);
}

Vec3 calcWrappedPathPointAt(const WrappedPath& wp, const std::vector<Mat4>& E_ws, double alpha) {
  const size_t n = wp.points.size();
  if (n == 0) return Vec3::Zero();
  if (n == 1) return wp.points[0].x_w;
  // geometric length of each piece: straight, or a surface arc between a wrap's two points
  std::vector<double> seg(n - 1);
  double total = 0.0;
  auto is_arc = [&](size_t i) {
    const auto &a = wp.points[i], &b = wp.points[i + 1];
    return a.wrap >= 0 && b.wrap >= 0 && a.wrap == b.wrap;
  };
  for (size_t i = 0; i + 1 < n; ++i) {
    seg[i] = is_arc(i) ? wp.results[wp.points[i].wrap].arcLength()
                       : (wp.points[i + 1].x_w - wp.points[i].x_w).norm();
    total += seg[i];
  }
  double s = std::clamp(alpha, 0.0, 1.0) * total;
  for (size_t i = 0; i + 1 < n; ++i) {
    if (s > seg[i] && i + 2 < n) {
      s -= seg[i];
      continue;
    }
    const double f = seg[i] > 0.0 ? std::clamp(s / seg[i], 0.0, 1.0) : 0.0;
    if (is_arc(i)) {
      const int k = wp.points[i].wrap;
      return applyPose(E_ws[k], wp.results[k].arcPoint(f));
    }
    return wp.points[i].x_w + f * (wp.points[i + 1].x_w - wp.points[i].x_w);
  }
  return wp.points.back().x_w;
}

}  // namespace redmax
