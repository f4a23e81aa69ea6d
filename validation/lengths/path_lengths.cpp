#include "validation/lengths/path_lengths.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "converter/coordinates_file.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap_composite.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::validation {
namespace {

// polyline segments of a network's wrapped path: calcNetworkWrapPathLength converges to 1e-6
// relative by 200 on cylinder_3x64 (network_model.hpp)
constexpr int kNetworkLengthSegments = 200;

}  // namespace

double calcModelPathLength(const Model& model, const Muscle& muscle, const VecX& q, const std::vector<Mat4>& E_wi,
                           NetworkWrapWorkspace& ws, std::vector<int>& active, std::vector<Vec3>& x_w,
                           WrapFallbackMonitor* monitor) {
  const MusclePath& path = muscle.path;
  calcActivePoints(path, q, E_wi, active, x_w);
  const WrapMassOptions& o = muscle.wrap;
  if (o.model == WrapModel::Smooth && hasSharedWrapSegments(muscle)) {
    // several wraps may share a segment: the smooth composition (core/muscles/wrap_composite.hpp)
    std::vector<Mat4> E_ws;
    for (const PathWrap& w : path.wraps) E_ws.push_back(w.body >= 0 ? Mat4(E_wi[w.body] * w.E_bs) : w.E_bs);
    return calcCompositePathLength(muscle, active, x_w, E_ws);
  }
  const std::vector<int> seg_wrap = calcSegmentWraps(muscle, active, x_w, E_wi);
  double length = 0.0;
  for (size_t i = 0; i < seg_wrap.size(); ++i) {
    const double straight = (x_w[i + 1] - x_w[i]).norm();
    if (seg_wrap[i] < 0) {
      length += straight;
      continue;
    }
    const PathWrap& w = path.wraps[seg_wrap[i]];
    const Mat4 E_ws = w.body >= 0 ? Mat4(E_wi[w.body] * w.E_bs) : w.E_bs;
    const Mat3 R = E_ws.topLeftCorner<3, 3>();
    const Vec3 p = E_ws.topRightCorner<3, 1>();
    const Vec3 p1 = R.transpose() * (x_w[i] - p), p2 = R.transpose() * (x_w[i + 1] - p);
    try {
      if (o.model == WrapModel::Neural) {
        NetworkWrapOptions no;
        no.fallback.width = o.width;
        NetworkWrapEval ev;
        const Mlp* net = o.networkFor(w.name, wrapTypeName(w.surface.type));
        const double l = calcNetworkWrapPathLength(net, w.surface, p1, p2, kNetworkLengthSegments, ws, &ev, no);
        if (monitor) monitor->record(muscle.name, w.name, ev, net);
        // the fallback is the smooth model: its own length, not a polyline through its points
        length += ev.usedNetwork()
                      ? l
                      : calcWrapModelLength(o, w.surface, p1, p2, Vec3::Zero(), Vec3::Zero()).length;
      } else {
        length += calcWrapModelLength(o, w.surface, p1, p2, Vec3::Zero(), Vec3::Zero()).length;
      }
    } catch (const std::invalid_argument&) {
      length += straight;  // an end inside the surface: no wrap
    }
  }
  return length;
}

PathLengthResult calcPathLengths(const osim::ModelDescription& d, const osim::BuildResult& build,
                                 const osim::Storage& coords, const std::string& model_file,
                                 const std::string& coords_file, const PathLengthOptions& o) {
  PathLengthResult res;
  const bool model_lengths = o.wrap == LengthWrap::Smooth || o.wrap == LengthWrap::Neural;
  // which built paths are reported: muscles (every path force with all_paths)
  std::vector<int> report;
  for (size_t k = 0; k < build.model.muscles().size(); ++k)
    if (o.all_paths || d.muscles[build.muscle_source[k]].is_muscle) report.push_back(static_cast<int>(k));
  if (report.empty()) throw osim::ConvertError(model_file, 0, "no muscle with a path to report");

  // coordinates: default values, overwritten by the file's columns (converter/coordinates_file.hpp)
  const Model& model = build.model;
  const osim::CoordinateRows rows =
      osim::coordinateRows(coords, d.coordinates, build.coordinate_index, model.nr(), coords_file);
  res.missing_coordinates = rows.missing;

  // the paths without their wraps when asked (None: straight segments only)
  std::vector<MusclePath> paths;
  for (int k : report) {
    MusclePath p = build.model.muscles()[k].path;
    if (o.wrap == LengthWrap::None) p.wraps.clear();
    res.wrapping += p.wraps.empty() ? 0 : 1;
    paths.push_back(std::move(p));
  }
  // smooth/neural: which paths take the wrap model's length; the others keep the exact one
  std::vector<Muscle> model_muscle(paths.size());
  std::vector<char> use_model(paths.size(), 0);
  if (model_lengths)
    for (size_t m = 0; m < paths.size(); ++m) {
      if (paths[m].wraps.empty()) continue;  // no wrap object: the polyline either way
      Muscle& mu = model_muscle[m];
      mu.name = build.model.muscles()[report[m]].name;
      mu.path = paths[m];
      mu.wrap = o.wrap_model;
      const std::string why = wrapMassPointsUnsupportedReason(mu);
      if (why.empty()) {
        use_model[m] = 1;
      } else {
        ++res.exact_fallbacks;
        res.refused += "  " + mu.name + ": " + why + "\n";
      }
    }

  osim::Storage& out = res.lengths;
  out.name = "MuscleTendonLengths";
  out.in_degrees = false;
  for (int k : report) out.labels.push_back(build.model.muscles()[k].name);
  out.time = coords.time;
  out.data.resize(coords.numRows(), static_cast<int>(report.size()));
  // optional: the surface length l of every wrap object of every reported path (0 when unused)
  osim::Storage& wl = res.wrap_lengths;
  std::vector<std::pair<int, int>> wl_cols;  // (path, wrap)
  if (o.wrap_lengths) {
    wl.name = "WrapSurfaceLengths";
    for (size_t m = 0; m < paths.size(); ++m)
      for (size_t w = 0; w < paths[m].wraps.size(); ++w) {
        wl.labels.push_back(out.labels[m] + "/" + paths[m].wraps[w].name);
        wl_cols.emplace_back(static_cast<int>(m), static_cast<int>(w));
      }
    if (wl_cols.empty()) throw std::invalid_argument("--wrap-lengths: no reported path has a wrap object");
    wl.time = coords.time;
    wl.data.setZero(coords.numRows(), static_cast<int>(wl_cols.size()));
  }
  std::vector<Mat4> E_wi;
  NetworkWrapWorkspace nws;
  std::vector<int> active;
  std::vector<Vec3> x_w;
  for (int row = 0; row < coords.numRows(); ++row) {
    const VecX& q = rows.q[row];
    calcBodyPoses(model, q, E_wi);
    for (size_t j = 0; j < wl_cols.size(); ++j) {
      // one wrapped-path evaluation per path, at its first column
      const int m = wl_cols[j].first;
      if (j > 0 && wl_cols[j - 1].first == m) continue;
      const WrappedPath wp = calcWrappedPath(model, paths[m], q, E_wi);
      for (size_t k = j; k < wl_cols.size() && wl_cols[k].first == m; ++k) {
        const int w = wl_cols[k].second;
        wl.data(row, static_cast<int>(k)) = wp.used[w] ? wp.results[w].length : 0.0;
      }
    }
    for (size_t m = 0; m < paths.size(); ++m) {
      const double l = use_model[m] ? calcModelPathLength(model, model_muscle[m], q, E_wi, nws, active, x_w, o.monitor)
                                    : calcPathLength(model, paths[m], q, E_wi);
      if (!std::isfinite(l)) {
        std::ostringstream os;
        os << coords_file << ": muscle '" << out.labels[m] << "' has a non-finite length at time " << coords.time[row]
           << " (row " << row + 1 << ")";
        res.failed = true;
        res.failure = os.str();
        return res;
      }
      out.data(row, static_cast<int>(m)) = l;
    }
  }
  return res;
}

}  // namespace redmax::validation
