#pragma once
// Muscle mass points [D Sec. 5.3]: N point masses per musculotendon, each fixed at a material
// coordinate alpha in [0, 1] (fraction of the path's arc length, the "texture coordinate"), and a
// muscle (path + fibre/tendon lengths + mass points) as plain data.
//
// Placement convention (docs/design.md §2: mass only in the fibre portion, tendons massless by default):
//   - fibre share   phi = l_opt / (l_opt + l_ts)  (optimal fibre length, tendon slack length),
//     taken as a constant fraction of the path;
//   - the tendon share 1 - phi is split equally between the two ends, so the fibre occupies
//     alpha in [(1 - phi) / 2, (1 + phi) / 2]. OpenSim's Hill models have a single lumped tendon in
//     series and do not say where it sits; most limb muscles have both a proximal and a distal
//     tendon/aponeurosis, and the symmetric split keeps the mass centred (a choice at one end would
//     move the muscle's centre of mass by up to (1 - phi) / 2 of the path for no stated reason);
//   - N points at the centres of N equal sub-intervals of that range,
//       alpha_k = a0 + (a1 - a0) (k + 1/2) / N,   k = 0..N-1,
//     each carrying mass m / N (uniform distribution). This is the midpoint rule for the kinetic and
//     potential energy of a uniform line density; no point sits on an attachment, where its mass
//     would only add to a bone.
//   - Region::WholePath spreads the points over alpha in [0, 1] in the same way.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/muscles/hill/muscle_model.hpp"
#include "core/muscles/path.hpp"

namespace redmax {

class Mlp;  // core/muscles/wrap/network.hpp

/// Where the points of a muscle sit along the path.
struct MassPointOptions {
  enum class Region { Fibre, WholePath };
  int count = 20;                     // points per muscle (>= 1)
  Region region = Region::Fibre;
};

/// Material coordinates and masses of one muscle's points (alpha.size() == mass.size()).
struct MassPoints {
  std::vector<double> alpha;          // arc-length fractions in [0, 1]                   (N)
  std::vector<double> mass;           // kg                                              (N)
  int size() const { return static_cast<int>(alpha.size()); }
  double totalMass() const;
};

/// Uniform distribution of `total_mass` (kg) by the convention above. Throws ModelError on a
/// negative or non-finite mass, count < 1, optimal_fiber_length <= 0 or tendon_slack_length < 0
/// (only checked for Region::Fibre).
MassPoints makeMassPoints(double total_mass, double optimal_fiber_length, double tendon_slack_length,
                          const MassPointOptions& options = {});

/// Explicit points; throws ModelError unless sizes match, alpha in [0, 1] and masses >= 0 finite.
MassPoints makeMassPoints(std::vector<double> alpha, std::vector<double> mass);

/// How the mass points of a Type III (wrapping) muscle follow its surface
/// (core/muscles/wrap_muscle.hpp).
enum class WrapModel {
  Smooth,  ///< analytic smooth model (core/muscles/wrap/smooth.hpp): C2, exact J and Jdot
  Exact,   ///< the exact library, J and Jdot by finite differences (energy jumps at contact changes)
  Neural   ///< a trained network (core/muscles/wrap/network_model.hpp): C-infinity, exact J and Jdot;
           ///< falls back to Smooth outside its training box (CLI word `neural`)
};

/// Wrap-model choice and parameters of one muscle (used only by Type III muscles with mass points).
struct WrapMassOptions {
  WrapModel model = WrapModel::Smooth;
  double width = 0.0;    ///< Smooth: transition width of the penetration (m); <= 0: 0.05 radius
  double fd_step = 0.0;  ///< Exact: central-difference step on the end points (m); <= 0: 1e-6 size
  /// Neural: the network (loadWrapNetwork); also the fallback's transition width is `width`
  std::shared_ptr<const Mlp> network;
  /// Neural: networks for single wrap objects (by the WrapObject's name) and for surface types (by
  /// wrapTypeName), as a manifest lists them (core/muscles/wrap/network_set.hpp); see networkFor
  std::map<std::string, std::shared_ptr<const Mlp>> wrap_networks, type_networks;
  /// The network of wrap object `wrap` (a surface of type `type_name`): its own, else its type's,
  /// else `network` (null when none)
  const Mlp* networkFor(const std::string& wrap, const std::string& type_name) const {
    if (auto it = wrap_networks.find(wrap); it != wrap_networks.end()) return it->second.get();
    if (auto it = type_networks.find(type_name); it != type_networks.end()) return it->second.get();
    return network.get();
  }
  bool hasNetwork() const { return network || !wrap_networks.empty() || !type_networks.empty(); }
  bool network_fd_jdot = false;   ///< Neural: Jdot by the forward difference [D Eq. 5.58], not exactly
  double network_fd_eps = 0.0;    ///< Neural: its time step (s); <= 0: 1e-6
  // fallbacks are counted in the workspace (MuscleKinematics::wrap_counts), not here
};

/// Fibre-following placement of a muscle's mass points (core/muscles/fibre_placement.hpp):
/// with a model the points spread over the fibre's share of the path, the tendon taking its own
/// length; without one they sit at the fixed arc fractions mass_points.alpha ([D], "uniform").
struct FibreFollowing {
  std::shared_ptr<const hill::MuscleModel> model;  ///< null: uniform placement
  std::vector<double> c;                           ///< each point's fraction of the fibre, (0, 1) (N)
  int fiber_state = -1;                            ///< fiber_length among the model's states; -1: rigid tendon
  bool enabled() const { return model != nullptr; }
};

/// A musculotendon: its path and, when it carries inertia, its mass points. A muscle with no mass
/// points is lumped (massless), as OpenSim sees it. Type III paths carry mass points only in the
/// shape core/muscles/wrap_muscle.hpp supports (origin, one wrap surface, insertion).
struct Muscle {
  std::string name;
  MusclePath path;
  double optimal_fiber_length = 0.0;  // m (informative here; used by makeMassPoints)
  double tendon_slack_length = 0.0;   // m
  MassPoints mass_points;             // empty = massless
  WrapMassOptions wrap;               // Type III with mass points only
  FibreFollowing fibre;               // Type I/II with mass points only; default uniform
};

/// validatePath plus: Type III paths with mass points must have the supported shape
/// (wrapMassPointsUnsupportedReason in core/muscles/wrap_muscle.hpp), alpha and masses checked;
/// fibre-following placement only on Type I/II paths, one fraction c in (0, 1) per point.
/// Throws ModelError naming the muscle.
void validateMuscle(const Model& model, const Muscle& muscle);

}  // namespace redmax
