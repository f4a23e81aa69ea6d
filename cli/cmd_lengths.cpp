// `redmax lengths`: musculotendon path lengths along a coordinates file, as OpenSim's
// GeometryPath::getLength gives them. The work is validation/lengths/path_lengths.hpp; this file
// parses flags, prints warnings and the summary, and writes the tables atomically.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/muscle_mass_flags.hpp"
#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "validation/lengths/path_lengths.hpp"

namespace redmax::cli {
namespace {

struct LengthsFlags {
  std::string model, coordinates, out, wrap_lengths;
  WrapFlags wrap;  // --wrap here: exact|smooth|neural|none, default exact
  bool quiet = false, full_precision = false, all_paths = false;
};

int runLengths(const LengthsFlags& f, const CLI::App& app) {
  if (!given(app, "--model") || !given(app, "--coordinates") || !given(app, "--out"))
    throw UsageError{"lengths needs --model M.osim, --coordinates Q.mot and --out LENGTHS.sto"};
  const std::string &model_file = f.model, &coords_file = f.coordinates, &out_path = f.out;
  const std::string& wrap = f.wrap.model;
  // the shared wrap flags' checks (width only with smooth/neural, network only and always with
  // neural, the network file loaded); none has no wrap model to configure
  osim::MuscleMassOptions wrap_flags;
  if (wrap == "none") {
    if (f.wrap.hasWidth()) throw UsageError{"--wrap-width needs --wrap smooth or neural"};
    if (f.wrap.hasNetwork()) throw UsageError{"--wrap-network needs --wrap smooth or neural"};
  } else {
    parseWrapFlags(f.wrap, wrap_flags);
  }
  const bool model_lengths = wrap == "smooth" || wrap == "neural";
  const bool quiet = f.quiet;
  const std::shared_ptr<WrapFallbackMonitor> monitor = wrap == "none" ? nullptr : makeWrapFallbackMonitor(f.wrap);
  if (quiet && monitor) monitor->setSink({});

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

  validation::PathLengthOptions po;
  po.wrap = wrap == "none"     ? validation::LengthWrap::None
            : wrap == "smooth" ? validation::LengthWrap::Smooth
            : wrap == "neural" ? validation::LengthWrap::Neural
                               : validation::LengthWrap::Exact;
  po.wrap_model = wrap_flags.wrap;
  po.monitor = monitor.get();
  po.all_paths = f.all_paths;
  po.wrap_lengths = given(app, "--wrap-lengths");
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  validation::PathLengthResult res;
  try {
    res = validation::calcPathLengths(d, build, coords, model_file, coords_file, po);
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  if (res.missing_coordinates > 0 && !quiet)
    std::cerr << "warning: " << res.missing_coordinates << " coordinate(s) not in " << coords_file
              << ": held at their default values\n";
  if (res.exact_fallbacks > 0)
    std::cerr << "warning: " << res.exact_fallbacks << " wrapping muscle(s) keep OpenSim's exact length (the " << wrap
              << " model cannot take their path):\n"
              << res.refused;
  if (res.failed) {
    std::cerr << "error: " << res.failure << "\n";
    return 1;
  }

  try {
    std::string description = "musculotendon path lengths (m), wrap " + wrap;
    if (model_lengths && wrap_flags.wrap.width > 0.0)
      description += " (width " + std::to_string(wrap_flags.wrap.width) + " m)";
    if (wrap == "neural")
      description += " (network " + (f.wrap.hasNetwork() ? f.wrap.network : defaultWrapNetworksPath()) + ")";
    osim::writeResultStorage(out_path, res.lengths, f.full_precision, description);
    if (po.wrap_lengths)
      osim::writeResultStorage(f.wrap_lengths, res.wrap_lengths, f.full_precision,
                               "surface length l of each wrap object (m; 0 = not wrapping; OpenSim's value)");
  } catch (const osim::ConvertError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  if (!quiet) {
    std::string detail;
    if (model_lengths && res.exact_fallbacks > 0)
      detail = ", " + std::to_string(res.exact_fallbacks) + " on the exact length";
    std::printf("lengths: %d frames, %d muscles (%d wrapping, wrap %s%s), %.4f s wall -> %s\n", coords.numRows(),
                res.lengths.numColumns(), res.wrapping, wrap.c_str(), detail.c_str(), wall, out_path.c_str());
    if (monitor) {
      long evaluations = 0;
      for (const auto& [name, c] : monitor->counts()) evaluations += c.evaluations;
      std::printf("network: %ld of %ld wrapped-segment evaluations fell back to the smooth model\n",
                  monitor->totalFallbacks(), evaluations);
      std::printf("%s", monitor->summary().c_str());
    }
  }
  return 0;
}

CommandRegistration reg(
    {"lengths", "musculotendon path lengths along a motion, wrapping as OpenSim does", [](CLI::App& app) {
       auto f = std::make_shared<LengthsFlags>();
       f->wrap.model = "exact";
       app.add_option("--model", f->model, "OpenSim model (.osim); required")->type_name("M.osim");
       app.add_option("--coordinates", f->coordinates,
                      ".mot/.sto; columns named as coordinates or as state names\n"
                      "(/jointset/<joint>/<coord>/value); coordinates absent from the file keep\n"
                      "their defaults; Rotational columns of a degrees file are converted;\n"
                      "constraints are not enforced (coupled coordinates used as written); required")
           ->type_name("Q.mot");
       app.add_option("--out", f->out, "output .sto: time, then one column per muscle named as the muscle (m);\nrequired")
           ->type_name("LENGTHS.sto");
       f->wrap.model_opt =
           app.add_option("--wrap", f->wrap.model,
                          "exact: OpenSim-exact wrapping (default); none: straight segments, no wraps;\n"
                          "smooth: the smooth wrap model's length (as mass points use it): straight\n"
                          "segments plus, on the segment each wrap acts on, the exact wrapped length\n"
                          "outside the transition band and a C2 blend with the straight one inside;\n"
                          "paths the model refuses (two wraps on one segment, ...) keep the exact\n"
                          "length and are named on stderr; neural: the same with the polyline through\n"
                          "a network's points (200 pieces) on wrapped segments; where the network\n"
                          "falls back (outside its training box, other surfaces) the smooth model's\n"
                          "length; counted in the summary")
               ->type_name("exact|smooth|neural|none")
               ->check(oneOf({"exact", "smooth", "neural", "none"}));
       addWrapFlags(app, f->wrap, false, "Options");
       app.add_option("--wrap-lengths", f->wrap_lengths,
                      "also write the surface length l of every wrap object of every path\n"
                      "(columns MUSCLE/WRAPOBJECT, 0 when that object does not wrap; OpenSim's\n"
                      "exact value whatever --wrap)")
           ->type_name("L.sto");
       app.add_flag("--all-paths", f->all_paths,
                    "every force with a path (PathSpring, PathActuator, ...), not only muscles");
       app.add_flag("--full-precision", f->full_precision, "write %.16e instead of OpenSim's %16.8lf");
       app.add_flag("--quiet", f->quiet, "no summary line and no warnings about missing coordinates");
       app.footer(
           "usage: redmax lengths --model M.osim --coordinates Q.mot [--wrap exact|smooth|neural|none]\n"
           "                      [--wrap-width W] [--wrap-network FILE] [--wrap-lengths L.sto]\n"
           "                      [--all-paths] [--full-precision] [--quiet] --out LENGTHS.sto\n"
           "Path length of every muscle at every row of the coordinates file, as OpenSim's\n"
           "GeometryPath computes it: active path points (conditional, moving), then each PathWrap in\n"
           "order over its range (WrapCylinder, WrapSphere, WrapEllipsoid, WrapTorus; quadrants, methods,\n"
           "several wrap objects per path), surface lengths between tangent points.\n"
           "Exit codes: 0 success, 1 a non-finite length, 2 bad input or usage.");
       return [f, &app] { return runLengths(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
