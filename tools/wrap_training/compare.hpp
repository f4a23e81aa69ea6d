#pragma once
// Speed against error of the wrap models (`redmax train-wrap --compare`): random muscles over a
// surface type's default training box (valid end points, random end-point velocities, mass points
// at alpha = (k + 0.5) / points), each evaluated for position + J (3 x 6) + Jdot per mass point by
//   - the exact library, J and Jdot by central differences (the reference; one wrap per perturbed
//     pair of end points shared by the muscle's points, as the runtime does);
//   - the smooth model (band width = width x the surface size);
//   - each network, batched per muscle, exact Jdot and the forward difference [D Eq. 5.58], and as
//     a run-time wrap model (network_model.hpp) for cylinders and spheres.
// Timings repeat each loop until it has run min_time_s, on one thread.
#include <cmath>
#include <string>
#include <vector>

#include "core/muscles/wrap/network.hpp"
#include "core/muscles/wrap/wrap_surface.hpp"

namespace redmax {

/// A network to compare; timing_only: untrained (no error is reported, only its cost).
struct WrapCompareNet {
  std::string name;
  Mlp net;
  bool timing_only = false;
};

struct WrapCompareOptions {
  WrapType type = WrapType::Cylinder;
  long muscles = 200;
  int points = 20;  ///< mass points per muscle
  unsigned long long seed = 1;
  double width = 0.05;  ///< smooth model's band, in surface sizes
  std::vector<WrapCompareNet> nets;  ///< inputs and outputs must be those of `type` (std::invalid_argument)
  double min_time_s = 0.3;
};

/// One model's line of the comparison.
struct WrapCompareRow {
  std::string method;
  long parameters = 0;
  double us_per_point = 0.0;
  double rms = NAN, max = NAN;  ///< position error against the exact library (surface size units)
  std::string note;
};

/// The comparison's rows: exact library, smooth model, then the networks in order.
std::vector<WrapCompareRow> compareWrapModels(const WrapCompareOptions& options);

/// An untrained network of the given hidden widths for `type` (timing only: the cost of a network
/// does not depend on its weights), its box the default training box.
Mlp makeTimingWrapNetwork(WrapType type, const std::vector<int>& hidden, unsigned long long seed);

}  // namespace redmax
