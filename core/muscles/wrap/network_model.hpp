#pragma once
// The trained wrap network as a run-time wrap model of one surface [D Sec. 5.3.3, Eq. 5.38, 5.44,
// 5.58] (issue 7): end points p1, p2 in the surface frame s (m), the muscle's arc fractions alpha
// and the surface size -> mass points w (3 x N), Jw = dw/d(p1, p2) (3 x 6 per point) and Jwdot =
// dJw/dt along (p1dot, p2dot), with one batched Mlp call for all points of the muscle.
//
// Scaling. Networks are trained in units of the surface size (osim_models/networks/README.md;
// radius input in [0.5, 1.5]); wrapping is scale-equivariant, so with R the radius (m) the network
// sees u = (p1 / R, p2 / R, alpha, 1) and w = R y(u). Then Jw = dw/dp = R (dy/du) (1 / R) = dy/du
// (scale-free), and Jwdot = d/dt (dy/du) along udot = (p1dot / R, p2dot / R): the network's Jdot
// along the scaled velocities.
//
// Input/output map (`meta wrap_map` in the network file). Absent (older files): the network sees
// q = p / R as above and outputs the point itself (in radii), so its training box bounds how far the
// end points may be. `compact C` (C > 0; `redmax train-wrap`'s files since issue 22): each end point
// enters as u = q / (1 + |q| / C), which maps all of space into the ball |u| < C (near end points
// keep their coordinates, far ones crowd towards the sphere |u| = C), and the output is the
// point's displacement d from the straight line, x = R (q1 + alpha (q2 - q1) + d(u1, u2, alpha)):
// d is zero on every straight path and of the order of the radius when the path wraps, however
// far the ends. Then Jw = d(q1 + alpha (q2 - q1))/dq + (dd/du) (du/dq) and Jwdot adds
// (d/dt dd/du) du/dq + dd/du d/dt(du/dq) and the alpha rate's -alphadot I, alphadot I.
//
// Jdot. Exact (forward tangents through the layers, Mlp::calcJacobianDot) by default, or the
// dissertation's forward difference of Jacobians [D Eq. 5.58] (Mlp::calcJacobianDotFd) with a time
// step eps (s) along the scaled velocity; its error is O(eps |udot|^2 |d2J/du2|).
//
// Fallback (checked on EVERY evaluation). The analytic smooth model (smooth.hpp) gives the points
// instead, and the result says why, when
//   - there is no network, or its `meta surface` names another surface type, or the surface is
//     neither a cylinder nor a sphere (ellipsoids and tori: the smooth model throughout);
//   - the surface is a cylinder with a quadrant and the configuration is one where OpenSim wraps
//     round the active side although the line passes on the other (a forced wrap, or a contact
//     whose point nearest the axis lies on the inactive side): networks are trained without a
//     quadrant; elsewhere the quadrant does not change the path (the smooth model's split);
//   - the cylinder's finite length changes the path: networks are trained on an effectively
//     infinite cylinder, and OpenSim's finite one differs from it only where both tangent points
//     lie beyond its ends (|z| > L/2: no wrap); an end point beyond an end alone changes nothing
//     (before issue 22 any end point beyond an end fell back);
//   - any scaled input of any point lies outside the network's training box (input_min/input_max
//     stored in the network file) [D Sec. 6.2.7].
// The fallback model is C2 but not equal to the network, so a switch between them moves the
// points: a run that falls back mid-way is not energy-consistent at the switch (callers count and
// warn; WrapFallbackMonitor).
//
// Counting. An evaluation's outcome is its return value; a muscle's outcomes are counted in its
// workspace (MuscleKinematics::wrap_counts, WrapFallbackCounts), never in model data, so threads
// with their own workspaces count without sharing anything. Callers that report fallbacks sum
// the counts of the workspaces they evaluated in into one WrapFallbackMonitor.
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/muscles/wrap/network.hpp"
#include "core/muscles/wrap/smooth.hpp"

namespace redmax {

struct Muscle;
struct PathWrap;
struct WrapMassOptions;

/// Why an evaluation of the network wrap model used the smooth model instead.
enum class NetworkWrapFallback {
  None,          ///< the network gave the points
  NoNetwork,     ///< no network was given
  SurfaceType,   ///< the network was trained for another surface type (meta surface)
  Quadrant,      ///< a quadrant changes the path (cylinder: a wrap round the active side; sphere: the library's own choice)
  FiniteLength,  ///< both tangent points lie beyond the cylinder's ends (no wrap there)
  OutsideBox     ///< a scaled input lies outside the training box
};

/// Short lowercase phrase for a reason ("outside the training box", ...).
std::string toString(NetworkWrapFallback why);

struct NetworkWrapOptions {
  bool fd_jdot = false;  ///< Jdot by the forward difference [D Eq. 5.58] instead of exactly
  double fd_eps = 1e-6;  ///< its time step (s) along the scaled end-point velocities
  SmoothWrapOptions fallback;  ///< options of the smooth model used on fallback
};

/// Outcome of one evaluation: which model gave the points, and for OutsideBox the first offending
/// input (index into the network's inputs, its scaled value, the mass point it belongs to).
struct NetworkWrapEval {
  NetworkWrapFallback fallback = NetworkWrapFallback::None;
  int input = -1;
  double value = 0.0;
  int point = -1;
  bool usedNetwork() const { return fallback == NetworkWrapFallback::None; }
  /// e.g. "input ins_x = 3.41 (size units) outside the training box [-3, 3]"
  std::string describe(const Mlp* net) const;
};

/// Buffers reused between evaluations (no allocation once sized for a muscle's point count).
struct NetworkWrapWorkspace {
  MlpWorkspace mlp;
  MatX X, Xdot, Y, J, Jdot;
};

/// The input/output map of a wrap network (header): compact = 0 for the older files' map (scaled
/// end points in, absolute points out); compact = C > 0 for `meta wrap_map compact C`.
struct WrapNetworkMap {
  double compact = 0.0;
  bool isCompact() const { return compact > 0.0; }
};

/// The map a network's `meta wrap_map` declares; std::invalid_argument for a value other than
/// "compact C" with a finite C > 0.
WrapNetworkMap wrapNetworkMap(const Mlp& net);
/// The meta value for a compact map ("compact C", C written with 17 digits).
std::string formatCompactWrapMap(double C);

/// u = q / (1 + |q| / C) (header), with M = du/dq and, when qdot is given, Mdot = d/dt M along qdot.
Vec3 calcCompactWrapInput(const Vec3& q, double C, Mat3* M = nullptr, const Vec3* qdot = nullptr,
                          Mat3* Mdot = nullptr);
/// The inverse: q = u / (1 - |u| / C) for |u| < C.
Vec3 calcCompactWrapInputInverse(const Vec3& u, double C);

/// "" when `net` can be a wrap network at all (8 inputs: origin, insertion, alpha, radius; 3
/// outputs), else why not.
std::string networkWrapUnsupportedReason(const Mlp& net);

/// "" when the Neural wrap model can serve `surface` with `net`: a usable network and a surface
/// the smooth fallback supports (smoothWrapUnsupportedReason); else why not. (Surfaces other than
/// the network's type are accepted and always fall back.)
std::string neuralWrapUnsupportedReason(const Mlp* net, const WrapSurface& surface);

/// The network's mass points at fractions alphas over `surface` (frame s), see the header; the
/// fractions move at `alphadots` (empty: all fixed), which enter Jdot (alpha is a network input).
/// With with_jdot false, Jdot is zero and no velocity pass is made. When x_alpha / x_alphadot are
/// given they receive dw/dalpha (m) and its time derivative along (p1dot, p2dot, alphadot). Returns
/// the outcome. std::invalid_argument for an unusable
/// network or surface (neuralWrapUnsupportedReason), an end point inside the surface or coincident
/// end points (as the smooth model).
NetworkWrapEval calcNetworkWrapModel(const Mlp* net, const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                     const Vec3& p1dot, const Vec3& p2dot, const std::vector<double>& alphas,
                                     bool with_jdot, WrapMassPoints& out, NetworkWrapWorkspace& ws,
                                     const NetworkWrapOptions& options = {},
                                     const std::vector<double>& alphadots = {}, std::vector<Vec3>* x_alpha = nullptr,
                                     std::vector<Vec3>* x_alphadot = nullptr);

/// One muscle's network wrap-model outcomes in one workspace (MuscleKinematics::wrap_counts): the
/// wrap-model dispatch adds to them, callers sum them (WrapFallbackMonitor::add).
struct WrapFallbackCounts {
  static constexpr int kReasons = static_cast<int>(NetworkWrapFallback::OutsideBox) + 1;
  long evaluations = 0;                  ///< calls of the wrap model
  long fallbacks = 0;                    ///< of which the smooth model gave the points
  std::array<long, kReasons> by_reason{};  ///< per NetworkWrapFallback (index None unused)
  NetworkWrapEval first;                 ///< the first fallback (fallback None: none yet)
  int first_wrap = -1;                   ///< its wrap object, index into path.wraps

  void record(const NetworkWrapEval& e, int wrap);
};

/// Per-muscle run summary of the network wrap model: evaluations, fallbacks and the first reason.
/// The core never prints: the first fallback of each muscle is passed to the sink (the CLI prints
/// it as a warning); later ones are only counted. Not thread-safe: it is the caller's, filled
/// from one thread with the counts of the workspaces it evaluated in (add(), or
/// takeWrapFallbackCounts in core/dynamics/muscle_term.hpp); share one between muscles (they are
/// told apart by name).
class WrapFallbackMonitor {
 public:
  using Sink = std::function<void(const std::string& message)>;
  struct Counts {
    long evaluations = 0;  ///< calls of the wrap model for the muscle
    long fallbacks = 0;    ///< of which the smooth model gave the points
    std::string first;     ///< the first fallback's description
    std::map<NetworkWrapFallback, long> by_reason;  ///< fallbacks per reason
  };

  explicit WrapFallbackMonitor(Sink sink = {});
  /// count one evaluation of muscle `muscle` (wrap object `wrap`); on its first fallback, tell the
  /// sink "muscle 'M', wrap object 'W': the network wrap model fell back to the smooth model (...)"
  void record(const std::string& muscle, const std::string& wrap, const NetworkWrapEval& e, const Mlp* net);
  /// add a workspace's counts of `muscle` (its name, wrap names and network); the sink hears of the
  /// muscle's first fallback as record() would tell it
  void add(const Muscle& muscle, const WrapFallbackCounts& c);
  void setSink(Sink sink);

  std::map<std::string, Counts> counts() const;
  long fallbacks(const std::string& muscle) const;
  long evaluations(const std::string& muscle) const;
  long totalFallbacks() const;
  /// one line per muscle: "  M: F of E evaluations fell back to the smooth model (R1 n1, R2 n2;
  /// first: ...)";
  /// "" when nothing was recorded
  std::string summary() const;
  void reset();

 private:
  /// after c's fallbacks grew from `before`: tell the sink of the muscle's first one
  void warnFirst(const std::string& muscle, const std::string& wrap, long before, const Counts& c);
  Sink sink_;
  std::map<std::string, Counts> counts_;
};

/// The Neural case of the wrap-model dispatch (core/muscles/wrap_muscle.cpp calcWrapModelPoints):
/// calcNetworkWrapModel with the network `net` (null: options.network) and the options of `options` (network_fd_jdot,
/// network_fd_eps, width of the fallback) in the caller's workspace `ws`.
NetworkWrapEval calcNeuralWrapModelPoints(const WrapMassOptions& options, const WrapSurface& surface, const Vec3& p1,
                                          const Vec3& p2, const Vec3& p1dot, const Vec3& p2dot,
                                          const std::vector<double>& alphas, const std::vector<double>& alphadots,
                                          bool velocity, WrapMassPoints& out, NetworkWrapWorkspace& ws,
                                          std::vector<Vec3>* x_alpha = nullptr,
                                          std::vector<Vec3>* x_alphadot = nullptr, const Mlp* net = nullptr);

/// Input layout of the network of a surface type: origin (3), insertion (3), alpha, then the
/// size parameters: radius (cylinder, sphere), semi-axes a b c (ellipsoid), inner and outer
/// radius (torus).
int wrapInputSize(WrapType type);

/// The surface described by the size part of an input vector (no quadrant; the cylinder's length
/// is 1000 radii, i.e. effectively infinite).
WrapSurface makeWrapSurfaceFromInput(WrapType type, const VecX& input);

/// A wrap network from a file (Mlp::load), checked by networkWrapUnsupportedReason.
/// NetworkFormatError (FILE:LINE: ...) for a bad file, std::runtime_error for I/O or an unusable
/// network (naming the file).
std::shared_ptr<const Mlp> loadWrapNetwork(const std::string& path);

/// The committed default network of a surface type: osim_models/networks/<type>_3x64.txt under
/// `source_dir` (the repository root). "" when none is committed for that type.
std::string defaultWrapNetworkPath(const std::string& source_dir, WrapType type);

/// Length of the path the network describes (m): the polyline through its points at alpha =
/// k / segments, k = 0..segments, ends included (the network has no length output; an
/// approximation for `redmax lengths --wrap neural`, converged to 1e-6 relative by 200 segments on
/// cylinder_3x64). `eval` reports fallbacks as calcNetworkWrapModel does.
double calcNetworkWrapPathLength(const Mlp* net, const WrapSurface& surface, const Vec3& p1, const Vec3& p2,
                                 int segments, NetworkWrapWorkspace& ws, NetworkWrapEval* eval = nullptr,
                                 const NetworkWrapOptions& options = {});

}  // namespace redmax
