#include "tools/wrap_training/train.hpp"

#include <barrier>
#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace redmax {
namespace {

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Fisher-Yates with our own generator (std::shuffle's use of the engine is unspecified)
void shuffle(std::vector<long>& v, std::mt19937_64& rng) {
  for (long i = static_cast<long>(v.size()) - 1; i > 0; --i) {
    const long j = static_cast<long>(rng() % static_cast<unsigned long long>(i + 1));
    std::swap(v[i], v[j]);
  }
}

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// Adam moments of one parameter block
struct AdamSlot {
  MatX m, v;
};

void adamStep(MatX& param, const MatX& grad, AdamSlot& s, const TrainOptions& o, double c1, double c2) {
  s.m = o.beta1 * s.m + (1.0 - o.beta1) * grad;
  s.v = o.beta2 * s.v + (1.0 - o.beta2) * grad.cwiseAbs2();
  param.array() -= o.learning_rate * (s.m.array() / c1) / ((s.v.array() / c2).sqrt() + o.adam_eps);
}

// f(t) for t = 0..T-1, on T - 1 new threads and this one
void runParallel(int T, const std::function<void(int)>& f) {
  if (T <= 1) return f(0);
  std::vector<std::thread> pool;
  pool.reserve(static_cast<size_t>(T - 1));
  for (int t = 1; t < T; ++t) pool.emplace_back(f, t);
  f(0);
  for (auto& th : pool) th.join();
}

}  // namespace

WrapInputBox makeDefaultWrapBox(WrapType type) {
  WrapInputBox b;
  b.names = {"ori_x", "ori_y", "ori_z", "ins_x", "ins_y", "ins_z", "alpha"};
  std::vector<double> lo{-3, -3, -3, -3, -3, -3, 0}, hi{3, 3, 3, 3, 3, 3, 1};
  if (type == WrapType::Cylinder) lo[2] = lo[5] = -2, hi[2] = hi[5] = 2;
  auto add = [&](const char* name, double l, double h) {
    b.names.push_back(name);
    lo.push_back(l);
    hi.push_back(h);
  };
  switch (type) {
    case WrapType::Cylinder:
    case WrapType::Sphere: add("radius", 0.5, 1.5); break;
    case WrapType::Ellipsoid:
      add("a", 0.5, 1.5);
      add("b", 0.5, 1.5);
      add("c", 0.5, 1.5);
      break;
    case WrapType::Torus:
      add("inner_radius", 0.2, 0.5);
      add("outer_radius", 1.0, 1.5);
      break;
  }
  b.lo = Eigen::Map<VecX>(lo.data(), lo.size());
  b.hi = Eigen::Map<VecX>(hi.data(), hi.size());
  return b;
}

WrapOracle makeExactWrapOracle(WrapType type) {
  return [type](const VecX& in) {
    WrapSample s;
    const WrapSurface surf = makeWrapSurfaceFromInput(type, in);
    const Vec3 p1 = in.segment<3>(0), p2 = in.segment<3>(3);
    const double alpha = in[6];
    // end points inside the surface are not configurations a muscle can have
    auto inside = [&](const Vec3& p) {
      switch (type) {
        case WrapType::Cylinder: return p.head<2>().norm() <= surf.radius;
        case WrapType::Sphere: return p.norm() <= surf.radius;
        case WrapType::Ellipsoid: return p.cwiseQuotient(surf.dimensions).squaredNorm() <= 1.0;
        case WrapType::Torus: {
          const double rho = p.head<2>().norm() - surf.outer_radius;
          return rho * rho + p[2] * p[2] <= surf.inner_radius * surf.inner_radius;
        }
      }
      return false;
    };
    if (inside(p1) || inside(p2) || (p1 - p2).norm() < 1e-9) return s;
    const WrapResult r = calcWrap(surf, p1, p2);
    if (r.code == WrapCode::InsideRadius) return s;
    s.valid = true;
    s.wraps = r.wraps();
    s.l = r.wraps() ? r.arcLength() : 0.0;
    s.L = calcWrappedPathLength(r, p1, p2);
    s.x = calcWrappedPathPoint(surf, r, p1, p2, alpha);
    return s;
  };
}

std::vector<int> parseHidden(const std::string& spec) {
  auto positive = [&](const std::string& s) {
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos || s.size() > 6)
      throw std::invalid_argument("--hidden: '" + spec + "' is not DEPTHxWIDTH (e.g. 6x256) or W1-W2-...");
    const int v = std::stoi(s);
    if (v < 1 || v > 4096) throw std::invalid_argument("--hidden: sizes must be between 1 and 4096");
    return v;
  };
  const auto x = spec.find('x');
  if (x != std::string::npos) {
    const int depth = positive(spec.substr(0, x)), width = positive(spec.substr(x + 1));
    if (depth > 64) throw std::invalid_argument("--hidden: at most 64 layers");
    return std::vector<int>(depth, width);
  }
  std::vector<int> out;
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, '-')) out.push_back(positive(item));
  if (out.empty() || out.size() > 64) throw std::invalid_argument("--hidden: '" + spec + "' lists no layers");
  return out;
}

WrapTrainingSet makeWrapTrainingSet(const WrapInputBox& box, const WrapOracle& oracle, long n, double threshold,
                                    unsigned long long seed, int threads) {
  const int n_in = static_cast<int>(box.lo.size());
  if (n < 1 || box.hi.size() != n_in) throw std::invalid_argument("makeWrapTrainingSet: bad box or sample count");
  std::mt19937_64 rng(seed);
  WrapTrainingSet set;
  set.X.resize(n_in, n);
  set.Y.resize(3, n);
  long kept = 0;
  // blocks of inputs drawn in sequence, labelled (in parallel), then examined in order: the set is
  // the one a serial loop would keep, whatever the thread count
  const int T = std::max(1, threads);
  const long block = T > 1 ? 1024L * T : 1;
  MatX Xb(n_in, block);
  std::vector<WrapSample> Sb(static_cast<size_t>(block));
  while (kept < n && set.drawn < 50 * n) {
    const long m = std::min(block, 50 * n - set.drawn);
    for (long j = 0; j < m; ++j)
      for (int i = 0; i < n_in; ++i) Xb(i, j) = box.lo[i] + (box.hi[i] - box.lo[i]) * uniform01(rng);
    runParallel(T, [&](int t) {
      for (long j = t; j < m; j += T) Sb[static_cast<size_t>(j)] = oracle(Xb.col(j));
    });
    for (long j = 0; j < m && kept < n; ++j) {
      const WrapSample& s = Sb[static_cast<size_t>(j)];
      ++set.drawn;
      if (!s.valid || !s.x.allFinite()) {
        ++set.invalid;
        continue;
      }
      // [D Sec. 5.3.3.1]: keep straight paths (l = 0) and clearly wrapped ones
      if (s.l > 0.0 && s.l < threshold * s.L) {
        ++set.near_contact;
        continue;
      }
      if (s.l > 0.0) ++set.wrapped;
      set.X.col(kept) = Xb.col(j);
      set.Y.col(kept) = s.x;
      ++kept;
    }
  }
  if (kept < n)
    throw std::runtime_error("only " + std::to_string(kept) + " of " + std::to_string(n) + " samples usable after " +
                             std::to_string(set.drawn) + " draws (box mostly inside the surface?)");
  return set;
}

Mlp trainWrapNetwork(const WrapTrainingSet& data, const WrapInputBox& box, const TrainOptions& opt,
                     std::vector<TrainEpoch>* history) {
  const auto t0 = std::chrono::steady_clock::now();
  const int n_in = static_cast<int>(data.X.rows()), n_out = static_cast<int>(data.Y.rows());
  const long n = data.X.cols();
  if (n < 2 || opt.batch < 1 || opt.epochs < 0) throw std::invalid_argument("trainWrapNetwork: too few samples or bad options");
  std::mt19937_64 rng(opt.seed);

  // held-out split
  std::vector<long> order(n);
  for (long i = 0; i < n; ++i) order[i] = i;
  shuffle(order, rng);
  const long n_val = std::max(1L, std::min(n - 1, static_cast<long>(std::llround(opt.validation_fraction * n))));
  const long n_tr = n - n_val;
  MatX Xtr(n_in, n_tr), Ytr(n_out, n_tr), Xval(n_in, n_val), Yval(n_out, n_val);
  for (long i = 0; i < n_val; ++i) Xval.col(i) = data.X.col(order[i]), Yval.col(i) = data.Y.col(order[i]);
  for (long i = 0; i < n_tr; ++i) Xtr.col(i) = data.X.col(order[n_val + i]), Ytr.col(i) = data.Y.col(order[n_val + i]);

  // network and normalisation from the training part (mean, standard deviation)
  Mlp net(n_in, opt.hidden, n_out, rng());
  auto stats = [](const MatX& A, VecX& mean, VecX& scale) {
    mean = A.rowwise().mean();
    scale = ((A.colwise() - mean).cwiseAbs2().rowwise().mean()).cwiseSqrt();
    for (Eigen::Index i = 0; i < scale.size(); ++i)
      if (!(scale[i] > 1e-12)) scale[i] = 1.0;  // constant input (e.g. a fixed radius)
  };
  stats(Xtr, net.input_mean, net.input_scale);
  stats(Ytr, net.output_mean, net.output_scale);
  if (opt.init) {
    // a continued run keeps the first run's normalisation: the weights were learnt in its units
    if (opt.init->architecture() != net.architecture() || opt.init->input_mean.size() != n_in ||
        opt.init->output_mean.size() != n_out)
      throw std::invalid_argument("trainWrapNetwork: the initial network is " + opt.init->architecture() + " with " +
                                  std::to_string(opt.init->input_mean.size()) + " inputs, expected " +
                                  net.architecture() + " with " + std::to_string(n_in));
    net = *opt.init;
    net.meta.clear();
  }
  net.input_min = box.lo;
  net.input_max = box.hi;
  if (static_cast<int>(box.names.size()) == n_in) net.input_names = box.names;
  net.output_names = {"x", "y", "z"};
  auto normIn = [&](const MatX& X) {
    MatX U = X.colwise() - net.input_mean;
    U.array().colwise() /= net.input_scale.array();
    return U;
  };
  auto normOut = [&](const MatX& Y) {
    MatX T = Y.colwise() - net.output_mean;
    T.array().colwise() /= net.output_scale.array();
    return T;
  };
  const MatX Utr = normIn(Xtr), Ttr = normOut(Ytr), Uval = normIn(Xval), Tval = normOut(Yval);

  const int L = net.layers();  // hidden layers + output layer
  std::vector<AdamSlot> sW(L), sb(L);
  for (int l = 0; l < L; ++l) {
    sW[l] = {MatX::Zero(net.weights(l).rows(), net.weights(l).cols()), MatX::Zero(net.weights(l).rows(), net.weights(l).cols())};
    sb[l] = {MatX::Zero(net.biases(l).size(), 1), MatX::Zero(net.biases(l).size(), 1)};
  }

  // forward in normalised units; H keeps the hidden activations for the backward pass
  auto forward = [&](const MatX& Uin, std::vector<MatX>& H, MatX& Vout) {
    for (int l = 0; l < L - 1; ++l) {
      const MatX& prev = l == 0 ? Uin : H[l - 1];
      H[l].noalias() = net.weights(l) * prev;
      H[l].colwise() += net.biases(l);
      H[l] = H[l].array().tanh();
    }
    Vout.noalias() = net.weights(L - 1) * H[L - 2];
    Vout.colwise() += net.biases(L - 1);
  };
  std::vector<MatX> Hval(L - 1);
  auto validation = [&](double& mse, double& rms_m) {
    double se = 0.0, se_m = 0.0;
    const long chunk = 4096;
    MatX Vv;
    for (long c0 = 0; c0 < n_val; c0 += chunk) {
      const long c = std::min(chunk, n_val - c0);
      forward(Uval.middleCols(c0, c), Hval, Vv);
      const MatX D = Vv - Tval.middleCols(c0, c);
      se += D.squaredNorm();
      se_m += (D.array().colwise() * net.output_scale.array()).matrix().squaredNorm();
    }
    mse = se / (static_cast<double>(n_val) * n_out);
    rms_m = std::sqrt(se_m / static_cast<double>(n_val));
  };

  // Data parallelism: every mini-batch is cut into S shards (fixed), each shard's gradient is
  // computed on its own workspace, and the shards are summed in shard order, so the weights depend
  // on S but not on the thread count T. S = 1 is the plain serial algorithm.
  const int T = std::max(1, opt.threads);
  const int S = opt.shards > 0 ? opt.shards : T;
  struct Shard {
    std::vector<MatX> H, gW, gb;
    MatX U, T, V, dV, dH, dZ;
    double loss = 0.0;
  };
  std::vector<Shard> shard(static_cast<size_t>(S));
  for (auto& sh : shard) sh.H.resize(L - 1), sh.gW.resize(L), sh.gb.resize(L);
  std::vector<MatX> gW(L), gb(L);

  std::vector<long> perm(n_tr);
  for (long i = 0; i < n_tr; ++i) perm[i] = i;
  long steps = 0;
  TrainEpoch last;
  for (int epoch = 1; epoch <= opt.epochs; ++epoch) {
    shuffle(perm, rng);
    double loss_sum = 0.0;
    const long n_batches = (n_tr + opt.batch - 1) / opt.batch;
    const long steps0 = steps;

    // gradient of the mean squared error over batch columns [b0, b0 + B), shard k's slice
    auto shardGradient = [&](int k, long b0, long B) {
      Shard& sh = shard[static_cast<size_t>(k)];
      const long c0 = B * k / S, c1 = B * (k + 1) / S, C = c1 - c0;
      sh.loss = 0.0;
      if (C == 0) {
        for (int l = 0; l < L; ++l) sh.gW[l].setZero(net.weights(l).rows(), net.weights(l).cols()), sh.gb[l].setZero(net.biases(l).size(), 1);
        return;
      }
      sh.U.resize(n_in, C);
      sh.T.resize(n_out, C);
      for (long j = 0; j < C; ++j) sh.U.col(j) = Utr.col(perm[b0 + c0 + j]), sh.T.col(j) = Ttr.col(perm[b0 + c0 + j]);
      forward(sh.U, sh.H, sh.V);
      sh.dV = sh.V - sh.T;
      sh.loss = sh.dV.squaredNorm() / (static_cast<double>(B) * n_out);
      sh.dV *= 2.0 / (static_cast<double>(B) * n_out);
      sh.gW[L - 1].noalias() = sh.dV * sh.H[L - 2].transpose();
      sh.gb[L - 1] = sh.dV.rowwise().sum();
      sh.dH.noalias() = net.weights(L - 1).transpose() * sh.dV;
      for (int l = L - 2; l >= 0; --l) {
        sh.dZ = sh.dH.array() * (1.0 - sh.H[l].array().square());
        const MatX& prev = l == 0 ? sh.U : sh.H[l - 1];
        sh.gW[l].noalias() = sh.dZ * prev.transpose();
        sh.gb[l] = sh.dZ.rowwise().sum();
        if (l > 0) sh.dH.noalias() = net.weights(l).transpose() * sh.dZ;
      }
    };
    // sum of the shards in order, then Adam, for one layer
    auto layerUpdate = [&](int l, long step) {
      gW[l] = shard[0].gW[l];
      gb[l] = shard[0].gb[l];
      for (int k = 1; k < S; ++k) gW[l] += shard[static_cast<size_t>(k)].gW[l], gb[l] += shard[static_cast<size_t>(k)].gb[l];
      const double c1 = 1.0 - std::pow(opt.beta1, static_cast<double>(step));
      const double c2 = 1.0 - std::pow(opt.beta2, static_cast<double>(step));
      adamStep(net.weights(l), gW[l], sW[l], opt, c1, c2);
      MatX bias = net.biases(l);
      adamStep(bias, gb[l], sb[l], opt, c1, c2);
      net.biases(l) = bias;
    };
    std::barrier<> sync(T);
    runParallel(T, [&](int t) {
      for (long bi = 0; bi < n_batches; ++bi) {
        const long b0 = bi * opt.batch, B = std::min<long>(opt.batch, n_tr - b0);
        for (int k = t; k < S; k += T) shardGradient(k, b0, B);
        sync.arrive_and_wait();
        for (int l = t; l < L; l += T) layerUpdate(l, steps0 + bi + 1);
        if (t == 0)
          for (int k = 0; k < S; ++k) loss_sum += shard[static_cast<size_t>(k)].loss;
        sync.arrive_and_wait();
      }
    });
    steps = steps0 + n_batches;
    last.epoch = epoch;
    last.steps = steps;
    last.train_mse = loss_sum / std::max(1L, n_batches);
    validation(last.val_mse, last.val_rms_m);
    last.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!std::isfinite(last.train_mse)) throw std::runtime_error("training diverged at epoch " + std::to_string(epoch) + " (loss not finite)");
    if (history) history->push_back(last);
    if (opt.on_epoch) opt.on_epoch(last);
    if (opt.time_limit_s > 0 && last.elapsed_s > opt.time_limit_s) break;
  }

  net.meta["seed"] = std::to_string(opt.seed);
  net.meta["architecture"] = net.architecture();
  net.meta["samples"] = std::to_string(n) + " (train " + std::to_string(n_tr) + ", validation " + std::to_string(n_val) + ")";
  net.meta["epochs"] = std::to_string(last.epoch);
  net.meta["adam"] = "lr " + fmt(opt.learning_rate) + " batch " + std::to_string(opt.batch) + " steps " + std::to_string(steps) +
                     (S > 1 ? " shards " + std::to_string(S) : std::string());
  net.meta["final_train_mse"] = fmt(last.train_mse);
  net.meta["final_val_mse"] = fmt(last.val_mse);
  net.meta["final_val_rms_m"] = fmt(last.val_rms_m);
  net.meta["train_seconds"] = fmt(last.elapsed_s);
  return net;
}

WrapErrorStats calcWrapNetworkError(const Mlp& net, const WrapTrainingSet& data) {
  WrapErrorStats s;
  MlpWorkspace ws;
  MatX Y;
  const long chunk = 4096;
  double se = 0.0;
  for (long c0 = 0; c0 < data.X.cols(); c0 += chunk) {
    const long c = std::min<long>(chunk, data.X.cols() - c0);
    net.calcOutput(data.X.middleCols(c0, c), Y, ws);
    for (long j = 0; j < c; ++j) {
      const double e = (Y.col(j) - data.Y.col(c0 + j)).norm();
      se += e * e;
      s.max = std::max(s.max, e);
    }
  }
  s.rms = std::sqrt(se / std::max<double>(1.0, static_cast<double>(data.X.cols())));
  return s;
}

}  // namespace redmax
