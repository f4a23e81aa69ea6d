#include "tools/wrap_training/model_networks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <thread>

#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {
namespace {

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// the exact library on the unconstrained surface of radius R (cylinder effectively infinite: 1000
// R long), end points q1, q2 in radii; the sample in radii. R matters: OpenSim's cylinder is not
// scale-equivariant (it slides its tangent points along the axis within a segment of +-10 m and
// tests with absolute tolerances of 1e-5), so a wrap object's labels are computed at its own
// radius, the size the run-time model and the library meet (on a unit cylinder an end point more
// than 10 radii along the axis from its tangent point keeps it at its own height: Rajagopal2016's
// AL_at_femshaft_r, R = 2.5 cm, whose origin lies 9.4-10.5 radii along the axis, took paths up to
// 5.6 radii off the real ones)
WrapSample label(WrapType type, const Vec3& q1, const Vec3& q2, double alpha, double R) {
  VecX in(8);
  in << R * q1, R * q2, alpha, R;
  WrapSample s = makeExactWrapOracle(type)(in);
  s.x /= R;
  s.l /= R;
  s.L /= R;
  return s;
}

constexpr double kFarRadii = 1000.0;

// kept samples: X = (u1, u2, alpha, 1), Y = x - straight point (radii)
struct SetBuilder {
  WrapTrainingSet set;
  long kept = 0;
  SetBuilder(long n) {
    set.X.resize(8, n);
    set.Y.resize(3, n);
  }
  void offer(const WrapSample& s, const Vec3& q1, const Vec3& q2, double alpha, double C, double threshold) {
    ++set.drawn;
    // end points beyond kFarRadii: the library's construction loses its precision there (seen:
    // displacements of 1e4 radii at 1e5 radii, from splines of moving points extrapolated at poses
    // drawn within the ranges), and the compact map has crowded them onto |u| = C anyway
    if (!s.valid || !s.x.allFinite() || q1.norm() > kFarRadii || q2.norm() > kFarRadii) {
      ++set.invalid;
      return;
    }
    if (s.l > 0.0 && s.l < threshold * s.L) {
      ++set.near_contact;
      return;
    }
    if (s.l > 0.0) ++set.wrapped;
    set.X.col(kept) << calcCompactWrapInput(q1, C), calcCompactWrapInput(q2, C), alpha, 1.0;
    set.Y.col(kept) = s.x - (q1 + alpha * (q2 - q1));
    ++kept;
  }
};

// draw candidates in blocks, label them on T threads, keep in order (the set does not depend on T)
template <class Draw>
WrapTrainingSet buildSet(WrapType type, double R, long n, double threshold, double C, unsigned long long seed,
                         int threads, Draw draw) {
  std::mt19937_64 rng(seed);
  SetBuilder b(n);
  const int T = std::max(1, threads);
  const long block = 1024L * T;
  std::vector<Vec3> a1(block), a2(block);
  std::vector<double> al(block);
  std::vector<WrapSample> s(block);
  while (b.kept < n && b.set.drawn < 50 * n) {
    for (long j = 0; j < block; ++j) draw(rng, a1[j], a2[j], al[j]);
    auto work = [&](int t) {
      for (long j = t; j < block; j += T) s[j] = label(type, a1[j], a2[j], al[j], R);
    };
    if (T == 1) {
      work(0);
    } else {
      std::vector<std::thread> pool;
      for (int t = 1; t < T; ++t) pool.emplace_back(work, t);
      work(0);
      for (auto& th : pool) th.join();
    }
    for (long j = 0; j < block && b.kept < n; ++j) b.offer(s[j], a1[j], a2[j], al[j], C, threshold);
  }
  if (b.kept < n)
    throw std::runtime_error("only " + std::to_string(b.kept) + " of " + std::to_string(n) + " samples usable after " +
                             std::to_string(b.set.drawn) + " draws (end points mostly inside the surface?)");
  return std::move(b.set);
}

}  // namespace

std::vector<WrapObjectInputs> collectWrapObjectInputs(const Model& model, const std::vector<Muscle>& muscles,
                                                      const std::vector<VecX>& poses) {
  std::map<std::string, WrapObjectInputs> by_name;
  std::vector<Mat4> E_wi;
  std::vector<int> active;
  std::vector<Vec3> x_w;
  for (const VecX& q : poses) {
    calcBodyPoses(model, q, E_wi);
    for (const Muscle& m : muscles) {
      const MusclePath& path = m.path;
      if (path.wraps.empty()) continue;
      calcActivePoints(path, q, E_wi, active, x_w);
      const std::vector<int> seg_wrap = calcSegmentWraps(m, active, x_w, E_wi);
      for (size_t i = 0; i < seg_wrap.size(); ++i) {
        if (seg_wrap[i] < 0) continue;
        const PathWrap& w = path.wraps[seg_wrap[i]];
        const Mat4 E_ws = w.body >= 0 ? Mat4(E_wi[w.body] * w.E_bs) : w.E_bs;
        const Mat3 R = E_ws.topLeftCorner<3, 3>();
        const Vec3 p = E_ws.topRightCorner<3, 1>();
        const double size = w.surface.type == WrapType::Cylinder || w.surface.type == WrapType::Sphere
                                ? w.surface.radius
                                : 1.0;
        WrapObjectInputs& in = by_name[w.name];
        if (in.name.empty()) {
          in.name = w.name;
          in.surface = w.surface;
        }
        if (std::find(in.muscles.begin(), in.muscles.end(), m.name) == in.muscles.end()) in.muscles.push_back(m.name);
        in.q1.push_back(R.transpose() * (x_w[i] - p) / size);
        in.q2.push_back(R.transpose() * (x_w[i + 1] - p) / size);
      }
    }
  }
  std::vector<WrapObjectInputs> out;
  for (auto& [name, in] : by_name) out.push_back(std::move(in));
  return out;
}

WrapTrainingSet makeWrapObjectTrainingSet(const WrapObjectInputs& in, long n, double threshold, double compact,
                                          double jitter, unsigned long long seed, int threads) {
  if (in.q1.empty()) throw std::invalid_argument("wrap object '" + in.name + "': no inputs to train on");
  const long m = static_cast<long>(in.q1.size());
  if (!(in.surface.radius > 0.0)) throw std::invalid_argument("wrap object '" + in.name + "': the radius must be positive");
  return buildSet(in.surface.type, in.surface.radius, n, threshold, compact, seed, threads,
                  [&](std::mt19937_64& rng, Vec3& q1, Vec3& q2, double& alpha) {
                    const long k = static_cast<long>(rng() % static_cast<unsigned long long>(m));
                    q1 = in.q1[k];
                    q2 = in.q2[k];
                    for (Vec3* q : {&q1, &q2}) {
                      const double s = jitter * std::max(q->norm(), 1.0);
                      for (int i = 0; i < 3; ++i) (*q)[i] += s * (2.0 * uniform01(rng) - 1.0);
                    }
                    alpha = uniform01(rng);
                  });
}

WrapInputBox makeCompactWrapBox(const WrapTrainingSet& set, double compact, double margin) {
  WrapInputBox b;
  b.names = {"ori_u", "ori_v", "ori_w", "ins_u", "ins_v", "ins_w", "alpha", "radius"};
  b.lo = set.X.rowwise().minCoeff();
  b.hi = set.X.rowwise().maxCoeff();
  for (int i = 0; i < 6; ++i) {
    const double pad = margin * (b.hi[i] - b.lo[i]) + 0.02 * compact;
    b.lo[i] = std::max(-compact, b.lo[i] - pad);
    b.hi[i] = std::min(compact, b.hi[i] + pad);
  }
  b.lo[6] = 0.0;
  b.hi[6] = 1.0;
  b.lo[7] = b.hi[7] = 1.0;
  return b;
}

WrapTrainingSet makeCompactWrapTrainingSet(WrapType type, long n, double threshold, double compact,
                                           unsigned long long seed, int threads) {
  const WrapInputBox near = makeDefaultWrapBox(type);
  return buildSet(type, 1.0, n, threshold, compact, seed, threads, [&](std::mt19937_64& rng, Vec3& q1, Vec3& q2, double& alpha) {
    for (int i = 0; i < 3; ++i) q1[i] = near.lo[i] + (near.hi[i] - near.lo[i]) * uniform01(rng);
    for (int i = 0; i < 3; ++i) q2[i] = near.lo[3 + i] + (near.hi[3 + i] - near.lo[3 + i]) * uniform01(rng);
    alpha = uniform01(rng);
  });
}

WrapInputBox makeCompactDefaultWrapBox(WrapType type, double compact) {
  if (type != WrapType::Cylinder && type != WrapType::Sphere)
    throw std::invalid_argument("the compact map takes cylinders and spheres (one radius)");
  // the image of the default box's corners bounds each mapped coordinate (|u_i| grows with |q_i|
  // and shrinks with the other coordinates), widened as makeCompactWrapBox widens
  const WrapInputBox near = makeDefaultWrapBox(type);
  WrapInputBox b;
  b.names = {"ori_u", "ori_v", "ori_w", "ins_u", "ins_v", "ins_w", "alpha", "radius"};
  b.lo = VecX::Zero(8);
  b.hi = VecX::Zero(8);
  for (int e = 0; e < 2; ++e)
    for (int i = 0; i < 3; ++i) {
      // the largest |u_i| over the box: q_i at its bound, the other coordinates zero
      Vec3 q = Vec3::Zero();
      q[i] = near.hi[3 * e + i];
      const double u = calcCompactWrapInput(q, compact)[i] + 0.02 * compact;
      b.lo[3 * e + i] = -std::min(u, compact);
      b.hi[3 * e + i] = std::min(u, compact);
    }
  b.lo[6] = 0.0;
  b.hi[6] = 1.0;
  b.lo[7] = b.hi[7] = 1.0;
  return b;
}

Mlp trainWrapObjectNetwork(const WrapObjectInputs& in, const ModelWrapTrainOptions& o, WrapErrorStats* test) {
  const WrapType type = in.surface.type;
  if (type != WrapType::Cylinder && type != WrapType::Sphere)
    throw std::invalid_argument("wrap object '" + in.name + "' is a " + wrapTypeName(type) +
                                ": networks take cylinders and spheres (one radius); the smooth model serves it");
  const WrapTrainingSet data =
      makeWrapObjectTrainingSet(in, o.samples, o.threshold, o.compact, o.jitter, o.train.seed, o.train.threads);
  const WrapInputBox box = makeCompactWrapBox(data, o.compact, o.margin);
  Mlp net = trainWrapNetwork(data, box, o.train);
  // fresh samples, all of them (near the contact change too)
  const WrapTrainingSet fresh = makeWrapObjectTrainingSet(in, std::min(o.samples, 5000L), 0.0, o.compact, o.jitter,
                                                          o.train.seed + 1000003, o.train.threads);
  const WrapErrorStats err = calcWrapNetworkError(net, fresh);
  if (test) *test = err;
  net.meta["surface"] = wrapTypeName(type);
  net.meta["wrap_object"] = in.name;
  net.meta["wrap_map"] = formatCompactWrapMap(o.compact);
  net.meta["label_radius_m"] = fmt(in.surface.radius);  // the library's labels at the object's size
  net.meta["inputs_seen"] = std::to_string(in.q1.size()) + " wrapped-segment evaluations of " +
                            std::to_string(in.muscles.size()) + " muscle(s), jitter " + fmt(o.jitter);
  net.meta["threshold"] = fmt(o.threshold);
  net.meta["test_rms_m"] = fmt(err.rms);
  net.meta["test_max_m"] = fmt(err.max);
  net.meta["box"] = "the compact inputs seen, widened (tools/wrap_training/model_networks.hpp makeCompactWrapBox)";
  return net;
}

std::vector<WrapNetworkCheck> checkWrapNetworks(const std::vector<WrapObjectInputs>& inputs,
                                                const std::function<const Mlp*(const std::string&, WrapType)>& pick,
                                                const std::vector<double>& alphas) {
  std::vector<WrapNetworkCheck> out;
  NetworkWrapWorkspace ws;
  WrapMassPoints pts;
  for (const WrapObjectInputs& in : inputs) {
    WrapNetworkCheck c;
    c.name = in.name;
    const Mlp* net = pick(in.name, in.surface.type);
    if (net) c.network = net->meta.count("wrap_object") ? net->meta.at("wrap_object") : net->architecture();
    const double size =
        in.surface.type == WrapType::Cylinder || in.surface.type == WrapType::Sphere ? in.surface.radius : 1.0;
    double se = 0.0;
    long n_err = 0;
    for (size_t k = 0; k < in.q1.size(); ++k) {
      const Vec3 p1 = size * in.q1[k], p2 = size * in.q2[k];
      NetworkWrapEval ev;
      try {
        ev = calcNetworkWrapModel(net, in.surface, p1, p2, Vec3::Zero(), Vec3::Zero(), alphas, false, pts, ws);
      } catch (const std::invalid_argument&) {
        continue;  // the smooth model refuses the surface, or an end inside: no wrap model is asked
      }
      ++c.evaluations;
      if (!ev.usedNetwork()) {
        ++c.fallbacks;
        ++c.by_reason[ev.fallback];
        continue;
      }
      const WrapResult r = calcWrap(in.surface, p1, p2);
      for (size_t a = 0; a < alphas.size(); ++a) {
        const double e = (pts.x[a] - calcWrappedPathPoint(in.surface, r, p1, p2, alphas[a])).norm() / size;
        se += e * e;
        c.max = std::max(c.max, e);
        ++n_err;
      }
    }
    c.rms = n_err > 0 ? std::sqrt(se / n_err) : 0.0;
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace redmax
