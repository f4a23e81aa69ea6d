#include "tools/wrap_training/compare.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <stdexcept>

#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "tools/wrap_training/train.hpp"

namespace redmax {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string num(double v, int prec = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", prec, v);
  return buf;
}

}  // namespace

Mlp makeTimingWrapNetwork(WrapType type, const std::vector<int>& hidden, unsigned long long seed) {
  // the cost of a network does not depend on its weights
  Mlp n(wrapInputSize(type), hidden, 3, seed);
  const WrapInputBox box = makeDefaultWrapBox(type);
  n.input_min = box.lo;
  n.input_max = box.hi;
  return n;
}

std::vector<WrapCompareRow> compareWrapModels(const WrapCompareOptions& o) {
  const WrapType type = o.type;
  const long muscles = o.muscles;
  const int points = o.points;
  const double width = o.width;
  if (muscles < 1 || points < 1) throw std::invalid_argument("compareWrapModels: muscles and points must be positive");
  const WrapInputBox box = makeDefaultWrapBox(type);
  for (const WrapCompareNet& cn : o.nets)
    if (cn.net.inputs() != wrapInputSize(type) || cn.net.outputs() != 3)
      throw std::invalid_argument("compareWrapModels: " + cn.name + " is not a " + wrapTypeName(type) + " wrap network");

  // muscles: end points from the default box (valid ones), velocities random, `points` mass points each
  const WrapOracle oracle = makeExactWrapOracle(type);
  std::mt19937_64 rng(o.seed);
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
  auto errors = [&](const std::vector<Vec3>& x, WrapCompareRow& row) {
    double se = 0.0, mx = 0.0;
    for (long i = 0; i < total_points; ++i) {
      const double e = (x[i] - exact[i]).norm();
      se += e * e;
      mx = std::max(mx, e);
    }
    row.rms = std::sqrt(se / total_points);
    row.max = mx;
  };
  // repeat a timed loop until it has run min_time_s; microseconds per mass point
  auto timePerPoint = [&](const std::function<void()>& all_points) {
    long reps = 0;
    const auto t0 = Clock::now();
    do {
      all_points();
      ++reps;
    } while (secondsSince(t0) < o.min_time_s);
    return 1e6 * secondsSince(t0) / (static_cast<double>(reps) * total_points);
  };
  std::vector<WrapCompareRow> rows;
  volatile double sink = 0.0;

  // exact library: position, then J and Jdot by central differences, one wrap per perturbed pair
  // of end points shared by the muscle's mass points, as the runtime does (calcExactWrapPointsFd:
  // 1 + 12 + 24 wraps per muscle)
  {
    WrapCompareRow row;
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
    WrapCompareRow row;
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
  for (const WrapCompareNet& cn : o.nets) {
    const Mlp& net = cn.net;
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
    WrapCompareRow row;
    row.method = "network " + cn.name;
    row.parameters = net.parameterCount();
    if (!cn.timing_only) errors(x, row);
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
      } while (secondsSince(t0) < o.min_time_s);
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

  (void)sink;
  return rows;
}

}  // namespace redmax
