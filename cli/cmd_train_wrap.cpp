// `redmax train-wrap`: train the Type III wrap network on samples of the exact wrapping library
// [D Sec. 5.3.3.1], or (--compare) time networks, the smooth model and the exact library per mass
// point (position + Jacobian + Jdot) against their position error.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>
#include <optional>
#include <string>
#include <vector>

#include "cli/flags.hpp"
#include "converter/atomic_file.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/muscles/wrap/train.hpp"
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
    if (init->meta.count("surface") && init->meta.at("surface") != wrapTypeName(type))
      throw UsageError{"--init " + *f + " is a " + init->meta.at("surface") + " network, not " + wrapTypeName(type)};
    if (init->architecture() != Mlp(wrapInputSize(type), opt.hidden, 3, 0).architecture())
      throw UsageError{"--init " + *f + " is " + init->architecture() + ", --hidden asks for another architecture"};
    opt.init = &*init;
  }
  const std::optional<std::string> report = optionalFlag(a, "report");
  if (report) requireFolder(*report);

  // samples of the exact library over the stated box [D Sec. 5.3.3.1]
  const WrapInputBox box = makeDefaultWrapBox(type);
  const WrapOracle oracle = makeExactWrapOracle(type);
  const auto t_data = Clock::now();
  const WrapTrainingSet data = makeWrapTrainingSet(box, oracle, samples, threshold, opt.seed, opt.threads);
  std::cerr << "train-wrap: " << wrapTypeName(type) << ", " << samples << " samples kept of " << data.drawn
            << " drawn (" << data.invalid << " with an end inside the surface, " << data.near_contact
            << " with 0 < l/L < " << threshold << " discarded; " << data.wrapped << " kept samples wrap), "
            << num(secondsSince(t_data), 3) << " s\n";

  // progress: a line every 2 s and at the end
  double last_print = -1e9;
  opt.on_epoch = [&](const TrainEpoch& e) {
    if (e.elapsed_s - last_print < 2.0 && e.epoch != opt.epochs) return;
    last_print = e.elapsed_s;
    std::cerr << "train-wrap: epoch " << e.epoch << "/" << opt.epochs << ", " << e.steps << " steps, train mse "
              << num(e.train_mse) << ", validation mse " << num(e.val_mse) << ", validation rms " << num(e.val_rms_m)
              << " (size units), " << num(e.elapsed_s, 3) << " s\n";
  };
  std::vector<TrainEpoch> history;
  Mlp net = trainWrapNetwork(data, box, opt, &history);

  // error on fresh samples, all of them (also those near the contact change)
  const WrapTrainingSet test = makeWrapTrainingSet(box, oracle, std::min(samples, 20000L), 0.0, opt.seed + 1000003, opt.threads);
  const WrapErrorStats err = calcWrapNetworkError(net, test);
  if (init)
    for (const char* k : {"command", "adam", "epochs", "final_val_rms_m", "train_seconds", "test_rms_m"})
      if (init->meta.count(k)) net.meta[std::string("init_") + k] = init->meta.at(k);
  net.meta["surface"] = wrapTypeName(type);
  net.meta["command"] = commandLine(app);
  net.meta["threshold"] = num(threshold, 6);
  net.meta["test_rms_m"] = num(err.rms, 6);
  net.meta["test_max_m"] = num(err.max, 6);
  net.meta["box"] = "core/muscles/wrap/train.hpp makeDefaultWrapBox (units of the surface size)";
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

struct CompareRow {
  std::string method;
  long parameters = 0;
  double us_per_point = 0.0;
  double rms = NAN, max = NAN;
  std::string note;
};

int runCompare(const FlagValues& a) {
  const WrapType type = parseWrapType(a.get("surface", "cylinder"));
  const std::optional<std::string> report = optionalFlag(a, "report");
  if (!report) throw UsageError{"--compare needs --report DIR"};
  requireFolder(*report);
  const long muscles = a.getInt("muscles", 200);
  const int points = static_cast<int>(a.getInt("mass-points", 20));
  if (muscles < 1 || points < 1) throw UsageError{"--muscles and --mass-points must be positive"};
  const unsigned long long seed = static_cast<unsigned long long>(a.getInt("seed", 1));
  const double width = a.getDouble("width", 0.05);
  const WrapInputBox box = makeDefaultWrapBox(type);
  std::vector<std::pair<std::string, Mlp>> nets;
  for (const auto& f : splitList(a.get("nets", ""))) {
    try {
      nets.emplace_back(std::filesystem::path(f).stem().string(), Mlp::load(f));
    } catch (const NetworkFormatError& e) {
      throw UsageError{e.what()};
    } catch (const std::runtime_error& e) {
      throw UsageError{e.what()};
    }
    const Mlp& n = nets.back().second;
    if (n.inputs() != wrapInputSize(type) || n.outputs() != 3 || (n.meta.count("surface") && n.meta.at("surface") != wrapTypeName(type)))
      throw UsageError{f + ": not a " + wrapTypeName(type) + " wrap network"};
  }
  const std::string untrained = a.get("untrained", "6x256");
  for (const auto& spec : untrained == "none" ? std::vector<std::string>{} : splitList(untrained)) {
    // timing only: the cost of a network does not depend on its weights
    Mlp n(wrapInputSize(type), parseHidden(spec), 3, seed);
    n.input_min = box.lo;
    n.input_max = box.hi;
    nets.emplace_back(spec + " (untrained, timing only)", n);
  }

  // muscles: end points from the default box (valid ones), velocities random, 20 mass points each
  const WrapOracle oracle = makeExactWrapOracle(type);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0), uv(-1.0, 1.0);
  std::vector<VecX> inputs;  // one per muscle (alpha slot unused)
  std::vector<Vec3> v1s, v2s;
  while (static_cast<long>(inputs.size()) < muscles) {
    VecX x(box.lo.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = box.lo[i] + (box.hi[i] - box.lo[i]) * u01(rng);
    x[6] = 0.5;
    if (!oracle(x).valid) continue;
    inputs.push_back(x);
    v1s.emplace_back(uv(rng), uv(rng), uv(rng));
    v2s.emplace_back(uv(rng), uv(rng), uv(rng));
  }
  std::vector<double> alphas(points);
  for (int k = 0; k < points; ++k) alphas[k] = (k + 0.5) / points;
  const long total_points = muscles * points;

  // exact positions (the reference)
  std::vector<Vec3> exact(total_points);
  for (long m = 0; m < muscles; ++m) {
    const WrapSurface s = makeWrapSurfaceFromInput(type, inputs[m]);
    const Vec3 p1 = inputs[m].segment<3>(0), p2 = inputs[m].segment<3>(3);
    const WrapResult r = calcWrap(s, p1, p2);
    for (int k = 0; k < points; ++k) exact[m * points + k] = calcWrappedPathPoint(s, r, p1, p2, alphas[k]);
  }
  auto errors = [&](const std::vector<Vec3>& x, CompareRow& row) {
    double se = 0.0, mx = 0.0;
    for (long i = 0; i < total_points; ++i) {
      const double e = (x[i] - exact[i]).norm();
      se += e * e;
      mx = std::max(mx, e);
    }
    row.rms = std::sqrt(se / total_points);
    row.max = mx;
  };
  // repeat a timed loop until it has run 0.3 s; microseconds per mass point
  auto timePerPoint = [&](const std::function<void()>& all_points) {
    long reps = 0;
    const auto t0 = Clock::now();
    do {
      all_points();
      ++reps;
    } while (secondsSince(t0) < 0.3);
    return 1e6 * secondsSince(t0) / (static_cast<double>(reps) * total_points);
  };
  std::vector<CompareRow> rows;
  volatile double sink = 0.0;

  // exact library: position, then J and Jdot by central differences, one wrap per perturbed pair
  // of end points shared by the muscle's mass points, as the runtime does (calcExactWrapPointsFd:
  // 1 + 12 + 24 wraps per muscle)
  {
    CompareRow row;
    row.method = "exact library + central differences";
    const double h = 1e-6;
    std::vector<Vec3> xp(points), xm(points);
    auto evalAll = [&](const WrapSurface& s, const Vec3& p1, const Vec3& p2, std::vector<Vec3>& xs) {
      const WrapResult r = calcWrap(s, p1, p2);
      for (int k = 0; k < points; ++k) xs[k] = calcWrappedPathPoint(s, r, p1, p2, alphas[k]);
    };
    std::vector<Eigen::Matrix<double, 3, 6>> J(points), Jp(points), Jm(points);
    auto jac = [&](const WrapSurface& s, const Vec3& p1, const Vec3& p2, std::vector<Eigen::Matrix<double, 3, 6>>& Js) {
      for (int i = 0; i < 6; ++i) {
        Vec3 a1 = p1, a2 = p2, b1 = p1, b2 = p2;
        (i < 3 ? a1 : a2)[i % 3] += h;
        (i < 3 ? b1 : b2)[i % 3] -= h;
        evalAll(s, a1, a2, xp);
        evalAll(s, b1, b2, xm);
        for (int k = 0; k < points; ++k) Js[k].col(i) = (xp[k] - xm[k]) / (2 * h);
      }
    };
    std::vector<Vec3> x(points);
    row.us_per_point = timePerPoint([&] {
      for (long m = 0; m < muscles; ++m) {
        const WrapSurface s = makeWrapSurfaceFromInput(type, inputs[m]);
        const Vec3 p1 = inputs[m].segment<3>(0), p2 = inputs[m].segment<3>(3);
        evalAll(s, p1, p2, x);
        jac(s, p1, p2, J);
        jac(s, p1 + h * v1s[m], p2 + h * v2s[m], Jp);
        jac(s, p1 - h * v1s[m], p2 - h * v2s[m], Jm);
        for (int k = 0; k < points; ++k) {
          const Eigen::Matrix<double, 3, 6> Jdot = (Jp[k] - Jm[k]) / (2 * h);
          sink = sink + x[k][0] + J[k](0, 0) + Jdot(0, 0);
        }
      }
    });
    row.rms = row.max = 0.0;
    row.note = "reference; J, Jdot jump at contact changes";
    rows.push_back(row);
  }

  // smooth model
  {
    CompareRow row;
    row.method = "smooth model (width " + num(width, 3) + " size)";
    std::vector<Vec3> x(total_points);
    // the band in units of the surface's size (radius, tube radius, smallest semi-axis)
    auto bandOf = [&](const WrapSurface& s) {
      const double size = type == WrapType::Torus       ? s.inner_radius
                          : type == WrapType::Ellipsoid ? s.dimensions.minCoeff()
                                                        : s.radius;
      return SmoothWrapOptions{width * size};
    };
    for (long m = 0; m < muscles; ++m) {
      const WrapSurface s = makeWrapSurfaceFromInput(type, inputs[m]);
      for (int k = 0; k < points; ++k)
        x[m * points + k] = calcSmoothWrapPoint(s, inputs[m].segment<3>(0), inputs[m].segment<3>(3), alphas[k], bandOf(s));
    }
    errors(x, row);
    row.us_per_point = timePerPoint([&] {
      for (long m = 0; m < muscles; ++m) {
        const WrapSurface s = makeWrapSurfaceFromInput(type, inputs[m]);
        for (int k = 0; k < points; ++k) {
          const auto sp = calcSmoothWrapPointDerivatives(s, inputs[m].segment<3>(0), inputs[m].segment<3>(3), alphas[k],
                                                         v1s[m], v2s[m], bandOf(s));
          sink = sink + sp.x[0] + sp.J(0, 0) + sp.Jdot(0, 0);
        }
      }
    });
    row.note = type == WrapType::Ellipsoid ? "exact J, Jdot (dual numbers); a muscle's points share the plane construction"
                                           : "exact J, Jdot (dual numbers)";
    rows.push_back(row);
  }

  // networks: one batch per muscle (all its mass points), exact Jdot and the forward difference
  for (const auto& [name, net] : nets) {
    std::vector<MatX> X(muscles), Xdot(muscles);
    for (long m = 0; m < muscles; ++m) {
      X[m].resize(net.inputs(), points);
      Xdot[m] = MatX::Zero(net.inputs(), points);
      for (int k = 0; k < points; ++k) {
        X[m].col(k) = inputs[m];
        X[m](6, k) = alphas[k];
        Xdot[m].col(k).segment<3>(0) = v1s[m];
        Xdot[m].col(k).segment<3>(3) = v2s[m];
      }
    }
    MlpWorkspace ws;
    MatX Y, J, Jdot, Yf, Jf, Jdot_fd;
    std::vector<Vec3> x(total_points);
    double jd_diff = 0.0, jd_norm = 0.0;
    long outside = 0;
    for (long m = 0; m < muscles; ++m) {
      net.calcJacobianDot(X[m], Xdot[m], Y, J, Jdot, ws);
      net.calcJacobianDotFd(X[m], Xdot[m], 1e-6, Yf, Jf, Jdot_fd, ws);
      jd_diff += (Jdot_fd - Jdot).squaredNorm();
      jd_norm += Jdot.squaredNorm();
      for (int k = 0; k < points; ++k) {
        x[m * points + k] = Y.col(k);
        if (!net.insideBox(X[m].col(k))) ++outside;
      }
    }
    const bool untrained = name.find("untrained") != std::string::npos;
    CompareRow row;
    row.method = "network " + name;
    row.parameters = net.parameterCount();
    if (!untrained) errors(x, row);
    row.us_per_point = timePerPoint([&] {
      for (long m = 0; m < muscles; ++m) {
        net.calcJacobianDot(X[m], Xdot[m], Y, J, Jdot, ws);
        sink = sink + Y(0, 0) + J(0, 0) + Jdot(0, 0);
      }
    });
    const double fd_us = timePerPoint([&] {
      for (long m = 0; m < muscles; ++m) {
        net.calcJacobianDotFd(X[m], Xdot[m], 1e-6, Y, J, Jdot, ws);
        sink = sink + Y(0, 0) + J(0, 0) + Jdot(0, 0);
      }
    });
    // the same network as a run-time wrap model (network_model.hpp: scaling by the radius, the box
    // test on every input, the smooth model where it fails)
    const bool as_model = networkWrapUnsupportedReason(net).empty() && (type == WrapType::Cylinder || type == WrapType::Sphere);
    std::vector<WrapSurface> surfs;
    for (long m = 0; m < muscles && as_model; ++m) surfs.push_back(makeWrapSurfaceFromInput(type, inputs[m]));
    NetworkWrapWorkspace nws;
    WrapMassPoints wmp;
    std::vector<long> on_net;  // muscles whose scaled inputs stay in the box (timed: the network's cost)
    for (long m = 0; m < muscles && as_model; ++m)
      if (calcNetworkWrapModel(&net, surfs[m], inputs[m].segment<3>(0), inputs[m].segment<3>(3), v1s[m], v2s[m], alphas,
                               true, wmp, nws)
              .usedNetwork())
        on_net.push_back(m);
    double model_us = NAN;
    if (!on_net.empty()) {
      long reps = 0;
      const auto t0 = Clock::now();
      do {
        for (long m : on_net) {
          calcNetworkWrapModel(&net, surfs[m], inputs[m].segment<3>(0), inputs[m].segment<3>(3), v1s[m], v2s[m], alphas,
                               true, wmp, nws);
          sink = sink + wmp.x[0][0] + wmp.J[0](0, 0) + wmp.Jdot[0](0, 0);
        }
        ++reps;
      } while (secondsSince(t0) < 0.3);
      model_us = 1e6 * secondsSince(t0) / (static_cast<double>(reps) * on_net.size() * points);
    }
    const long fell_back = muscles - static_cast<long>(on_net.size());
    row.note = "exact Jdot; Eq. 5.58 FD Jdot (eps 1e-6): " + num(fd_us, 3) + " us/point, rel. diff " +
               num(std::sqrt(jd_diff / std::max(jd_norm, 1e-300)), 2);
    if (as_model)
      row.note += "; as a wrap model (scaling, box test, " + std::to_string(fell_back) + " of " + std::to_string(muscles) +
                  " muscles leave the box at radius 0.5-1.5, timed on the others): " + num(model_us, 3) + " us/point";
    if (outside) row.note += "; " + std::to_string(outside) + " points outside the training box";
    rows.push_back(row);
  }

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
    const auto o = validation::renderPlot(gp, validation::PlotFormat::Auto, fig, *report + "/speed_error");
    if (!o.ok) std::cerr << "note: plot not drawn: " << o.error << "\n";
  }
  std::cout << "wrote " << *report << "/speed_error.csv and the plot\n";
  (void)sink;
  return 0;
}

// ---------------------------------------------------------------------------------------------
// the threshold and architecture study [D Sec. 6.2.6, Fig. 6.8-6.11]

int runStudy(const FlagValues& a) {
  const std::optional<std::string> report = optionalFlag(a, "report");
  if (!report) throw UsageError{"--study needs --report DIR"};
  requireFolder(*report);
  std::vector<double> thresholds;
  for (const auto& t : splitList(a.get("thresholds", "0.01,0.05,0.1"))) {
    char* end = nullptr;
    const double v = std::strtod(t.c_str(), &end);
    if (*end != '\0' || !(v >= 0.0 && v < 1.0)) throw UsageError{"--thresholds: '" + t + "' is not in [0, 1)"};
    thresholds.push_back(v);
  }
  std::vector<std::string> archs = splitList(a.get("architectures", "1x32,3x32"));
  for (const auto& h : archs) parseHidden(h);  // validate before training
  const long samples = a.getInt("samples", 10000);
  if (samples < 10) throw UsageError{"--samples must be at least 10"};
  TrainOptions opt;
  opt.epochs = static_cast<int>(a.getInt("epochs", 60));
  opt.batch = static_cast<int>(a.getInt("batch", 64));
  opt.learning_rate = a.getDouble("lr", 1e-3);
  opt.seed = static_cast<unsigned long long>(a.getInt("seed", 1));
  if (opt.epochs < 1 || opt.batch < 1) throw UsageError{"--epochs and --batch must be positive"};

  // Fig. 6.8's scene: unit cylinder, origin fixed, the insertion moves along x through the contact
  // change (the straight line touches the cylinder at ins_x = -0.33)
  const WrapType type = WrapType::Cylinder;
  const WrapSurface surf = WrapSurface::makeCylinder(1.0, 1000.0);
  const Vec3 ori(-2.0, 1.2, 0.3);
  const double alpha = 0.5;
  const int n = 251;
  std::vector<double> xs(n), x_exact(n), j_exact(n);
  auto exactPoint = [&](double x) {
    const Vec3 ins(x, -1.3, -0.2);
    return calcWrappedPathPoint(surf, calcWrap(surf, ori, ins), ori, ins, alpha);
  };
  for (int k = 0; k < n; ++k) {
    xs[k] = -1.5 + 2.5 * k / (n - 1);
    x_exact[k] = exactPoint(xs[k])[0];
    const double h = 1e-7;  // one-sided near the kink would mix branches: central, tiny step
    j_exact[k] = (exactPoint(xs[k] + h)[0] - exactPoint(xs[k] - h)[0]) / (2 * h);
  }
  const WrapInputBox box = makeDefaultWrapBox(type);
  const WrapOracle oracle = makeExactWrapOracle(type);
  validation::CsvTable t;
  t.header = {"ins_x", "x_exact", "dxdins_exact"};
  std::vector<std::vector<double>> cols;
  validation::PlotFigure fig;
  fig.title = "x_alpha (alpha 0.5) and d x_alpha / d ins_x near the contact change, by threshold and network";
  fig.columns = 2;
  for (double thr : thresholds) {
    const WrapTrainingSet data = makeWrapTrainingSet(box, oracle, samples, thr, opt.seed);
    std::vector<validation::PlotLine> lx{validation::makePlotLine("exact library", xs, x_exact)},
        lj{validation::makePlotLine("exact library (differences)", xs, j_exact)};
    for (const auto& arch : archs) {
      opt.hidden = parseHidden(arch);
      const Mlp net = trainWrapNetwork(data, box, opt);
      MlpWorkspace ws;
      MatX X(8, n), Y, J;
      for (int k = 0; k < n; ++k) X.col(k) << ori, Vec3(xs[k], -1.3, -0.2), alpha, 1.0;
      net.calcJacobian(X, Y, J, ws);
      std::vector<double> xn(n), jn(n);
      for (int k = 0; k < n; ++k) xn[k] = Y(0, k), jn[k] = J(0, 8 * k + 3);
      const std::string name = arch + " thr " + num(thr, 3);
      t.header.push_back("x_" + name);
      t.header.push_back("dxdins_" + name);
      cols.push_back(xn);
      cols.push_back(jn);
      lx.push_back(validation::makePlotLine(arch, xs, xn));
      lj.push_back(validation::makePlotLine(arch, xs, jn));
      std::cerr << "train-wrap --study: threshold " << thr << ", " << arch << ": validation rms "
                << net.meta.at("final_val_rms_m") << " (size units)\n";
    }
    fig.panels.push_back(validation::makeXYPanel("x_alpha.x, threshold " + num(100 * thr, 3) + "%", "ins_x", "x_alpha.x", lx));
    fig.panels.push_back(validation::makeXYPanel("d x_alpha.x / d ins_x, threshold " + num(100 * thr, 3) + "%", "ins_x",
                                                 "Jacobian entry", lj));
  }
  for (int k = 0; k < n; ++k) {
    std::vector<double> row{xs[k], x_exact[k], j_exact[k]};
    for (const auto& c : cols) row.push_back(c[k]);
    t.addRow(row);
  }
  osim::writeFileAtomic(*report + "/study.csv", validation::formatCsv(t));
  const auto gp = validation::findGnuplot();
  if (gp.available) {
    const auto o = validation::renderPlot(gp, validation::PlotFormat::Auto, fig, *report + "/study");
    if (!o.ok) std::cerr << "note: plot not drawn: " << o.error << "\n";
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
    std::cerr << "train-wrap --pendulums: " << i + 1 << "/" << specs.size() << " done, drift "
              << num(runs.back().max_drift, 3) << " J, " << num(runs.back().wall_s, 3) << " s\n";
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

int runTrainWrap(const CLI::App& app) {
  const FlagValues a(app);
  if (a.has("compare") + a.has("study") + a.has("pendulums") > 1)
    throw UsageError{"--compare, --study and --pendulums exclude each other"};
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
  app.add_option("--out", "the trained network (required for training)")->type_name("NET.txt")->group(train);
  app.add_option("--report",
                 "training: loss.csv and a loss plot; --compare: speed_error.csv and a plot;\n"
                 "--study: study.csv and a plot; --pendulums: pendulums.csv")
      ->type_name("DIR");
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
    {"train-wrap", "train the Type III wrap network, or compare wrap models (speed against error)",
     [](CLI::App& app) {
       declareTrainWrapFlags(app);
       app.footer("usage: redmax train-wrap --surface cylinder|sphere|ellipsoid|torus [--hidden 6x256] [--samples N]\n"
     "                         [--epochs E] [--batch B] [--lr 1e-4] [--seed S] [--threshold 0.01]\n"
     "                         [--time-limit SECONDS] [--threads T [--shards S]] [--init NET.txt]\n"
     "                         --out NET.txt [--report DIR]\n"
     "       redmax train-wrap --compare --surface cylinder|sphere|ellipsoid|torus [--nets A.txt,B.txt]\n"
     "                         [--untrained 6x256,...|none]\n"
     "                         [--muscles M] [--mass-points N] [--width W] [--seed S] --report DIR\n"
     "       redmax train-wrap --study [--thresholds 0.01,0.05,0.1] [--architectures 1x32,3x32] [--samples N]\n"
     "                         [--epochs E] [--batch B] [--lr R] [--seed S] --report DIR\n"
     "       redmax train-wrap --pendulums NET.txt [--count 8] [--duration 2] [--tol 1e-12] [--seed S] [--fd-jdot]\n"
     "                         [--report DIR]\n"
     "Training [D Sec. 5.3.3.1]: N samples (default 30000) drawn uniformly from the surface type's box\n"
     "(core/muscles/wrap/train.hpp makeDefaultWrapBox; units of the surface size) and labelled by the exact\n"
     "library; samples with 0 < l/L < threshold are discarded. A tanh MLP (--hidden DEPTHxWIDTH or W1-W2-...,\n"
     "default 6x256) is trained with Adam (--lr, default 1e-4; --batch default 256) on the mean squared error\n"
     "for E epochs (default 100) or until --time-limit. Deterministic for a seed. The network file records\n"
     "the command, seed, losses and the error on fresh samples. --report DIR writes loss.csv and a loss plot.\n"
     "--threads T labels samples and computes gradients on T threads; every mini-batch is cut into S shards\n"
     "(default T) summed in order, so the network depends on S and the seed, not on T (S = 1: serial).\n"
     "--init NET.txt continues training from that network (same surface and --hidden; its normalisation is kept,\n"
     "Adam restarts); its command and losses are kept in the new file's meta as init_*.\n"
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
