#pragma once
// Differentiable simulation: the discrete adjoint of the core's fixed-step integrators
// (docs/gradients.md). The dissertation optimizes a reaching task with the adjoint method
// [D Sec. 6.2.11]; this is that method for the steps of core/integrators.
//
// A run is the map y_{k+1} = Phi_k(y_k, p) with y = (q, qdot, z) and N fixed steps of length h
// (FixedStepIntegrator::step: euler [D Eq. 4.20], bdf1 [D Eq. 4.80-4.82], sdirk2), and an
// objective J(y_N, p). Reverse accumulation gives dJ/dp for any number of parameters at a cost
// that does not grow with their number:
//   lambda_N = dJ/dy_N,   lambda_k = (dPhi_k/dy_k)^T lambda_{k+1},
//   dJ/dp    = dJ/dp|explicit + sum_k (dPhi_k/dp)^T lambda_{k+1} + (dy_0/dp)^T lambda_0.
// What is differentiated how (docs/gradients.md §2): where every part of the system has written
// derivatives (the skeleton, joint springs and dampers, coordinate limit forces, generalized
// springs, the driven coordinates' forces, Type I and II muscles' mass points, coordinate
// couplers; no other constraints, no auxiliary states) dPhi_k/dy_k, dPhi_k/du and dPhi_k/ds are exact, from the derivatives of
// inverse dynamics (core/dynamics/id_derivatives.hpp; a muscle mass s through dtau/ds, linear in
// s) through each integrator's own equations (§2.1). Elsewhere dPhi_k/dy_k is the central difference of the
// whole step, so every term the step evaluates (M, f with springs, dampers, muscle inertia of
// every path type, K and D of bdf1, the KKT rows of constraints, the z update) is in it; the
// generalized-force columns dPhi_k/du are central differences of the step along each driven
// coordinate (one pair per coordinate, shared by all of its time pieces), and so are the columns
// of each excitation-driven control (one pair per muscle per step, distributed to its nodes by
// the hat-function weights at the step's time); system parameters
// (muscle masses) are fourth-order central differences of the step between systems built at
// s -+ delta and s -+ 2 delta.
// The objective's derivatives are analytic. The forward run is the integrator's own step; no
// chart switch (System::reparameterize) is applied between steps.
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/dynamics/system.hpp"

namespace redmax::adjoint {

/// One generalized-force parameter (N m or N) on a system coordinate: the weight of one basis
/// function of time, evaluated at each step's start t_k = t0 + k h (the force is constant within a
/// step); a coordinate's force is the sum over its parameters.
///   Pieces  1 during time piece `piece` of `pieces` equal pieces (step k of N in piece k pieces / N)
///   Linear  the hat of node `piece` of `pieces` nodes at t0 + i duration / (pieces - 1): a
///           piecewise-linear force (one node: a constant)
///   Cubic   basis function `piece` of the clamped uniform cubic B-spline with `pieces` (>= 4)
///           control points over the run: a C2 force in time; the first and last control points
///           are its values at the start and the end
struct ForceParameter {
  enum class Shape { Pieces, Linear, Cubic };
  int coordinate = -1;
  int piece = 0;
  int pieces = 1;
  Shape shape = Shape::Pieces;
};

/// The weight of fp's basis function at step k of n (see ForceParameter).
double forceBasis(const ForceParameter& fp, int k, int n);

/// One muscle-excitation parameter: node `node` of the `nodes` nodes of a piecewise-linear
/// excitation in time on the system's control `control` (a MuscleForceTerm's excitation; nodes at
/// t0 + i duration / (nodes - 1), one node: a constant). The excitation of step k is the
/// interpolant at the step's start time t_k, clamped to [min, max] (the muscle's min_control and
/// max_control), constant during the step (docs/gradients.md §2). All nodes of one control must
/// have the same `nodes`, `min` and `max`.
struct ExcitationParameter {
  int control = -1;
  int node = 0;
  int nodes = 1;
  double min = 0.0, max = 1.0;
};

/// A system that depends on parameters (e.g. muscle masses): built for a value of them.
using SystemFactory = std::function<std::shared_ptr<const System>(const VecX& system_params)>;

/// What is simulated and which parameters the gradient is taken with respect to. The parameter
/// vector p is ordered: forces, excitation nodes, initial q entries, initial qdot entries, system
/// parameters.
struct Problem {
  std::string integrator = "euler";  ///< euler, bdf1 or sdirk2
  double dt = 1e-3;
  double duration = 1.0;             ///< cut into ceil(duration / dt) equal steps (as advance())
  /// sdirk2's Newton tolerance: tighter than a simulation's default (1e-10), since the step
  /// Jacobians difference converged stages and the iteration's error would show in them
  double newton_tol = 1e-12;
  /// relative step of the central differences of one step (dPhi_k/dy_k, dPhi_k/du): the default
  /// is about cbrt(machine epsilon), where truncation (e^2) and round-off (eps / e) meet for steps
  /// whose nonlinearity has the scale of the state; Hill-type tendons near their slack length
  /// bend on micrometres and want less (docs/gradients.md §2)
  double jacobian_step = 6e-6;
  /// how the step Jacobians are formed (docs/gradients.md §2.1): "analytic" from the derivatives
  /// of inverse dynamics (core/dynamics/id_derivatives.hpp; AdjointError where they do not
  /// apply), "differences" (central differences of the whole step), "auto" analytic where they
  /// apply, differences elsewhere
  std::string step_jacobians = "auto";
  State initial;                     ///< the state the run starts from before p is applied
  std::vector<ForceParameter> forces;
  std::vector<ExcitationParameter> excitations;
  /// the system's own controls (e.g. muscle excitations) during the whole run, for those that no
  /// excitation parameter drives (size numControls(); empty: all zero)
  VecX controls;
  std::vector<int> initial_q;        ///< coordinates whose initial value is a parameter
  std::vector<int> initial_qdot;     ///< coordinates whose initial speed is a parameter
  /// builds the system for the system parameters (called with an empty vector when there are
  /// none); the system must have no controllers and no coordinate map (checked); its controls
  /// are `controls` and the excitation parameters
  SystemFactory make_system;
  int num_system_params = 0;
  VecX system_param_delta;           ///< step of the central differences per system parameter
                                     ///< (the systems at s - 2 delta must be valid)
  int numParameters() const {
    return static_cast<int>(forces.size() + excitations.size() + initial_q.size() + initial_qdot.size()) +
           num_system_params;
  }
};

/// J(y_N, p) = sum of weighted terms:
///   point:  w/2 |x(q_N) - target|^2 for a point fixed in a body (x_i in body coordinates)
///   speed:  w/2 |qdot_N|^2 (come to rest)
///   effort: w sum_steps h |u_k|^2 (the integral of the squared generalized forces)
///   excitation effort: w sum_steps h |e_k|^2 over the excitation-driven controls (clamped)
///   track: w/2 sum_{k=1..N} h |x(q_k) - target(t_k)|^2 for a body point against a sampled
///          trajectory (linear between samples; the run must lie within them), the integral of the
///          squared tracking error by the right-endpoint rule
///   coordinate track: w/2 sum_{k=1..N} h (q_c(t_k) - target(t_k))^2 for a coordinate against a
///          sampled trajectory (e.g. a motion file's column), the same rule
struct Objective {
  struct Point {
    int body = -1;
    Vec3 x_i = Vec3::Zero();
    Vec3 target = Vec3::Zero();
    double weight = 1.0;
  };
  struct Track {
    int body = -1;
    Vec3 x_i = Vec3::Zero();
    std::vector<double> t;       ///< sample times, increasing (s)
    std::vector<Vec3> target;    ///< ground positions at t (m)
    double weight = 1.0;
    /// the target at time `time` (linear between samples; clamped to the first and last)
    Vec3 at(double time) const;
  };
  struct CoordinateTrack {
    int coordinate = -1;         ///< index into q
    std::vector<double> t;       ///< sample times, increasing (s)
    std::vector<double> value;   ///< the coordinate at t (rad or m)
    double weight = 1.0;
    /// the target at time `time` (linear between samples; clamped to the first and last)
    double at(double time) const;
  };
  std::vector<Point> points;
  std::vector<Track> tracks;
  std::vector<CoordinateTrack> coordinate_tracks;
  double speed_weight = 0.0;
  double effort_weight = 0.0;
  double excitation_weight = 0.0;
  /// true when a term is summed over the run's steps (tracks, coordinate_tracks)
  bool tracking() const { return !tracks.empty() || !coordinate_tracks.empty(); }
};

struct Result {
  double objective = 0.0;
  VecX gradient;             ///< dJ/dp (empty unless asked)
  State final;               ///< y_N
  long steps = 0;
  long step_evaluations = 0; ///< calls of the integrator's step, forward and adjoint together
  double forward_seconds = 0.0;  ///< wall time of the forward pass (the simulation alone)
  bool analytic_jacobians = false;  ///< the step Jacobians came from the ID derivatives
  std::string jacobian_note;     ///< why they did not; when they did, the parts taken by local differences (or empty)
};

/// How a result's step Jacobians were formed, as the commands print it: "analytic (...)" or
/// "central differences of the step; not analytic: <why>"
std::string stepJacobiansText(const Result& r);

/// Thrown for a problem that cannot be differentiated (bad sizes, unknown integrator, controls).
class AdjointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Simulate at parameters p and return the objective, with the adjoint gradient when
/// `with_gradient`. Throws AdjointError for an invalid problem and SimulationError when the run
/// diverges or produces NaN.
Result evaluate(const Problem& problem, const Objective& objective, const VecX& p, bool with_gradient);

/// The states y_0 .. y_N of the run at p and the controls of each step (the system's own, e.g.
/// the clamped muscle excitations, then one per driven coordinate), with the system that ran
/// them: the forward pass of evaluate, for plots and reports.
struct Trajectory {
  std::shared_ptr<const System> system;
  std::vector<State> states;   ///< N + 1
  std::vector<VecX> controls;  ///< N: step k's
};
Trajectory simulateTrajectory(const Problem& problem, const VecX& p);

/// The gradient by central differences of whole simulations: the reference `redmax gradient
/// --check` compares with. Per parameter, fourth-order differences (at p_i -+ e, -+ 2e) with
/// e = r max(1, |p_i|) for r = 1e-3, 1e-4, 1e-5, 1e-6 (a mass steps at most a quarter of itself),
/// and of the neighbouring pair of estimates that agree best the finer: kDifferenceRunsPerParameter
/// runs per parameter.
inline constexpr int kDifferenceRunsPerParameter = 16;
VecX finiteDifferenceGradient(const Problem& problem, const Objective& objective, const VecX& p);

/// max_i |a_i - b_i| / max_i |b_i|: the worst component error relative to the reference's scale
/// (0 when both vanish).
double worstRelativeError(const VecX& a, const VecX& b);

}  // namespace redmax::adjoint
