#pragma once
// The threshold and architecture study [D Sec. 6.2.6, Fig. 6.8-6.11] (`redmax train-wrap
// --study`): Fig. 6.8's scene, a unit cylinder with the origin fixed at (-2, 1.2, 0.3) and the
// insertion moving along x (y = -1.3, z = -0.2) through the contact change (the straight line
// touches the cylinder at ins_x = -0.33); the mass point at alpha = 0.5. For every threshold a
// training set over the default cylinder box, for every architecture a network trained on it;
// each network's x_alpha.x and d x_alpha.x / d ins_x along the sweep, against the exact library's
// (its derivative by central differences, step 1e-7).
#include <functional>
#include <string>
#include <vector>

#include "tools/wrap_training/train.hpp"

namespace redmax {

struct WrapStudyOptions {
  std::vector<double> thresholds{0.01, 0.05, 0.1};     ///< each in [0, 1)
  std::vector<std::string> architectures{"1x32", "3x32"};  ///< parseHidden specs
  long samples = 10000;  ///< training samples per threshold
  TrainOptions train;    ///< epochs, batch, learning rate, seed (hidden is set per architecture)
  int points = 251;      ///< samples of the sweep ins_x in [-1.5, 1]
};

/// One network's curves along the sweep.
struct WrapStudyCurve {
  double threshold = 0.0;
  std::string architecture;
  std::vector<double> x, dxdins;  ///< x_alpha.x and d x_alpha.x / d ins_x, one per sweep point
  std::string val_rms;            ///< the network's final validation rms (meta final_val_rms_m)
};

struct WrapStudy {
  std::vector<double> ins_x, x_exact, dxdins_exact;
  std::vector<WrapStudyCurve> curves;  ///< threshold-major, architectures in order
};

/// Run the study; on_curve (if set) is called after each network.
WrapStudy runWrapThresholdStudy(const WrapStudyOptions& options,
                                const std::function<void(const WrapStudyCurve&)>& on_curve = {});

}  // namespace redmax
