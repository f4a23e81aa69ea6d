#pragma once
// Networks for a given model (issue 22; `redmax train-wrap --for MODEL.osim`): for each wrap object
// the model's muscles use, the surface-frame end points its wrapped segments have over a set of
// poses (a trial, or poses drawn within the coordinate ranges), a network trained on exactly those
// inputs (jittered, at random arc fractions) with the compact input map and the displacement output
// of core/muscles/wrap/network_model.hpp (`meta wrap_map compact C`), and a check of a set of
// networks on such inputs: how often each falls back to the smooth model, and its position error
// against the exact library where it serves.
//
// Inputs are in radii (p / R), and the network's radius input is 1. Training labels come from the
// exact library on the unconstrained surface of the object's own radius (no quadrant, the cylinder
// effectively infinite), scaled to radii: OpenSim's cylinder is not scale-equivariant (absolute
// lengths and tolerances in its tangent-point slide), so a network is for its object's size, and it
// is what the run-time model serves; configurations where a
// quadrant or the cylinder's finite length change the path fall back at run time
// (NetworkWrapFallback::Quadrant, FiniteLength), and the check counts them.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/muscles/mass_points.hpp"
#include "core/skeleton/model.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "tools/wrap_training/train.hpp"

namespace redmax {

/// What one wrap object sees over a set of poses.
struct WrapObjectInputs {
  std::string name;                  ///< the WrapObject's name
  WrapSurface surface;               ///< as the model has it (m)
  std::vector<std::string> muscles;  ///< muscles whose wrapped segments it takes
  std::vector<Vec3> q1, q2;          ///< segment ends in the surface frame, in radii (one per evaluation)
};

/// For every wrap object of the model's muscles (active surfaces), the wrapped-segment ends of every
/// muscle at every pose, as the wrap models get them (calcSegmentWraps: each wrap on the segment of
/// its range its straight line penetrates most; a segment with an end inside the surface takes none).
/// Ordered by name.
std::vector<WrapObjectInputs> collectWrapObjectInputs(const Model& model, const std::vector<Muscle>& muscles,
                                                      const std::vector<VecX>& poses);

struct ModelWrapTrainOptions {
  TrainOptions train;          ///< architecture, epochs, batch, learning rate, seed, threads
  long samples = 20000;        ///< training samples per wrap object
  double threshold = 0.01;     ///< discard 0 < l/L < threshold [D Sec. 5.3.3.1]
  double compact = 4.0;        ///< the compact map's C (radii)
  double jitter = 0.05;        ///< end points moved by up to jitter * max(|q|, 1) per coordinate
  double margin = 0.1;         ///< the training box: the inputs' range widened by margin of it (+0.02 C)
};

/// Training set over what `in` sees (inputs mapped: u1, u2, alpha, 1; outputs: displacement from the
/// straight line, radii). Labels from the exact library on a surface of the object's own radius
/// (OpenSim's cylinder has absolute lengths and tolerances, so a unit surface can give another path),
/// scaled to radii; end points beyond 1000 radii are not used (counted invalid: the library loses its
/// precision there). std::runtime_error when too few usable; std::invalid_argument for no inputs or a
/// radius <= 0.
WrapTrainingSet makeWrapObjectTrainingSet(const WrapObjectInputs& in, long n, double threshold, double compact,
                                          double jitter, unsigned long long seed, int threads = 1);

/// The box of compact inputs a set covers, widened by `margin` (ModelWrapTrainOptions).
WrapInputBox makeCompactWrapBox(const WrapTrainingSet& set, double compact, double margin);

/// A network for one wrap object (cylinder or sphere): meta surface, wrap_object, wrap_map, the
/// error on fresh samples (test_rms_m, test_max_m: radii). std::invalid_argument for other surface
/// types or no inputs.
Mlp trainWrapObjectNetwork(const WrapObjectInputs& in, const ModelWrapTrainOptions& options,
                           WrapErrorStats* test = nullptr);

/// Generic training set for a surface type with the compact map: end points drawn from the older
/// default box (makeDefaultWrapBox, radius 1), given to the network mapped, with displacement
/// outputs. (Drawing u uniformly in the whole ball |u| < C was tried: far end points make the
/// displacement a near-discontinuous function of u, and a 3x64 network ended at RMS 2.25 radii,
/// max 67, on such samples; measured, not kept.)
WrapTrainingSet makeCompactWrapTrainingSet(WrapType type, long n, double threshold, double compact,
                                           unsigned long long seed, int threads = 1);
/// Its box: each mapped end-point coordinate within the image of the default box (widened by
/// 0.02 C), alpha in [0, 1], radius 1.
WrapInputBox makeCompactDefaultWrapBox(WrapType type, double compact);

/// One wrap object's result of checkWrapNetworks.
struct WrapNetworkCheck {
  std::string name;
  std::string network;  ///< "" when none applies
  long evaluations = 0, fallbacks = 0;
  std::map<NetworkWrapFallback, long> by_reason;
  double rms = 0.0, max = 0.0;  ///< position error where the network serves (radii), over `alphas`
};

/// For each wrap object's inputs, the network `pick(name, type)` (may be null) evaluated on the real
/// surface at fractions `alphas`: fallbacks by reason (calcNetworkWrapModel) and the position error
/// against the exact library where it serves.
std::vector<WrapNetworkCheck> checkWrapNetworks(const std::vector<WrapObjectInputs>& inputs,
                                                const std::function<const Mlp*(const std::string&, WrapType)>& pick,
                                                const std::vector<double>& alphas);

}  // namespace redmax
