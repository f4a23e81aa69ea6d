#pragma once
// The reaching task of [D Sec. 6.2.11] (`redmax optimize --task reach`, docs/gradients.md §7):
// constant generalized forces on an arm's coordinates (the shoulder and elbow torques) that bring a
// point of the hand to a target at the final time of a fixed-step run from the model's default
// state, optionally with the hand at rest there. The objective is
//   J(u) = 1/2 |p(q_N) - target|^2 + rest/2 |qdot_N|^2
// (the `point` and `speed` terms of core/adjoint). Minimized either by L-BFGS on the adjoint
// gradient (LBFGSpp, Debian's liblbfgspp-dev) or gradient-free by NLopt's Nelder-Mead or BOBYQA
// (libnlopt-dev), as the dissertation compared fminunc with and without its derivatives.
//
// Every method works in the scaled variables x = u / diag(M(q_0)) (ReachSetup::scale), starts
// from zero torques and stops at the first of: J <= stop_objective (by
// default 1/2 tolerance^2: the hand within `tolerance` of the target when rest = 0), its own
// convergence test (L-BFGS: |g| <= 1e-10, or a failed line search after which a restart from
// the best point with an empty memory no longer improves; NLopt: relative x change
// <= 1e-10), or max_simulations runs. A run that diverges (torques that spin the arm until the
// fixed step blows up) counts as a simulation with an infinite objective. One "simulation" is one forward run; an L-BFGS evaluation
// also runs the adjoint sweep, whose cost is counted apart in step evaluations.
//
// Driven by muscle excitations instead (drive = "excitations", beyond the dissertation, which
// names this as what its method could not do): the arm's Hill-type muscles pull (activation and
// fibre length are states of the run, docs/gradients.md §2) and the parameters are `nodes`
// piecewise-linear excitation nodes per muscle, from initial_excitation, bounded by each muscle's
// [min_control, max_control] (L-BFGS-B for lbfgs, NLopt's bounds for the others); the objective
// adds excitation_weight times the integral of the squared excitations. The report then also
// plots the hand path, the excitations and the tendon forces of the best run, and replays the
// best excitations on the lumped model (no muscle mass) when the muscles carry mass.
//
// The tracking task (task = "track", docs/gradients.md §7): the same torque parameters and
// methods, but the objective is the gradient's tracking SPEC (coords:FILE.mot[@C,...] from `motion`
// and any further terms of `objective`, e.g. track:MARKER=FILE.trc) summed over the whole run; the
// run starts from the motion's pose at its start for the tracked coordinates (at the model's
// default speeds, the motion's rates or speeds optimized with the torques: initial_speeds); the error reported is
// sqrt(2 J / duration) (trackingError) and the report adds best_run.csv and tracking.png|svg (each
// tracked coordinate of the best run against the motion).
//
// The report (writeReachReport) in DIR: report.md (setup, per method: converged torques,
// simulations, step evaluations, wall time, final error and speed), <method>_iterations.csv (one
// row per objective evaluation), objective.png|svg (best objective against simulations, every
// method, log scale; needs gnuplot). Written into a temporary folder beside DIR and renamed into
// place, so DIR is either the whole report or untouched.
#include <functional>
#include <string>
#include <vector>

#include "validation/gradient/gradient.hpp"
#include "validation/simulate/simulate.hpp"

namespace redmax::validation {

struct ReachOptions {
  /// reach: a point to a target at the end (the dissertation's); track: a tracking objective
  /// over the whole run (coordinates of a motion file and/or markers of a TRC file)
  std::string task = "reach";
  /// track: FILE.mot[@C,...], the gradient's coords: term (docs/gradients.md §3), weight 1
  std::string motion;
  /// track: further terms of the gradient's objective SPEC (e.g. "track:M=F.trc;1e-4*effort"),
  /// added to the motion's; a tracked task needs a coords: or track: term among them
  std::string objective;
  std::string model_path;
  SimulationModelOptions model_options;
  std::string body = "hand";
  Vec3 point = Vec3::Zero();   ///< in the body's frame (m)
  Vec3 target = Vec3::Zero();  ///< in ground (m)
  std::vector<std::string> coordinates;  ///< torqued coordinates; empty: all of the model's
  /// the torques in time: "" constant (the dissertation's), "K" K constant pieces, "K~linear" K
  /// nodes of a piecewise-linear torque, "K~cubic" K (>= 4) control points of a cubic B-spline
  std::string torques_in_time;
  double duration = 0.3, dt = 0.01;
  std::string integrator = "euler";      ///< euler, bdf1 or sdirk2
  double rest_weight = 0.0;              ///< weight of 1/2 |qdot_N|^2
  double tolerance = 1e-3;               ///< m: the reach error that counts as reached
  double stop_objective = -1.0;          ///< < 0: 1/2 tolerance^2
  double max_torque = 100.0;             ///< N m: the gradient-free methods' box +-max_torque
  double initial_step = 1.0;             ///< rad/s^2: the gradient-free methods' first step (scaled)
  long max_simulations = 2000;
  std::string drive = "torques";         ///< torques or excitations
  std::vector<std::string> muscles;      ///< excited muscles; empty: every muscle with a Hill-type model
  int nodes = 5;                         ///< excitation nodes per muscle over the run
  double initial_excitation = 0.1;       ///< every node's start value (within each muscle's bounds)
  double excitation_weight = 0.0;        ///< weight of the integral of the squared excitations
  /// track: the run's initial speeds of the tracked coordinates: "default" (the model's), "motion"
  /// (the motion's rates at the start, startRate) or "free" (parameters optimized with the torques,
  /// from the motion's rates; they follow the torques in the parameter vector, unscaled, rad/s or m/s)
  std::string initial_speeds = "default";
};

/// The rate at `time` of a tracked coordinate (rad/s or m/s): the derivative of the quadratic
/// through the samples i, i+1, i+2 where t_i <= time < t_{i+1} (the last three samples near the
/// end; the slope of two; 0 for one): second order in the spacing, unlike the linear
/// interpolant's slope (first order), for motions sampled at 100 Hz or coarser.
double startRate(const adjoint::Objective::CoordinateTrack& track, double time);

/// The task resolved against the model.
struct ReachSetup {
  ReachOptions options;
  GradientSetup gradient;  ///< the adjoint problem (torque parameters) and the objective
  Vec3 start_point = Vec3::Zero();  ///< the hand point at the start (default pose)
  /// N m per optimization unit, per torque: the coordinate's diagonal entry of the mass matrix at
  /// the start (kg m^2), so that every method works in joint accelerations (rad/s^2), u = scale x.
  /// The shoulder's long-axis rotation has about a tenth of the flexion's inertia; in torques the
  /// problem is that badly scaled and L-BFGS's first steps fling the arm round.
  VecX scale;
  VecX x0;            ///< the start, scaled (zero torques, or the initial excitations)
  VecX lower, upper;  ///< bounds on the scaled parameters (excitations: the muscles' control bounds)
  bool bounded = false;  ///< lbfgs runs L-BFGS-B within [lower, upper] (the excitations)
};

/// The objective at which every method stops: stop_objective when >= 0, else 1/2 tolerance^2
/// (reach: the point within `tolerance` m) or 1/2 tolerance^2 duration (track: trackingError <=
/// tolerance).
double stopObjective(const ReachOptions& o);

/// track: sqrt(2 J / duration), the run's root-mean-square tracking error when the objective is one
/// unit-weight coords: term (rad or m, summed over the tracked coordinates)
double trackingError(const ReachOptions& o, double objective);

/// Throws std::invalid_argument ("--body 'x': ...", "--coordinates 'c': ...", "--target: ...")
/// for bad input, osim::ConvertError / ModelError for the model.
ReachSetup makeReachSetup(const ReachOptions& options);

/// One objective evaluation of an optimization.
struct ReachEvaluation {
  long simulations = 0;        ///< forward runs so far, this one included
  long step_evaluations = 0;   ///< integrator steps so far (forward and adjoint)
  double seconds = 0.0;        ///< since the method started
  double objective = 0.0;
  double best_objective = 0.0; ///< the lowest so far
  double error = 0.0;          ///< |p - target| of this run (m); track: trackingError
};

struct ReachResult {
  std::string method;          ///< lbfgs, nelder-mead or bobyqa
  VecX torques;                ///< the best parameters found (per setup coordinate)
  std::vector<std::string> names;
  std::vector<ReachEvaluation> evaluations;
  long simulations = 0, step_evaluations = 0;
  long restarts = 0;           ///< L-BFGS restarts after a failed line search; NLopt restarts after converging short
  long failed_simulations = 0; ///< runs that diverged (counted in simulations, objective +inf)
  double seconds = 0.0;
  /// at the best parameters: error |p - target| (m; track: trackingError), final_speed |qdot_N|
  double objective = 0.0, error = 0.0, final_speed = 0.0;
  bool reached = false;        ///< error <= tolerance
  std::string stop;            ///< why it stopped
  /// how its adjoint gradients formed the step Jacobians (adjoint::stepJacobiansText); empty for
  /// the gradient-free methods
  std::string gradient_route;
};

/// Progress: called after every evaluation.
using ReachProgress = std::function<void(const std::string& method, const ReachEvaluation&)>;

/// Run one method (lbfgs, nelder-mead, bobyqa) from setup.x0 (zero torques or the initial excitations). Throws std::invalid_argument
/// for an unknown method and SimulationError when a run diverges.
ReachResult optimizeReach(const ReachSetup& setup, const std::string& method, const ReachProgress& progress = {});

/// The methods optimizeReach takes.
const std::vector<std::string>& reachMethods();

/// The best run replayed (for excitation reports): times, the hand point, per excited muscle its
/// excitation and tendon force per step; `lumped_*` the same excitations on the model without
/// muscle mass (empty when the muscles carry none).
struct ReachReplay {
  std::vector<double> t;
  std::vector<Vec3> hand;
  std::vector<std::string> muscles;
  std::vector<std::vector<double>> excitation, tendon_force;  ///< [muscle][step]
  std::vector<Vec3> lumped_hand;
  double lumped_error = -1.0;  ///< m, at the end (< 0: not replayed)
};
ReachReplay replayReach(const ReachSetup& setup, const VecX& params);

/// track: the tracked coordinates of the run at params against their targets, per step (the
/// state at t_k and the target there, the objective's linear interpolation of the file).
struct TrackReplay {
  std::vector<double> t;
  std::vector<std::string> coordinates;
  std::vector<std::vector<double>> simulated, target;  ///< [coordinate][state]
  double rms = 0.0;  ///< the root-mean-square error over the tracked coordinates and the states t_1 .. t_N
};
TrackReplay replayTrack(const ReachSetup& setup, const VecX& params);

/// Write the report into dir (see the top of this file); returns the plot's status line. Throws
/// std::runtime_error "PATH: why" when the folder cannot be written.
std::string writeReachReport(const std::string& dir, const ReachSetup& setup, const std::vector<ReachResult>& results,
                             const std::string& command_line);

}  // namespace redmax::validation
