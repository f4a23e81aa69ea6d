// `redmax lengths`: musculotendon path lengths along a coordinates file, as OpenSim's
// GeometryPath::getLength gives them (DESIGN.md §3; OPENSIM_SEMANTICS.md §1.5, §6). Exact wrapping
// over cylinders, spheres, ellipsoids and tori (core/muscles/wrap/). Coordinates absent from the
// file keep their defaults; Rotational columns of a degrees file are converted; constraints are not
// enforced (the file's coupled coordinates are used as written).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "converter/build/build_core_model.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/skeleton/kinematics.hpp"

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

int runLengths(const std::vector<std::string>& argv) {
  const Args a(argv, {"model", "coordinates", "wrap", "out", "wrap-lengths"},
               {"quiet", "full-precision", "all-paths"});
  if (!a.positionals().empty())
    throw UsageError{"lengths takes no positional arguments (got '" + a.positionals().front() + "')"};
  if (!a.has("model") || !a.has("coordinates") || !a.has("out"))
    throw UsageError{"lengths needs --model M.osim, --coordinates Q.mot and --out LENGTHS.sto"};
  const std::string model_file = *a.get("model"), coords_file = *a.get("coordinates"),
                    out_path = *a.get("out");
  const std::string wrap = a.get("wrap", "exact");
  if (wrap == "neural" || wrap == "smooth")
    throw UsageError{"--wrap " + wrap + " chooses how mass points move over wrap surfaces (simulate, id and "
                     "validate with muscle mass); lengths are OpenSim's: --wrap exact (default) or none"};
  if (wrap != "exact" && wrap != "none")
    throw UsageError{"--wrap must be exact, neural, smooth or none, got '" + wrap + "'"};
  const bool quiet = a.has("quiet");

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
  for (size_t k = 0; k < build.muscles.size(); ++k)
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
    MusclePath p = build.muscles[k].path;
    if (wrap == "none") p.wraps.clear();
    paths.push_back(std::move(p));
  }

  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  osim::Storage out;
  out.name = "MuscleTendonLengths";
  out.in_degrees = false;
  for (int k : report) out.labels.push_back(build.muscles[k].name);
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
      const double l = calcPathLength(model, paths[m], q, E_wi);
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
    std::printf("lengths: %d frames, %d muscles (%d wrapping, wrap %s), %.4f s wall -> %s\n",
                coords.numRows(), static_cast<int>(paths.size()), wrapping, wrap.c_str(), wall,
                out_path.c_str());
  }
  return 0;
}

CommandRegistration reg(
    {"lengths", "musculotendon path lengths along a motion, wrapping as OpenSim does",
     "usage: redmax lengths --model M.osim --coordinates Q.mot [--wrap exact|none]\n"
     "                      [--wrap-lengths L.sto] [--all-paths] [--full-precision] [--quiet]\n"
     "                      --out LENGTHS.sto\n"
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
     "                       (neural and smooth are not available here yet)\n"
     "  --wrap-lengths FILE  also write the surface length l of every wrap object of every path\n"
     "                       (columns MUSCLE/WRAPOBJECT, 0 when that object does not wrap)\n"
     "  --all-paths          every force with a path (PathSpring, PathActuator, ...), not only muscles\n"
     "  --out FILE           output .sto: time, then one column per muscle named as the muscle (m)\n"
     "  --full-precision     write %.16e instead of OpenSim's %16.8lf\n"
     "  --quiet              no summary line and no warnings about missing coordinates\n"
     "Exit codes: 0 success, 1 a non-finite length, 2 bad input or usage.\n",
     runLengths});

}  // namespace
}  // namespace redmax::cli
