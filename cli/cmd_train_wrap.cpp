// `redmax train-wrap`: train the Type III wrap network on samples of the exact wrapping library
// (progress on stdout, flushed line by line, in every mode: stderr holds only notes, warnings and the
// error line)
// [D Sec. 5.3.3.1], or (--compare) time networks, the smooth model and the exact library per mass
// point (position + Jacobian + Jdot) against their position error. The work is done by
// tools/wrap_training/ (train.hpp, compare.hpp, study.hpp); this file parses, calls and prints.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "cli/flags.hpp"
#include "converter/atomic_file.hpp"
#include "converter/build/build_core_model.hpp"
#include "converter/build/functions_to_core.hpp"
#include "converter/coordinates_file.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "core/muscles/wrap/network_set.hpp"
#include "core/muscles/wrap_composite.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "tools/wrap_training/model_networks.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "tools/wrap_training/compare.hpp"
#include "tools/wrap_training/study.hpp"
#include "tools/wrap_training/train.hpp"
#include "validation/report/csv.hpp"
#include "validation/report/plot.hpp"
#include "validation/scenes/wrap_pendulums.hpp"

namespace redmax::cli {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }



void requireFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) throw UsageError{"--report: cannot create folder '" + dir + "'"};
}

void requireParent(const std::string& file, const char* flag) {
  const auto parent = std::filesystem::path(file).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent))
    throw UsageError{std::string(flag) + " " + file + ": folder '" + parent.string() + "' does not exist"};
}

// the flag's value, or nothing when it was not given
std::optional<std::string> optionalFlag(const FlagValues& a, const std::string& name) {
  if (!a.has(name)) return std::nullopt;
  return a.get(name, "");
}

std::string num(double v, int prec = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", prec, v);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// training

int runTrain(const FlagValues& a, const CLI::App& app) {
  const WrapType type = parseWrapType(a.get("surface", "cylinder"));
  TrainOptions opt;
  opt.hidden = parseHidden(a.get("hidden", "6x256"));
  const long samples = a.getInt("samples", 30000);
  opt.epochs = static_cast<int>(a.getInt("epochs", 100));
  opt.batch = static_cast<int>(a.getInt("batch", 256));
  opt.learning_rate = a.getDouble("lr", 1e-4);
  opt.seed = static_cast<unsigned long long>(a.getInt("seed", 1));
  opt.time_limit_s = a.getDouble("time-limit", 0.0);
  opt.threads = static_cast<int>(a.getInt("threads", 1));
  opt.shards = static_cast<int>(a.getInt("shards", opt.threads));
  const double threshold = a.getDouble("threshold", 0.01);
  if (opt.threads < 1 || opt.threads > 256) throw UsageError{"--threads must be between 1 and 256"};
  if (opt.shards < 1 || opt.shards > 4096) throw UsageError{"--shards must be between 1 and 4096"};
  if (samples < 10 || samples > 100000000) throw UsageError{"--samples must be between 10 and 1e8"};
  if (opt.epochs < 1 || opt.epochs > 10000000) throw UsageError{"--epochs must be at least 1"};
  if (opt.batch < 1) throw UsageError{"--batch must be at least 1"};
  if (!(opt.learning_rate > 0.0 && opt.learning_rate < 1.0)) throw UsageError{"--lr must be in (0, 1)"};
  if (!(threshold >= 0.0 && threshold < 1.0)) throw UsageError{"--threshold must be in [0, 1)"};
  if (opt.time_limit_s < 0.0) throw UsageError{"--time-limit must be >= 0"};
  const std::optional<std::string> out = optionalFlag(a, "out");
  if (!out) throw UsageError{"--out NET.txt is required"};
  requireParent(*out, "--out");
  std::optional<Mlp> init;
  if (const auto f = optionalFlag(a, "init")) {
    init = Mlp::load(*f);  // a malformed file throws with its line
    const double C = a.getDouble("compact", 0.0);
    const auto im = init->meta.find("wrap_map");
    if ((im == init->meta.end()) != (C == 0.0) || (C > 0.0 && im->second != formatCompactWrapMap(C)))
      throw UsageError{"--init " + *f + " has " + (im == init->meta.end() ? std::string("the older map") : "wrap_map " + im->second) +
                       ", --compact asks for " + (C > 0.0 ? formatCompactWrapMap(C) : std::string("the older map"))};
    if (init->meta.count("surface") && init->meta.at("surface") != wrapTypeName(type))
      throw UsageError{"--init " + *f + " is a " + init->meta.at("surface") + " network, not " + wrapTypeName(type)};
    if (init->architecture() != Mlp(wrapInputSize(type), opt.hidden, 3, 0).architecture())
      throw UsageError{"--init " + *f + " is " + init->architecture() + ", --hidden asks for another architecture"};
    opt.init = &*init;
  }
  const std::optional<std::string> report = optionalFlag(a, "report");
  if (report) requireFolder(*report);

  // samples of the exact library over the stated box [D Sec. 5.3.3.1], or (--compact C) over all of
  // space through the compact map, displacement outputs (core/muscles/wrap/network_model.hpp)
  const double compact = a.getDouble("compact", 0.0);
  if (!(compact >= 0.0 && compact <= 1000.0)) throw UsageError{"--compact must be in [0, 1000] radii (0: the older map)"};
  if (compact > 0.0 && type != WrapType::Cylinder && type != WrapType::Sphere)
    throw UsageError{"--compact takes cylinders and spheres (one radius)"};
  const WrapInputBox box = compact > 0.0 ? makeCompactDefaultWrapBox(type, compact) : makeDefaultWrapBox(type);
  const WrapOracle oracle = makeExactWrapOracle(type);
  auto makeSet = [&](long n, double thr, unsigned long long seed) {
    return compact > 0.0 ? makeCompactWrapTrainingSet(type, n, thr, compact, seed, opt.threads)
                         : makeWrapTrainingSet(box, oracle, n, thr, seed, opt.threads);
  };
  const auto t_data = Clock::now();
  const WrapTrainingSet data = makeSet(samples, threshold, opt.seed);
  std::cout << "train-wrap: " << wrapTypeName(type) << ", " << samples << " samples kept of " << data.drawn
            << " drawn (" << data.invalid << " with an end inside the surface, " << data.near_contact
            << " with 0 < l/L < " << threshold << " discarded; " << data.wrapped << " kept samples wrap), "
            << num(secondsSince(t_data), 3) << " s\n" << std::flush;

  // progress: a line every 2 s and at the end
  double last_print = -1e9;
  opt.on_epoch = [&](const TrainEpoch& e) {
    if (e.elapsed_s - last_print < 2.0 && e.epoch != opt.epochs) return;
    last_print = e.elapsed_s;
    std::cout << "train-wrap: epoch " << e.epoch << "/" << opt.epochs << ", " << e.steps << " steps, train mse "
              << num(e.train_mse) << ", validation mse " << num(e.val_mse) << ", validation rms " << num(e.val_rms_m)
              << " (size units), " << num(e.elapsed_s, 3) << " s\n" << std::flush;
  };
  std::vector<TrainEpoch> history;
  Mlp net = trainWrapNetwork(data, box, opt, &history);

  // error on fresh samples, all of them (also those near the contact change)
  const WrapTrainingSet test = makeSet(std::min(samples, 20000L), 0.0, opt.seed + 1000003);
  const WrapErrorStats err = calcWrapNetworkError(net, test);
  if (init)
    for (const char* k : {"command", "adam", "epochs", "final_val_rms_m", "train_seconds", "test_rms_m"})
      if (init->meta.count(k)) net.meta[std::string("init_") + k] = init->meta.at(k);
  net.meta["surface"] = wrapTypeName(type);
  net.meta["command"] = commandLine(app);
  net.meta["threshold"] = num(threshold, 6);
  net.meta["test_rms_m"] = num(err.rms, 6);
  net.meta["test_max_m"] = num(err.max, 6);
  if (compact > 0.0) {
    net.meta["wrap_map"] = formatCompactWrapMap(compact);
    net.meta["box"] = "the default box's end points through the compact map (tools/wrap_training/model_networks.hpp "
                      "makeCompactWrapTrainingSet, makeCompactDefaultWrapBox; units of the surface size)";
  } else {
    net.meta["box"] = "tools/wrap_training/train.hpp makeDefaultWrapBox (units of the surface size)";
  }
  net.save(*out);
  std::cout << "trained " << net.architecture() << " (" << net.parameterCount() << " parameters) on "
            << wrapTypeName(type) << ": " << history.size() << " epochs, " << history.back().steps << " steps, "
            << num(history.back().elapsed_s, 3) << " s; validation mse " << num(history.back().val_mse)
            << "; position error on " << test.X.cols() << " fresh samples: rms " << num(err.rms) << ", max "
            << num(err.max) << " (surface size units)\nwrote " << *out << "\n";

  if (report) {
    validation::CsvTable t;
    t.header = {"epoch", "steps", "train_mse", "val_mse", "val_rms", "elapsed_s"};
    std::vector<double> ep, tr, va;
    for (const auto& e : history) {
      t.addRow({double(e.epoch), double(e.steps), e.train_mse, e.val_mse, e.val_rms_m, e.elapsed_s});
      ep.push_back(e.epoch);
      tr.push_back(e.train_mse);
      va.push_back(e.val_mse);
    }
    const std::string dir = *report;
    osim::writeFileAtomic(dir + "/loss.csv", validation::formatCsv(t));
    validation::PlotFigure fig;
    fig.title = "train-wrap " + wrapTypeName(type) + " " + net.architecture() + " seed " + std::to_string(opt.seed);
    validation::PlotPanel p = validation::makeXYPanel("loss (normalised MSE)", "epoch", "MSE",
                                                      {validation::makePlotLine("train", ep, tr),
                                                       validation::makePlotLine("validation", ep, va)});
    p.log_y = true;
    fig.panels.push_back(p);
    const auto gp = validation::findGnuplot();
    if (gp.available) {
      const auto o = validation::renderPlot(gp, validation::PlotFormat::Auto, fig, dir + "/loss");
      if (!o.ok) std::cerr << "note: loss plot not drawn: " << o.error << "\n";
    } else {
      std::cerr << "note: loss plot not drawn: " << gp.why_not << "\n";
    }
    std::cout << "wrote " << dir << "/loss.csv and the loss plot\n";
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// speed against error

int runCompare(const FlagValues& a) {
  WrapCompareOptions o;
  o.type = parseWrapType(a.get("surface", "cylinder"));
  const WrapType type = o.type;
  const std::optional<std::string> report = optionalFlag(a, "report");
  if (!report) throw UsageError{"--compare needs --report DIR"};
  requireFolder(*report);
  o.muscles = a.getInt("muscles", 200);
  o.points = static_cast<int>(a.getInt("mass-points", 20));
  const long muscles = o.muscles;
  const int points = o.points;
  if (muscles < 1 || points < 1) throw UsageError{"--muscles and --mass-points must be positive"};
  o.seed = static_cast<unsigned long long>(a.getInt("seed", 1));
  o.width = a.getDouble("width", 0.05);
  for (const auto& f : splitList(a.get("nets", ""))) {
    Mlp n;
    try {
      n = Mlp::load(f);
    } catch (const NetworkFormatError& e) {
      throw UsageError{e.what()};
    } catch (const std::runtime_error& e) {
      throw UsageError{e.what()};
    }
    if (n.inputs() != wrapInputSize(type) || n.outputs() != 3 || (n.meta.count("surface") && n.meta.at("surface") != wrapTypeName(type)))
      throw UsageError{f + ": not a " + wrapTypeName(type) + " wrap network"};
    o.nets.push_back({std::filesystem::path(f).stem().string(), std::move(n), false});
  }
  const std::string untrained = a.get("untrained", "6x256");
  for (const auto& spec : untrained == "none" ? std::vector<std::string>{} : splitList(untrained))
    o.nets.push_back({spec + " (untrained, timing only)", makeTimingWrapNetwork(type, parseHidden(spec), o.seed), true});

  const std::vector<WrapCompareRow> rows = compareWrapModels(o);

  // table, CSV, plot
  validation::CsvTable t;
  t.header = {"method", "parameters", "us_per_point", "rms_error", "max_error", "note"};
  std::cout << "speed against error, " << wrapTypeName(type) << ": " << muscles << " muscles x " << points
            << " mass points (default box, unit-size surface), position + J (3x6) + Jdot, 1 thread\n";
  std::printf("%-48s %10s %12s %12s %12s  %s\n", "method", "params", "us/point", "rms err", "max err", "note");
  for (const auto& r : rows) {
    t.rows.push_back({r.method, std::to_string(r.parameters), num(r.us_per_point, 6), num(r.rms, 6), num(r.max, 6), r.note});
    std::printf("%-48s %10ld %12.4g %12.4g %12.4g  %s\n", r.method.c_str(), r.parameters, r.us_per_point, r.rms, r.max,
                r.note.c_str());
  }
  osim::writeFileAtomic(*report + "/speed_error.csv", validation::formatCsv(t));
  std::vector<validation::PlotLine> lines;
  for (const auto& r : rows)
    if (std::isfinite(r.rms) && r.rms > 0.0) {
      auto l = validation::makePlotLine(r.method, {r.us_per_point}, {r.rms}, "points");
      l.width = 2.5;
      lines.push_back(l);
    }
  validation::PlotFigure fig;
  fig.title = "wrap models: speed against error";
  fig.panel_width = 720;
  fig.panel_height = 420;
  fig.panels.push_back(validation::makeLogLogPanel(wrapTypeName(type) + ": position + J + Jdot", "microseconds per mass point",
                                                   "RMS position error (surface size units)", lines));
  const auto gp = validation::findGnuplot();
  if (gp.available) {
    const auto drawn = validation::renderPlot(gp, validation::PlotFormat::Auto, fig, *report + "/speed_error");
    if (!drawn.ok) std::cerr << "note: plot not drawn: " << drawn.error << "\n";
  }
  std::cout << "wrote " << *report << "/speed_error.csv and the plot\n";
  return 0;
}

// ---------------------------------------------------------------------------------------------
// the threshold and architecture study [D Sec. 6.2.6, Fig. 6.8-6.11]

int runStudy(const FlagValues& a) {
  const std::optional<std::string> report = optionalFlag(a, "report");
  if (!report) throw UsageError{"--study needs --report DIR"};
  requireFolder(*report);
  WrapStudyOptions o;
  o.thresholds.clear();
  for (const auto& t : splitList(a.get("thresholds", "0.01,0.05,0.1"))) {
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (*end != '\0' || !(v >= 0.0 && v < 1.0)) throw UsageError{"--thresholds: '" + t + "' is not in [0, 1)"};
    o.thresholds.push_back(v);
  }
  o.architectures = splitList(a.get("architectures", "1x32,3x32"));
  for (const auto& h : o.architectures) parseHidden(h);  // validate before training
  o.samples = a.getInt("samples", 10000);
  if (o.samples < 10) throw UsageError{"--samples must be at least 10"};
  TrainOptions& opt = o.train;
  opt.epochs = static_cast<int>(a.getInt("epochs", 60));
  opt.batch = static_cast<int>(a.getInt("batch", 64));
  opt.learning_rate = a.getDouble("lr", 1e-3);
  opt.seed = static_cast<unsigned long long>(a.getInt("seed", 1));
  if (opt.epochs < 1 || opt.batch < 1) throw UsageError{"--epochs and --batch must be positive"};

  const WrapStudy study = runWrapThresholdStudy(o, [](const WrapStudyCurve& c) {
    std::cout << "train-wrap --study: threshold " << c.threshold << ", " << c.architecture << ": validation rms "
              << c.val_rms << " (size units)\n" << std::flush;
  });

  // CSV: the sweep, the exact library, then x and its derivative per network; a plot per threshold
  const std::vector<double>& xs = study.ins_x;
  validation::CsvTable t;
  t.header = {"ins_x", "x_exact", "dxdins_exact"};
  validation::PlotFigure fig;
  fig.title = "x_alpha (alpha 0.5) and d x_alpha / d ins_x near the contact change, by threshold and network";
  fig.columns = 2;
  const size_t na = o.architectures.size();  // curves: threshold-major
  for (size_t i = 0; i < o.thresholds.size(); ++i) {
    const double thr = o.thresholds[i];
    std::vector<validation::PlotLine> lx{validation::makePlotLine("exact library", xs, study.x_exact)},
        lj{validation::makePlotLine("exact library (differences)", xs, study.dxdins_exact)};
    for (size_t j = 0; j < na; ++j) {
      const WrapStudyCurve& c = study.curves[i * na + j];
      const std::string name = c.architecture + " thr " + num(thr, 3);
      t.header.push_back("x_" + name);
      t.header.push_back("dxdins_" + name);
      lx.push_back(validation::makePlotLine(c.architecture, xs, c.x));
      lj.push_back(validation::makePlotLine(c.architecture, xs, c.dxdins));
    }
    fig.panels.push_back(validation::makeXYPanel("x_alpha.x, threshold " + num(100 * thr, 3) + "%", "ins_x", "x_alpha.x", lx));
    fig.panels.push_back(validation::makeXYPanel("d x_alpha.x / d ins_x, threshold " + num(100 * thr, 3) + "%", "ins_x",
                                                 "Jacobian entry", lj));
  }
  for (size_t k = 0; k < xs.size(); ++k) {
    std::vector<double> row{xs[k], study.x_exact[k], study.dxdins_exact[k]};
    for (const auto& c : study.curves) row.push_back(c.x[k]), row.push_back(c.dxdins[k]);
    t.addRow(row);
  }
  osim::writeFileAtomic(*report + "/study.csv", validation::formatCsv(t));
  const auto gp = validation::findGnuplot();
  if (gp.available) {
    const auto drawn = validation::renderPlot(gp, validation::PlotFormat::Auto, fig, *report + "/study");
    if (!drawn.ok) std::cerr << "note: plot not drawn: " << drawn.error << "\n";
  }
  std::cout << "wrote " << *report << "/study.csv and the plot\n";
  return 0;
}

// ---------------------------------------------------------------------------------------------
// a group of wrapping double pendulums on one network (issue 7, Results)

int runPendulums(const FlagValues& a) {
  const std::string file = a.get("pendulums", "");
  std::shared_ptr<const Mlp> net;
  try {
    net = loadWrapNetwork(file);
  } catch (const std::runtime_error& e) {  // NetworkFormatError included
    throw UsageError{e.what()};
  }
  if (net->meta.count("surface") && net->meta.at("surface") != "cylinder")
    throw UsageError{"--pendulums " + file + ": the pendulums wrap a cylinder, this network is for a " +
                     net->meta.at("surface")};
  const long count = a.getInt("count", 8);
  const double duration = a.getDouble("duration", 2.0);
  const double tol = a.getDouble("tol", 1e-12);
  const unsigned seed = static_cast<unsigned>(a.getInt("seed", 1));
  if (count < 1 || count > 1000) throw UsageError{"--count must be between 1 and 1000"};
  if (!(duration > 0.0 && duration <= 1000.0)) throw UsageError{"--duration must be in (0, 1000] s"};
  if (!(tol > 0.0 && tol < 1.0)) throw UsageError{"--tol must be in (0, 1)"};
  const std::optional<std::string> report = optionalFlag(a, "report");
  if (report) requireFolder(*report);
  WrapMassOptions wrap;
  wrap.model = WrapModel::Neural;
  wrap.network = net;
  wrap.network_fd_jdot = a.has("fd-jdot");
  const auto specs = scenes::makeWrapPendulumGroup(static_cast<int>(count), seed);
  std::vector<scenes::WrapPendulumRun> runs;
  for (size_t i = 0; i < specs.size(); ++i) {
    runs.push_back(scenes::runWrapPendulum(specs[i], wrap, duration, tol));
    std::cout << "train-wrap --pendulums: " << i + 1 << "/" << specs.size() << " done, drift "
              << num(runs.back().max_drift, 3) << " J, " << num(runs.back().wall_s, 3) << " s\n" << std::flush;
  }
  double worst = 0.0;
  long fallbacks = 0, evaluations = 0;
  for (const auto& r : runs) {
    worst = std::max(worst, r.max_drift);
    fallbacks += r.fallbacks;
    evaluations += r.evaluations;
  }
  std::cout << count << " wrapping double pendulums (seed " << seed << ") on " << file << " (" << net->architecture()
            << "), " << num(duration, 4) << " s rk45 rtol = atol = " << num(tol, 2) << ", Jdot "
            << (wrap.network_fd_jdot ? "by forward differences [D Eq. 5.58]" : "exact") << ":\n"
            << scenes::formatWrapPendulumTable(runs) << "largest energy drift " << num(worst, 3) << " J; " << fallbacks
            << " of " << evaluations << " wrap evaluations fell back to the smooth model\n";
  if (report) {
    validation::CsvTable t;
    t.header = {"pendulum", "origin_x", "origin_y", "insertion_x", "insertion_y", "radius", "tilt", "q2_0", "E0",
                "max_drift", "max_10ms_change", "contact_changes", "steps", "evaluations", "fallbacks", "wall_s"};
    for (size_t i = 0; i < runs.size(); ++i) {
      const auto& r = runs[i];
      const auto& s = r.spec;
      t.addRow({double(i), s.origin.x(), s.origin.y(), s.insertion.x(), s.insertion.y(), s.radius, s.tilt, s.q2, r.E0,
                r.max_drift, r.max_step_change, double(r.contact_changes), double(r.steps), double(r.evaluations),
                double(r.fallbacks), r.wall_s});
    }
    osim::writeFileAtomic(*report + "/pendulums.csv", validation::formatCsv(t));
    std::cout << "wrote " << *report << "/pendulums.csv\n";
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// networks for a model (issue 22): --for MODEL.osim (--coordinates LIST | --ranges default)
// [--check NETWORKS | --out DIR]. Progress goes to stdout (flushed line by line), so stderr holds
// only warnings and the error line.

struct ModelPoses {
  osim::ModelDescription d;
  osim::BuildResult build;
  std::vector<VecX> poses;
  std::string described;  // "238 frames of a.mot" / "500 poses within the coordinate ranges"
};

ModelPoses readModelPoses(const FlagValues& a) {
  ModelPoses m;
  const std::string model_file = a.get("for", "");
  const bool has_coords = a.has("coordinates"), has_ranges = a.has("ranges");
  if (has_coords == has_ranges) throw UsageError{"--for needs one of --coordinates Q.mot[,Q2.mot...] or --ranges default"};
  if (has_ranges && a.get("ranges", "") != "default")
    throw UsageError{"--ranges takes 'default' (the model's coordinate ranges), got '" + a.get("ranges", "") + "'"};
  if (a.has("frames") && !has_ranges) throw UsageError{"--frames needs --ranges default"};
  const long frames = a.getInt("frames", 500);
  if (frames < 1 || frames > 10000000) throw UsageError{"--frames must be between 1 and 1e7"};
  m.d = osim::readOsimModel(model_file);  // ConvertError: FILE:LINE: ...
  osim::BuildOptions opt;
  opt.constraints = false;  // poses as given, nothing enforced (as `redmax lengths`)
  m.build = osim::buildCoreModel(m.d, opt);
  for (const auto& w : m.build.warnings) std::cerr << "warning: " << w << "\n";
  const int nr = m.build.model.nr();
  if (has_coords) {
    const std::vector<std::string> files = splitList(a.get("coordinates", ""));
    if (files.empty()) throw UsageError{"--coordinates needs at least one file"};
    for (const auto& f : files) {
      const osim::Storage st = osim::readStorage(f);
      const osim::CoordinateRows rows = osim::coordinateRows(st, m.d.coordinates, m.build.coordinate_index, nr, f);
      if (rows.missing > 0)
        std::cerr << "warning: " << rows.missing << " coordinate(s) not in " << f << ": held at their default values\n";
      m.poses.insert(m.poses.end(), rows.q.begin(), rows.q.end());
    }
    m.described = std::to_string(m.poses.size()) + " frames of " + a.get("coordinates", "");
  } else {
    // uniform within each coordinate's range, seeded; a coordinate a CoordinateCouplerConstraint
    // makes dependent follows its function (else coupled coordinates, a knee's patella, take poses
    // the model never reaches)
    std::map<std::string, int> index;
    for (size_t ci = 0; ci < m.d.coordinates.size(); ++ci) index[m.d.coordinates[ci].name] = m.build.coordinate_index[ci];
    struct Coupler {
      int dependent;
      std::vector<int> independent;
      AxisFunctionPtr f;
      double scale;
    };
    std::vector<Coupler> couplers;
    for (const auto& c : m.d.constraints) {
      if (c.kind != osim::ConstraintKind::CoordinateCoupler || !c.enforced || !c.function) continue;
      Coupler cp{index.count(c.dependent_coordinate) ? index[c.dependent_coordinate] : -1, {}, nullptr, c.scale_factor};
      for (const auto& n : c.independent_coordinates) cp.independent.push_back(index.count(n) ? index[n] : -1);
      bool ok = cp.dependent >= 0;
      for (int k : cp.independent) ok = ok && k >= 0;
      if (!ok) continue;
      cp.f = osim::makeCoreFunction(*c.function, static_cast<int>(cp.independent.size()), model_file,
                                    "CoordinateCouplerConstraint '" + c.name + "'");
      couplers.push_back(std::move(cp));
    }
    std::mt19937_64 rng(static_cast<unsigned long long>(a.getInt("seed", 1)));
    for (long f = 0; f < frames; ++f) {
      VecX q = VecX::Zero(nr);
      for (size_t ci = 0; ci < m.d.coordinates.size(); ++ci) {
        const int k = m.build.coordinate_index[ci];
        if (k < 0) continue;
        const auto& c = m.d.coordinates[ci];
        const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
        q[k] = c.locked ? c.default_value : c.range_min + (c.range_max - c.range_min) * u;
      }
      for (const Coupler& cp : couplers) {
        VecJ x(static_cast<Eigen::Index>(cp.independent.size()));
        for (size_t j = 0; j < cp.independent.size(); ++j) x[static_cast<Eigen::Index>(j)] = q[cp.independent[j]];
        FunctionValue v;
        cp.f->evaluate(x, 0, v);
        q[cp.dependent] = cp.scale * v.value;
      }
      m.poses.push_back(std::move(q));
    }
    m.described = std::to_string(frames) + " poses drawn within the coordinate ranges (seed " +
                  std::to_string(a.getInt("seed", 1)) + "; " + std::to_string(couplers.size()) +
                  " coupled coordinate(s) following their function)";
  }
  if (m.poses.empty()) throw UsageError{"no poses: the coordinates files have no rows"};
  return m;
}

std::string safeFileName(const std::string& name) {
  std::string s;
  for (char c : name) s += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ? c : '_';
  return s.empty() ? "wrap" : s;
}

int runCheckNetworks(const FlagValues& a, const ModelPoses& m, const std::vector<WrapObjectInputs>& inputs) {
  const std::string path = a.get("check", "");
  WrapNetworkSet set;
  try {
    set = loadWrapNetworks(path);
  } catch (const NetworkFormatError& e) {
    throw UsageError{e.what()};  // FILE:LINE: what is wrong
  } catch (const std::runtime_error& e) {
    throw UsageError{std::string("--check: ") + e.what()};
  }
  WrapMassOptions o;
  set.applyTo(o);
  const std::vector<double> alphas{0.1, 0.3, 0.5, 0.7, 0.9};
  const auto rows = checkWrapNetworks(
      inputs, [&](const std::string& name, WrapType t) { return o.networkFor(name, wrapTypeName(t)); }, alphas);
  std::cout << "check " << path << " on " << a.get("for", "") << ", " << m.described
            << " (position error against the exact library at alpha 0.1..0.9 where the network serves, in radii):\n";
  std::printf("%-28s %-10s %12s %12s %9s %10s %10s  %s\n", "wrap object", "surface", "evaluations", "fallbacks",
              "share", "rms", "max", "reasons");
  long E = 0, F = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    std::string reasons;
    for (const auto& [why, n] : r.by_reason) reasons += (reasons.empty() ? "" : "; ") + toString(why) + " " + std::to_string(n);
    std::printf("%-28s %-10s %12ld %12ld %8.2f%% %10.4g %10.4g  %s\n", r.name.c_str(),
                wrapTypeName(inputs[i].surface.type).c_str(), r.evaluations, r.fallbacks,
                r.evaluations ? 100.0 * r.fallbacks / r.evaluations : 0.0, r.rms, r.max, reasons.c_str());
    E += r.evaluations;
    F += r.fallbacks;
  }
  std::printf("total: %ld of %ld wrapped-segment evaluations fell back to the smooth model (%.2f%%)\n", F, E,
              E ? 100.0 * F / E : 0.0);
  return 0;
}

int runForModel(const FlagValues& a, const CLI::App& app) {
  if (a.has("check") && a.has("out")) throw UsageError{"--check reads networks, --out writes them: give one"};
  if (!a.has("check") && !a.has("out")) throw UsageError{"--for needs --out DIR (train) or --check NETWORKS"};
  for (const char* f : {"surface", "hidden", "init", "compare", "study", "pendulums"})
    if (a.has(f)) throw UsageError{std::string("--") + f + " does not go with --for"};
  ModelWrapTrainOptions o;
  TrainOptions& t = o.train;
  t.hidden = parseHidden(a.get("architecture", "3x32"));
  o.samples = a.getInt("samples", 8000);
  t.epochs = static_cast<int>(a.getInt("epochs", 40));
  t.batch = static_cast<int>(a.getInt("batch", 64));
  t.learning_rate = a.getDouble("lr", 3e-3);
  t.seed = static_cast<unsigned long long>(a.getInt("seed", 1));
  t.threads = static_cast<int>(a.getInt("threads", 1));
  t.shards = static_cast<int>(a.getInt("shards", t.threads));
  o.threshold = a.getDouble("threshold", 0.01);
  o.compact = a.getDouble("compact", 4.0);
  if (o.samples < 10 || o.samples > 100000000) throw UsageError{"--samples must be between 10 and 1e8"};
  if (t.epochs < 1 || t.batch < 1) throw UsageError{"--epochs and --batch must be positive"};
  if (!(t.learning_rate > 0.0 && t.learning_rate < 1.0)) throw UsageError{"--lr must be in (0, 1)"};
  if (t.threads < 1 || t.threads > 256 || t.shards < 1 || t.shards > 4096)
    throw UsageError{"--threads must be between 1 and 256, --shards between 1 and 4096"};
  if (!(o.threshold >= 0.0 && o.threshold < 1.0)) throw UsageError{"--threshold must be in [0, 1)"};
  if (!(o.compact > 0.0 && o.compact <= 1000.0)) throw UsageError{"--compact must be in (0, 1000] radii"};
  std::string dir;
  if (a.has("out")) {
    dir = a.get("out", "");
    std::error_code ec;
    if (dir.empty()) throw UsageError{"--out needs a folder"};
    if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
      throw UsageError{"--out " + dir + ": exists and is not a folder (--for writes a folder of networks)"};
  }

  const auto t0 = Clock::now();
  ModelPoses m;
  try {
    m = readModelPoses(a);
  } catch (const osim::ConvertError& e) {
    throw UsageError{e.what()};  // FILE:LINE: what is wrong
  } catch (const ModelError& e) {
    throw UsageError{a.get("for", "") + ": " + e.what()};
  }
  // the wrapping muscles the smooth model (and so the network model) takes; the others keep the exact
  // model at run time (two wrap objects able to share a segment) and need no network
  std::vector<Muscle> muscles;
  for (const Muscle& mu : m.build.model.muscles()) {
    if (mu.path.wraps.empty()) continue;
    Muscle probe = mu;
    probe.wrap = WrapMassOptions{};
    // two wrap objects able to share a segment: the smooth model composes them, a network does not
    const std::string why = hasSharedWrapSegments(probe) ? "two wrap objects can share a segment, which a network "
                                                           "does not compose"
                                                         : wrapMassPointsUnsupportedReason(probe);
    if (why.empty()) muscles.push_back(mu);
    else std::cout << "train-wrap: muscle '" << mu.name << "' skipped (the wrap models cannot take its path: " << why << ")\n";
  }
  const std::vector<WrapObjectInputs> inputs = collectWrapObjectInputs(m.build.model.skeleton(), muscles, m.poses);
  std::cout << "train-wrap --for " << a.get("for", "") << ": " << m.described << "; " << inputs.size()
            << " wrap object(s) take wrapped segments\n"
            << std::flush;
  if (a.has("check")) return runCheckNetworks(a, m, inputs);
  if (inputs.empty()) throw UsageError{a.get("for", "") + ": no muscle wraps a surface over these poses: nothing to train"};
  requireFolder(dir);

  std::string manifest = "redmax-wrap-networks 1\n# written by: " + commandLine(app) +
                         "\n# one network per wrap object (core/muscles/wrap/network_set.hpp)\n";
  int trained = 0, k = 0;
  for (const WrapObjectInputs& in : inputs) {
    ++k;
    const std::string head = "train-wrap: [" + std::to_string(k) + "/" + std::to_string(inputs.size()) +
                             "] wrap object '" + in.name + "' (" + wrapTypeName(in.surface.type) + ", " +
                             std::to_string(in.muscles.size()) + " muscle(s), " + std::to_string(in.q1.size()) +
                             " evaluations)";
    if (in.surface.type != WrapType::Cylinder && in.surface.type != WrapType::Sphere) {
      std::cout << head << ": skipped, networks take cylinders and spheres; the smooth model serves it\n" << std::flush;
      continue;
    }
    const auto t1 = Clock::now();
    double last = -1e9;
    o.train.on_epoch = [&](const TrainEpoch& e) {
      if (e.elapsed_s - last < 5.0 && e.epoch != o.train.epochs) return;
      last = e.elapsed_s;
      std::cout << head << ": epoch " << e.epoch << "/" << o.train.epochs << ", validation rms " << num(e.val_rms_m)
                << " radii, " << num(e.elapsed_s, 3) << " s\n"
                << std::flush;
    };
    WrapErrorStats err;
    Mlp net = trainWrapObjectNetwork(in, o, &err);
    net.meta["command"] = commandLine(app);
    const std::string file = safeFileName(in.name) + ".txt";
    net.save((std::filesystem::path(dir) / file).string());
    manifest += "wrap " + in.name + " " + file + "\n";
    ++trained;
    std::cout << head << ": error on fresh samples rms " << num(err.rms) << ", max " << num(err.max) << " radii, "
              << num(secondsSince(t1), 3) << " s -> " << file << "\n"
              << std::flush;
  }
  if (trained == 0) throw UsageError{"no wrap object is a cylinder or a sphere: nothing to train"};
  // the manifest last: a run cut short leaves no manifest naming missing files
  const std::string mpath = (std::filesystem::path(dir) / wrapNetworkManifestName()).string();
  osim::writeFileAtomic(mpath, manifest);
  std::cout << "trained " << trained << " network(s) in " << num(secondsSince(t0), 3) << " s; wrote " << mpath
            << " (use: --wrap neural --wrap-network " << dir << ")\n";
  return 0;
}

int runTrainWrap(const CLI::App& app) {
  const FlagValues a(app);
  if (a.has("compare") + a.has("study") + a.has("pendulums") > 1)
    throw UsageError{"--compare, --study and --pendulums exclude each other"};
  if (a.has("for")) return runForModel(a, app);
  for (const char* f : {"check", "coordinates", "ranges", "frames", "architecture"})
    if (a.has(f)) throw UsageError{std::string("--") + f + " needs --for MODEL.osim"};
  if (a.has("pendulums")) return runPendulums(a);
  if (a.has("study")) return runStudy(a);
  return a.has("compare") ? runCompare(a) : runTrain(a, app);
}

// Defaults depend on the mode (training, --compare, --study, --pendulums), so the flags are read
// through FlagValues with each mode's default; the validators check the form here.
void declareTrainWrapFlags(CLI::App& app) {
  const std::string train = "Training", compare = "--compare", study = "--study", pend = "--pendulums";
  app.add_option("--surface", "cylinder (default), sphere, ellipsoid or torus")->type_name("SURFACE");
  app.add_option("--hidden", "the tanh MLP's hidden layers, DEPTHxWIDTH or W1-W2-... (default 6x256)")
      ->type_name("ARCH")
      ->group(train);
  app.add_option("--samples", "samples drawn from the surface type's box (default 30000; --study 10000)")
      ->type_name("N")
      ->check(integer())
      ->group(train);
  app.add_option("--epochs", "training epochs (default 100; --study 60)")->type_name("E")->check(integer())->group(train);
  app.add_option("--batch", "mini-batch size (default 256; --study 64)")->type_name("B")->check(integer())->group(train);
  app.add_option("--lr", "Adam's learning rate (default 1e-4; --study 1e-3)")->type_name("R")->check(number())->group(train);
  app.add_option("--seed", "random seed (default 1); the network is deterministic for a seed")
      ->type_name("S")
      ->check(integer());
  app.add_option("--threshold", "samples with 0 < l/L < threshold are discarded (default 0.01)")
      ->type_name("F")
      ->check(number())
      ->group(train);
  app.add_option("--time-limit", "stop training after this many seconds (default 0: none)")
      ->type_name("SECONDS")
      ->check(number())
      ->group(train);
  app.add_option("--threads", "label samples and compute gradients on T threads (default 1)")
      ->type_name("T")
      ->check(integer())
      ->group(train);
  app.add_option("--shards",
                 "every mini-batch is cut into S shards (default T) summed in order, so the\n"
                 "network depends on S and the seed, not on T (S = 1: serial)")
      ->type_name("S")
      ->check(integer())
      ->group(train);
  app.add_option("--init",
                 "continue training from that network (same surface and --hidden; its\n"
                 "normalisation is kept, Adam restarts); its command and losses are kept in the\n"
                 "new file's meta as init_*")
      ->type_name("NET.txt")
      ->group(train);
  app.add_option("--compact",
                 "the compact input map u = q / (1 + |q| / C) and displacement outputs (C in radii;\n"
                 "cylinder and sphere; --for: default 4); 0 (default without --for): the older map")
      ->type_name("C")
      ->check(number())
      ->group(train);
  app.add_option("--out", "the trained network (required for training; --for: a folder of networks\nand its manifest wrap_networks.txt)")
      ->type_name("NET.txt|DIR")
      ->group(train);
  app.add_option("--report",
                 "training: loss.csv and a loss plot; --compare: speed_error.csv and a plot;\n"
                 "--study: study.csv and a plot; --pendulums: pendulums.csv")
      ->type_name("DIR");
  const std::string forg = "--for";
  app.add_option("--for",
                 "train one network per wrap object the model's muscles use, on the surface-frame\n"
                 "inputs they see over the poses (compact map), and write DIR/wrap_networks.txt")
      ->type_name("MODEL.osim")
      ->group(forg);
  app.add_option("--coordinates", "--for: the poses, one or more coordinate files (.mot/.sto)")
      ->type_name("Q.mot,...")
      ->group(forg);
  app.add_option("--ranges",
                 "--for: poses drawn uniformly within the model's coordinate ranges (coordinates a\n"
                 "CoordinateCouplerConstraint makes dependent follow its function)")
      ->type_name("default")
      ->group(forg);
  app.add_option("--frames", "--ranges: how many poses (default 500)")->type_name("N")->check(integer())->group(forg);
  app.add_option("--architecture", "--for: the networks' hidden layers (default 3x32)")->type_name("ARCH")->group(forg);
  app.add_option("--check",
                 "--for: instead of training, evaluate these networks (a file, a manifest or a\n"
                 "folder) on the poses: fallbacks to the smooth model and position error per wrap object")
      ->type_name("NETWORKS")
      ->group(forg);
  app.add_flag("--compare")->description("time networks, the smooth model and the exact library per mass point")->group(compare);
  app.add_option("--nets", "trained networks to compare")->type_name("A.txt,B.txt")->group(compare);
  app.add_option("--untrained", "network sizes timed only (default 6x256), or none")
      ->type_name("6x256,...|none")
      ->group(compare);
  app.add_option("--muscles", "muscles with random end points and velocities (default 200)")
      ->type_name("M")
      ->check(integer())
      ->group(compare);
  app.add_option("--mass-points", "mass points per muscle (default 20)")->type_name("N")->check(integer())->group(compare);
  app.add_option("--width", "the smooth model's band width in surface sizes (default 0.05)")
      ->type_name("W")
      ->check(number())
      ->group(compare);
  app.add_flag("--study")->description("the threshold and architecture study [D Sec. 6.2.6]")->group(study);
  app.add_option("--thresholds", "thresholds to train with (default 0.01,0.05,0.1)")
      ->type_name("LIST")
      ->group(study);
  app.add_option("--architectures", "hidden layers to train (default 1x32,3x32)")->type_name("LIST")->group(study);
  app.add_option("--pendulums", "a group of wrapping double pendulums on this cylinder network")
      ->type_name("NET.txt")
      ->group(pend);
  app.add_option("--count", "pendulums (default 8)")->type_name("N")->check(integer())->group(pend);
  app.add_option("--duration", "simulated seconds (default 2)")->type_name("S")->check(number())->group(pend);
  app.add_option("--tol", "rk45's rtol = atol (default 1e-12)")->type_name("TOL")->check(number())->group(pend);
  app.add_flag("--fd-jdot")->description("Jdot by the forward difference [D Eq. 5.58] instead of exact")->group(pend);
}

CommandRegistration reg(
    {"train-wrap", "train Type III wrap networks (one, or all a model needs), or compare wrap models",
     [](CLI::App& app) {
       declareTrainWrapFlags(app);
       app.footer("usage: redmax train-wrap --surface cylinder|sphere|ellipsoid|torus [--hidden 6x256] [--samples N]\n"
     "                         [--epochs E] [--batch B] [--lr 1e-4] [--seed S] [--threshold 0.01]\n"
     "                         [--time-limit SECONDS] [--threads T [--shards S]] [--init NET.txt]\n"
     "                         --out NET.txt [--report DIR]\n"
     "       redmax train-wrap --for MODEL.osim (--coordinates Q.mot[,...] | --ranges default [--frames N])\n"
     "                         [--architecture 3x32] [--samples N] [--epochs E] [--compact C] [--seed S]\n"
     "                         (--out DIR | --check NETWORKS)\n"
     "       redmax train-wrap --compare --surface cylinder|sphere|ellipsoid|torus [--nets A.txt,B.txt]\n"
     "                         [--untrained 6x256,...|none]\n"
     "                         [--muscles M] [--mass-points N] [--width W] [--seed S] --report DIR\n"
     "       redmax train-wrap --study [--thresholds 0.01,0.05,0.1] [--architectures 1x32,3x32] [--samples N]\n"
     "                         [--epochs E] [--batch B] [--lr R] [--seed S] --report DIR\n"
     "       redmax train-wrap --pendulums NET.txt [--count 8] [--duration 2] [--tol 1e-12] [--seed S] [--fd-jdot]\n"
     "                         [--report DIR]\n"
     "Training [D Sec. 5.3.3.1]: N samples (default 30000) drawn uniformly from the surface type's box\n"
     "(tools/wrap_training/train.hpp makeDefaultWrapBox; units of the surface size) and labelled by the exact\n"
     "library; samples with 0 < l/L < threshold are discarded. A tanh MLP (--hidden DEPTHxWIDTH or W1-W2-...,\n"
     "default 6x256) is trained with Adam (--lr, default 1e-4; --batch default 256) on the mean squared error\n"
     "for E epochs (default 100) or until --time-limit. Deterministic for a seed. The network file records\n"
     "the command, seed, losses and the error on fresh samples. --report DIR writes loss.csv and a loss plot.\n"
     "--threads T labels samples and computes gradients on T threads; every mini-batch is cut into S shards\n"
     "(default T) summed in order, so the network depends on S and the seed, not on T (S = 1: serial).\n"
     "--init NET.txt continues training from that network (same surface and --hidden; its normalisation is kept,\n"
     "Adam restarts); its command and losses are kept in the new file's meta as init_*.\n"
     "--compact C: inputs through the compact map u = q / (1 + |q| / C) (same samples, box mapped) and the\n"
     "point's displacement from the straight line as output (meta wrap_map compact C).\n"
     "--for MODEL.osim: for every wrap object (cylinder or sphere) the model's muscles wrap over the poses\n"
     "(--coordinates files, or --ranges default: --frames poses, default 500, uniform in the coordinate ranges,\n"
     "coupled coordinates following their CoordinateCouplerConstraint),\n"
     "collects the surface-frame end points of its wrapped segments, trains a network on them (jittered, random\n"
     "alpha; defaults --architecture 3x32, --samples 8000, --epochs 40, --batch 64, --lr 3e-3, --compact 4)\n"
     "and writes DIR/NAME.txt per wrap object and the manifest DIR/wrap_networks.txt, with progress on stdout.\n"
     "--check NETWORKS evaluates networks instead: per wrap object the evaluations, fallbacks to the smooth\n"
     "model by reason, and the position error against the exact library (radii) where the network serves.\n"
     "--compare: M muscles (default 200) x N mass points (default 20) with random end points and velocities;\n"
     "for the exact library (J, Jdot by central differences, wraps shared by a muscle's points), the smooth\n"
     "model (band width W surface sizes, default 0.05) and each network (trained ones from --nets; --untrained\n"
     "sizes are timed only), prints and writes\n"
     "DIR/speed_error.csv and a plot: microseconds per mass point (position + J + Jdot) and position error.\n"
     "--study [D Sec. 6.2.6]: for each threshold and architecture, trains a cylinder network (defaults: 10000\n"
     "samples, 60 epochs, batch 64, lr 1e-3) and writes DIR/study.csv and a plot of x_alpha.x (alpha 0.5) and\n"
     "d x_alpha.x / d ins_x against ins_x as the insertion moves through the contact change, with the exact library.\n"
     "--pendulums NET.txt: a group of wrapping double pendulums (validation/scenes/wrap_pendulums.hpp; origin,\n"
     "insertion, radius and surface tilt drawn with the seed) all on one cylinder network (WrapModel::Neural),\n"
     "gravity only, rk45 at --tol for --duration s; prints each one's energy drift, contact changes, steps and\n"
     "smooth-model fallbacks (--fd-jdot: Jdot by the forward difference [D Eq. 5.58]); --report DIR writes\n"
     "DIR/pendulums.csv.");
       return [&app] { return runTrainWrap(app); };
     }});

}  // namespace
}  // namespace redmax::cli
