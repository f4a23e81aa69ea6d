// `redmax lengths`: musculotendon path lengths along a coordinates file, as OpenSim's
// GeometryPath::getLength gives them (docs/commands.md §1; docs/opensim_compatibility.md §1.5, §6). Exact wrapping
// over cylinders, spheres, ellipsoids and tori (core/muscles/wrap/). Coordinates absent from the
// file keep their defaults; Rotational columns of a degrees file are converted; constraints are not
// enforced (the file's coupled coordinates are used as written).
// --wrap smooth|neural: the length with the wrap model that mass points use (issue 7): straight
// segments between active points plus, on the segment each wrap object acts on
// (calcSegmentWraps, core/muscles/wrap_muscle.hpp), the model's length of that wrapped segment:
// the smooth model's (calcWrapModelLength), or the polyline through the network's points
// (calcNetworkWrapPathLength), with the smooth model where the network falls back. Paths the model
// refuses (wrapMassPointsUnsupportedReason: two wraps on one segment, unsupported surfaces) keep
// OpenSim's exact length and are named once.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "cli/muscle_mass_flags.hpp"
#include "converter/build/build_core_model.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::cli {
namespace {

// the column holding coordinate c: its name, its absolute state name
// (/jointset/<joint>/<name>/value), or any label whose last element is the name or whose last two
// are <name>/value (OpenSim's label matching); -1 when none
int findCoordinateColumn(const osim::Storage& s, const osim::CoordinateDesc& c) {
  int k = s.findColumn(c.name);
  if (k >= 0) return k;
  k = s.findColumn("/jointset/" + c.joint + "/" + c.name + "/value");
  if (k >= 0) return k;
  for (int j = 0; j < s.numColumns(); ++j) {
    const std::string& l = s.labels[j];
    const std::string tail = "/" + c.name;
    const std::string tail_value = "/" + c.name + "/value";
    auto ends = [&](const std::string& t) {
      return l.size() >= t.size() && l.compare(l.size() - t.size(), t.size(), t) == 0;
    };
    if (ends(tail_value) || ends(tail)) return j;
  }
  return -1;
}

// polyline segments of a network's wrapped path: calcNetworkWrapPathLength converges to 1e-6
// relative by 200 on cylinder_3x64 (network_model.hpp)
constexpr int kNetworkLengthSegments = 200;

// The wrap model's length of muscle's path at q (m), see the file header. A wrapped segment whose
// end lies inside its surface (origin -> surface -> insertion only; calcSegmentWraps skips such
// segments elsewhere) is straight, as OpenSim's InsideRadius leaves it.
double calcModelPathLength(const Model& model, const Muscle& muscle, const VecX& q, const std::vector<Mat4>& E_wi,
                           NetworkWrapWorkspace& ws, std::vector<int>& active, std::vector<Vec3>& x_w) {
  const MusclePath& path = muscle.path;
  active.clear();
  x_w.clear();
  for (size_t i = 0; i < path.points.size(); ++i) {
    const PathPoint& pt = path.points[i];
    if (!isPathPointActive(pt, q)) continue;
    Vec3 x_b, dx, ddx;
    calcPointLocation(pt, q, x_b, dx, ddx);
    active.push_back(static_cast<int>(i));
    x_w.push_back(pt.body >= 0 ? transformPoint(E_wi[pt.body], x_b) : x_b);
  }
  const std::vector<int> seg_wrap = calcSegmentWraps(muscle, active, x_w, E_wi);
  const WrapMassOptions& o = muscle.wrap;
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
        const double l =
            calcNetworkWrapPathLength(o.network.get(), w.surface, p1, p2, kNetworkLengthSegments, ws, &ev, no);
        if (o.monitor) o.monitor->record(muscle.name, w.name, ev, o.network.get());
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

int runLengths(const std::vector<std::string>& argv) {
  const Args a(argv, {"model", "coordinates", "wrap", "out", "wrap-lengths", "wrap-width", "wrap-network"},
               {"quiet", "full-precision", "all-paths"});
  if (!a.positionals().empty())
    throw UsageError{"lengths takes no positional arguments (got '" + a.positionals().front() + "')"};
  if (!a.has("model") || !a.has("coordinates") || !a.has("out"))
    throw UsageError{"lengths needs --model M.osim, --coordinates Q.mot and --out LENGTHS.sto"};
  const std::string model_file = *a.get("model"), coords_file = *a.get("coordinates"),
                    out_path = *a.get("out");
  const std::string wrap = a.get("wrap", "exact");
  if (wrap != "exact" && wrap != "none" && wrap != "smooth" && wrap != "neural")
    throw UsageError{"--wrap must be exact, smooth, neural or none, got '" + wrap + "'"};
  // the shared wrap flags' checks (width only with smooth/neural, network only and always with
  // neural, the network file loaded); none has no wrap model to configure
  osim::MuscleMassOptions wrap_flags;
  if (wrap == "none") {
    for (const char* f : {"wrap-width", "wrap-network"})
      if (a.has(f)) throw UsageError{std::string("--") + f + " needs --wrap smooth or neural"};
  } else {
    parseWrapFlags(a, wrap_flags);
  }
  const bool model_lengths = wrap == "smooth" || wrap == "neural";
  const bool quiet = a.has("quiet");
  if (quiet && wrap_flags.wrap.monitor) wrap_flags.wrap.monitor->setSink({});

  osim::ModelDescription d;
  osim::BuildResult build;
  osim::Storage coords;
  try {
    d = osim::readOsimModel(model_file);
    osim::BuildOptions opt;
    opt.constraints = false;  // lengths: coordinates as given, nothing enforced
    build = osim::buildCoreModel(d, opt);
    coords = osim::readStorage(coords_file);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const ModelError& e) {
    std::cerr << "error: " << model_file << ": " << e.what() << "\n";
    return 2;
  }
  for (const auto& w : build.warnings) std::cerr << "warning: " << w << "\n";
  for (const auto& u : build.unsupported)
    std::cerr << "warning: " << model_file << ":" << u.line << ": " << u.what << "\n";

  // which built paths are reported: muscles (every path force with --all-paths)
  std::vector<int> report;
  for (size_t k = 0; k < build.model.muscles().size(); ++k)
    if (a.has("all-paths") || d.muscles[build.muscle_source[k]].is_muscle)
      report.push_back(static_cast<int>(k));
  if (report.empty()) {
    std::cerr << "error: " << model_file << ": no muscle with a path to report\n";
    return 2;
  }

  // coordinates: default values, overwritten by the file's columns (degrees -> radians for
  // Rotational coordinates of a degrees file, as OpenSim converts them)
  const Model& model = build.model;
  VecX q0 = VecX::Zero(model.nr());
  std::vector<std::pair<int, int>> column_of;  // (core coordinate, data column)
  std::vector<double> scale;
  int missing = 0;
  for (size_t ci = 0; ci < d.coordinates.size(); ++ci) {
    const int k = build.coordinate_index[ci];
    if (k < 0) continue;
    const osim::CoordinateDesc& c = d.coordinates[ci];
    q0[k] = c.default_value;
    const int col = findCoordinateColumn(coords, c);
    if (col < 0) {
      ++missing;
      continue;
    }
    column_of.emplace_back(k, col);
    scale.push_back(coords.in_degrees && c.motion_type == osim::MotionType::Rotational
                        ? osim::degreesToRadians()
                        : 1.0);
  }
  if (column_of.empty()) {
    std::cerr << "error: " << coords_file << ": no column names a coordinate of the model\n";
    return 2;
  }
  if (missing > 0 && !quiet)
    std::cerr << "warning: " << missing << " coordinate(s) not in " << coords_file
              << ": held at their default values\n";

  // the paths without their wraps when asked (--wrap none: straight segments only)
  std::vector<MusclePath> paths;
  for (int k : report) {
    MusclePath p = build.model.muscles()[k].path;
    if (wrap == "none") p.wraps.clear();
    paths.push_back(std::move(p));
  }
  // smooth/neural: which paths take the wrap model's length; the others keep the exact one
  std::vector<Muscle> model_muscle(paths.size());
  std::vector<char> use_model(paths.size(), 0);
  int exact_fallbacks = 0;
  if (model_lengths) {
    std::string refused;
    for (size_t m = 0; m < paths.size(); ++m) {
      if (paths[m].wraps.empty()) continue;  // no wrap object: the polyline either way
      Muscle& mu = model_muscle[m];
      mu.name = build.model.muscles()[report[m]].name;
      mu.path = paths[m];
      mu.wrap = wrap_flags.wrap;
      const std::string why = wrapMassPointsUnsupportedReason(mu);
      if (why.empty()) {
        use_model[m] = 1;
      } else {
        ++exact_fallbacks;
        refused += "  " + mu.name + ": " + why + "\n";
      }
    }
    if (exact_fallbacks > 0)
      std::cerr << "warning: " << exact_fallbacks << " wrapping muscle(s) keep OpenSim's exact length (the " << wrap
                << " model cannot take their path):\n"
                << refused;
  }

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  osim::Storage out;
  out.name = "MuscleTendonLengths";
  out.in_degrees = false;
  for (int k : report) out.labels.push_back(build.model.muscles()[k].name);
  out.time = coords.time;
  out.data.resize(coords.numRows(), static_cast<int>(report.size()));
  // optional: the surface length l of every wrap object of every reported path (0 when unused)
  const std::string wl_path = a.get("wrap-lengths", "");
  osim::Storage wl;
  std::vector<std::pair<int, int>> wl_cols;  // (path, wrap)
  if (!wl_path.empty()) {
    wl.name = "WrapSurfaceLengths";
    for (size_t m = 0; m < paths.size(); ++m)
      for (size_t w = 0; w < paths[m].wraps.size(); ++w) {
        wl.labels.push_back(out.labels[m] + "/" + paths[m].wraps[w].name);
        wl_cols.emplace_back(static_cast<int>(m), static_cast<int>(w));
      }
    if (wl_cols.empty()) throw UsageError{"--wrap-lengths: no reported path has a wrap object"};
    wl.time = coords.time;
    wl.data.setZero(coords.numRows(), static_cast<int>(wl_cols.size()));
  }
  std::vector<Mat4> E_wi;
  NetworkWrapWorkspace nws;
  std::vector<int> active;
  std::vector<Vec3> x_w;
  for (int row = 0; row < coords.numRows(); ++row) {
    VecX q = q0;
    for (size_t j = 0; j < column_of.size(); ++j)
      q[column_of[j].first] = coords.data(row, column_of[j].second) * scale[j];
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
      const double l = use_model[m] ? calcModelPathLength(model, model_muscle[m], q, E_wi, nws, active, x_w)
                                    : calcPathLength(model, paths[m], q, E_wi);
      if (!std::isfinite(l)) {
        std::cerr << "error: " << coords_file << ": muscle '" << out.labels[m]
                  << "' has a non-finite length at time " << coords.time[row] << " (row " << row + 1
                  << ")\n";
        return 1;
      }
      out.data(row, static_cast<int>(m)) = l;
    }
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();

  try {
    const std::filesystem::path parent = std::filesystem::path(out_path).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    osim::StorageWriteOptions wo;
    if (a.has("full-precision")) {
      wo.scientific = true;
      wo.decimals = 16;
    }
    wo.description = "musculotendon path lengths (m), wrap " + wrap;
    if (model_lengths && wrap_flags.wrap.width > 0.0)
      wo.description += " (width " + std::to_string(wrap_flags.wrap.width) + " m)";
    if (wrap == "neural") wo.description += " (network " + a.get("wrap-network", "") + ")";
    osim::writeStorage(out_path, out, wo);
    if (!wl_path.empty()) {
      wo.description = "surface length l of each wrap object (m; 0 = not wrapping; OpenSim's value)";
      osim::writeStorage(wl_path, wl, wo);
    }
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (!quiet) {
    int wrapping = 0;
    for (const auto& p : paths) wrapping += p.wraps.empty() ? 0 : 1;
    std::string detail;
    if (model_lengths && exact_fallbacks > 0)
      detail = ", " + std::to_string(exact_fallbacks) + " on the exact length";
    std::printf("lengths: %d frames, %d muscles (%d wrapping, wrap %s%s), %.4f s wall -> %s\n", coords.numRows(),
                static_cast<int>(paths.size()), wrapping, wrap.c_str(), detail.c_str(), wall, out_path.c_str());
    if (wrap_flags.wrap.monitor) {
      long evaluations = 0;
      for (const auto& [name, c] : wrap_flags.wrap.monitor->counts()) evaluations += c.evaluations;
      std::printf("network: %ld of %ld wrapped-segment evaluations fell back to the smooth model\n",
                  wrap_flags.wrap.monitor->totalFallbacks(), evaluations);
      std::printf("%s", wrap_flags.wrap.monitor->summary().c_str());
    }
  }
  return 0;
}

CommandRegistration reg(
    {"lengths", "musculotendon path lengths along a motion, wrapping as OpenSim does",
     "usage: redmax lengths --model M.osim --coordinates Q.mot [--wrap exact|smooth|neural|none]\n"
     "                      [--wrap-width W] [--wrap-network FILE] [--wrap-lengths L.sto]\n"
     "                      [--all-paths] [--full-precision] [--quiet] --out LENGTHS.sto\n"
     "Path length of every muscle at every row of the coordinates file, as OpenSim's\n"
     "GeometryPath computes it: active path points (conditional, moving), then each PathWrap in\n"
     "order over its range (WrapCylinder, WrapSphere, WrapEllipsoid, WrapTorus; quadrants, methods,\n"
     "several wrap objects per path), surface lengths between tangent points.\n"
     "  --model FILE         OpenSim model (.osim)\n"
     "  --coordinates FILE   .mot/.sto; columns named as coordinates or as state names\n"
     "                       (/jointset/<joint>/<coord>/value); coordinates absent from the file keep\n"
     "                       their defaults; Rotational columns of a degrees file are converted;\n"
     "                       constraints are not enforced (coupled coordinates used as written)\n"
     "  --wrap exact         OpenSim-exact wrapping (default); none: straight segments, no wraps\n"
     "  --wrap smooth        the smooth wrap model's length (as mass points use it): straight\n"
     "                       segments plus, on the segment each wrap acts on, the exact wrapped length\n"
     "                       outside the transition band and a C2 blend with the straight one inside;\n"
     "                       paths the model refuses (two wraps on one segment, ...) keep the exact\n"
     "                       length and are named on stderr\n"
     "  --wrap neural        the same with the polyline through a network's points (200 pieces) on\n"
     "                       wrapped segments; where the network falls back (outside its training\n"
     "                       box, other surfaces) the smooth model's length; counted in the summary\n"
     "  --wrap-width W       smooth (and neural's fallback): transition width in metres (default 0.05\n"
     "                       of the surface size)\n"
     "  --wrap-network FILE  neural (required): a network of `redmax train-wrap`\n"
     "                       (e.g. osim_models/networks/cylinder_6x256.txt)\n"
     "  --wrap-lengths FILE  also write the surface length l of every wrap object of every path\n"
     "                       (columns MUSCLE/WRAPOBJECT, 0 when that object does not wrap; OpenSim's\n"
     "                       exact value whatever --wrap)\n"
     "  --all-paths          every force with a path (PathSpring, PathActuator, ...), not only muscles\n"
     "  --out FILE           output .sto: time, then one column per muscle named as the muscle (m)\n"
     "  --full-precision     write %.16e instead of OpenSim's %16.8lf\n"
     "  --quiet              no summary line and no warnings about missing coordinates\n"
     "Exit codes: 0 success, 1 a non-finite length, 2 bad input or usage.\n",
     runLengths});

}  // namespace
}  // namespace redmax::cli
