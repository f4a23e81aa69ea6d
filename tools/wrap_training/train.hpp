#pragma once
// Training the wrap network (a tool, not part of the engine: the engine only evaluates networks,
// core/muscles/wrap/network.hpp) [D Sec. 5.3.3.1, 6.2.6]: samples drawn uniformly from a stated box of
// inputs (origin, insertion in the surface frame, alpha, surface size), labelled by an exact
// wrapping oracle; samples whose wrapped length l is a small nonzero fraction of the path length L
// (0 < l/L < threshold) are discarded, so the network never sees the contact change's kink.
// Mean squared error in normalised output units, Adam, mini-batches.
//
// Determinism: one seeded generator (std::mt19937_64, top 53 bits -> double) draws the samples,
// the validation split, the initial weights and every epoch's shuffle; reductions run in a fixed
// order (Eigen without OpenMP), so a seed reproduces a network bit for bit on the same build and
// machine. Parallel training splits every mini-batch into a fixed number of shards whose gradients
// are summed in shard order: the result depends on the shard count, never on the thread count.
#include <functional>
#include <string>
#include <vector>

#include "core/muscles/wrap/network.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap/wrap_surface.hpp"

namespace redmax {

/// One labelled sample from the exact wrapping library.
struct WrapSample {
  bool valid = false;  ///< false: the input is not a usable configuration (an end point inside the surface)
  bool wraps = false;  ///< the path touches the surface
  double l = 0.0;      ///< wrapped (on-surface) length, m
  double L = 0.0;      ///< whole path length, m
  Vec3 x = Vec3::Zero();  ///< the mass point at arc fraction alpha, surface frame, m
};

/// Exact oracle: raw network input (origin 3, insertion 3, alpha, size parameters) -> sample.
using WrapOracle = std::function<WrapSample(const VecX& input)>;

/// Box of raw inputs sampled uniformly; names become the network's input names.
struct WrapInputBox {
  std::vector<std::string> names;
  VecX lo, hi;
};

/// The default training box of a surface type, in units of the surface size (wrapping is
/// scale-equivariant: scale inputs by 1/size at run time for other scales):
///   origin, insertion: every coordinate in [-3, 3] (cylinder z in [-2, 2]); alpha in [0, 1];
///   cylinder and sphere radius in [0.5, 1.5]; ellipsoid semi-axes in [0.5, 1.5];
///   torus inner radius in [0.2, 0.5], outer radius in [1.0, 1.5].
WrapInputBox makeDefaultWrapBox(WrapType type);

/// Oracle over the exact library (calcWrap + calcWrappedPathPoint): invalid when an end point is
/// inside the surface; l = geometric arc length, L = whole path length.
WrapOracle makeExactWrapOracle(WrapType type);

/// Samples kept for training, one per column, and how many were drawn and thrown away.
struct WrapTrainingSet {
  MatX X;  ///< n_in x n raw inputs
  MatX Y;  ///< 3 x n mass-point positions
  long drawn = 0, invalid = 0, near_contact = 0;  ///< near_contact: 0 < l/L < threshold
  long wrapped = 0;                               ///< kept samples that wrap
};

/// Draw samples until n are kept (or 50 n drawn). threshold: discard 0 < l/L < threshold
/// [D Sec. 5.3.3.1]. Throws std::runtime_error if fewer than n could be kept. With threads > 1 the
/// oracle runs on blocks of inputs in parallel (it must be thread-safe; the exact oracle is); the
/// inputs are still drawn in sequence and kept in order, so the set does not depend on threads.
WrapTrainingSet makeWrapTrainingSet(const WrapInputBox& box, const WrapOracle& oracle, long n, double threshold,
                                    unsigned long long seed, int threads = 1);

/// One line of the loss curve.
struct TrainEpoch {
  int epoch = 0;
  long steps = 0;          ///< Adam steps so far
  double train_mse = 0.0;  ///< mean over the epoch's mini-batches, normalised output units
  double val_mse = 0.0;    ///< held-out samples, normalised output units
  double val_rms_m = 0.0;  ///< held-out position error (RMS of |y - y_exact|), m
  double elapsed_s = 0.0;
};

struct TrainOptions {
  std::vector<int> hidden = std::vector<int>(6, 256);  ///< widths of the hidden layers; see parseHidden
  int epochs = 100;
  int batch = 256;
  double learning_rate = 1e-4;  ///< [D Sec. 6.2]
  double beta1 = 0.9, beta2 = 0.999, adam_eps = 1e-8;
  double validation_fraction = 0.1;
  unsigned long long seed = 1;
  double time_limit_s = 0.0;  ///< > 0: stop after the epoch that passes it
  int threads = 1;  ///< worker threads (harness-level parallelism; the core stays single-threaded)
  int shards = 0;   ///< gradient shards per mini-batch (<= 0: = threads); 1 = the serial algorithm
  /// continue from this network (its weights and normalisation; Adam's moments start at zero);
  /// its inputs, outputs and hidden widths must match. Null: fresh weights from the seed.
  const Mlp* init = nullptr;
  std::function<void(const TrainEpoch&)> on_epoch;  ///< progress (called after every epoch)
};

/// Train a tanh MLP on the set; its normalisation is taken from the data (mean and standard
/// deviation per input and output), its box from `box`. meta gets seed, architecture, samples,
/// epochs and final losses; callers add the command line.
Mlp trainWrapNetwork(const WrapTrainingSet& data, const WrapInputBox& box, const TrainOptions& opt,
                     std::vector<TrainEpoch>* history = nullptr);

/// "6x256" -> {256 x 6}; "64-32" -> {64, 32}. std::invalid_argument on anything else.
std::vector<int> parseHidden(const std::string& spec);

/// RMS and max of |net(x) - y| over a set (m).
struct WrapErrorStats {
  double rms = 0.0, max = 0.0;
};
WrapErrorStats calcWrapNetworkError(const Mlp& net, const WrapTrainingSet& data);

}  // namespace redmax
