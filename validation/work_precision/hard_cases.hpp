#pragma once
// Hard cases of the work-precision report (issue 9): numerical stability where the coordinates,
// the mass distribution, the stiffness, the run length or the path model make integration hard.
// Each case is a library function (tests/validation/hard_cases_test.cpp asserts its property; the
// report's "hard cases" table prints its measured number). Scenes are built in code; SI units,
// radians; energies in J.
//
//   spin         exponential-coordinate spherical joint spinning through many charts [D Sec. 4.5.8]
//   gimbal       SphericalEuler (XYZ) joint driven into gimbal lock: the run is stopped by a
//                singularity guard with a SimulationError naming joint, time and step
//   light_distal 10 g distal link spanned by a 1 kg muscle (20 mass points): integrator x step ladder
//   stiff        one hinge with a stiff spring (omega = 1000 rad/s): largest stable step of euler
//                (theory 2 / omega) and bdf1 (linearly implicit [D Eq. 4.80-4.82])
//   long_run     60 s of the conservative pendulum_straight scene with rk45: energy drift per second
//   conditional  a conditional path point switching during a run: energy jump per switch
//   nan          a force that turns NaN mid-run: the run stops naming time, coordinate and step
//   flick        finger flick [D Sec. 6.2.5] (validation/simulate/finger_flick.hpp): the largest
//                fingertip force and impulse survived, lumped vs inertial, per integrator and step
//   wrap_jump    wrapping double pendulum (makeWrapPendulum): the energy jump at each contact
//                change for each path model (smooth vs exact library with FD Jacobians)
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/mass_points.hpp"
#include "validation/report/report.hpp"
#include "validation/simulate/finger_flick.hpp"

namespace redmax::validation {

/// One outcome of integrating a scene (integrateHardCase).
struct HardRun {
  std::string integrator;
  double value = 0.0;          ///< fixed step dt (s) or rtol for rk45/cvode
  bool ok = false;             ///< no SimulationError and the check passed
  std::string failure;         ///< the SimulationError text (time, quantity, step) or the check's
  double failure_time = 0.0;
  double t_reached = 0.0;      ///< last sample time reached (s)
  double energy0 = 0.0;        ///< J
  double max_energy_err = 0.0; ///< max |E(t) - E(0)| over the samples, J
  double final_energy_err = 0.0;  ///< E(T) - E(0), J
  IntegratorStats stats;
  double cpu_s = 0.0;
};

/// Integrate sys from s0 for `duration`, sampling every sample_dt (s); a SimulationError or a
/// non-empty return of `check(state, energy)` stops the run (ok = false). Never throws for a
/// failing run; throws std::invalid_argument for bad integrator names or options.
HardRun integrateHardCase(const System& sys, const State& s0, const std::string& integrator, double value,
                          double duration, double sample_dt,
                          const std::function<std::string(const State&, double)>& check = {});

/// Throws SimulationError when some joint's singularityDistance (core/joints/joint.hpp) is below
/// `threshold`: "joint 'NAME' (TYPE) reached a coordinate singularity: distance D < threshold at
/// t = T s (step h = H s)". Returns the smallest distance over the joints otherwise.
double checkJointSingularities(const Model& model, const State& s, double threshold, double h);

// 1. spinning body, SphericalExp, rk45 rtol 1e-10
struct SpinCase {
  double revolutions = 0.0, max_q_norm = 0.0;
  long chart_switches = 0;
  double energy_err_rel = 0.0, momentum_err_rel = 0.0;  ///< max over 10 ms samples
};
SpinCase runSpinCase(double duration);

// 2. gimbal lock
struct GimbalCase {
  bool reported = false;            ///< the guard stopped the run with a SimulationError
  bool state_finite = true;         ///< every state returned was finite
  std::string message;
  double report_time = 0.0;
  double min_distance = 1.0;        ///< smallest |cos q2| reached before the report
  std::string unguarded;            ///< what the same run does without the guard
  double unguarded_min_distance = 1.0;  ///< smallest |cos q2| of that run (sampled every 0.1 ms)
};
GimbalCase runGimbalCase(const std::string& integrator, double threshold);

// 3. light distal link, heavy muscle
std::vector<HardRun> runLightDistalCase(bool quick);
/// the scene (for tests): 1 kg proximal link, 0.01 kg distal link (0.5 m each), muscle of 1 kg on
/// 20 points from link 1 to link 2, gravity -9.81 y, q = (0.8, -0.4) at rest
System makeLightDistalSystem(State& initial);

// 4. stiff spring
struct StiffCase {
  double omega = 0.0;                   ///< rad/s
  double euler_theory = 0.0;            ///< 2 / omega
  double euler_largest_stable = 0.0;    ///< bisected, relative resolution 1e-3
  double bdf1_largest_stable = 0.0;     ///< largest ladder step that stayed bounded (ladder up to 1 s)
  std::vector<HardRun> ladder;          ///< euler and bdf1 at 1e-4 ... 1 s
};
/// stable: 2000 steps without exceeding 1e6 times the initial energy
bool stiffStable(const std::string& integrator, double h);
StiffCase runStiffCase();

// 5. long run
HardRun runLongRunCase(const std::string& models_dir, double duration, double rtol);

// 6. conditional path point
struct ConditionalSwitch {
  double time = 0.0;
  double measured = 0.0;   ///< E after - E before across the sample interval holding the switch, J
  double predicted = 0.0;  ///< E(other branch) - E(this branch) at the interpolated switch state, J
};
struct ConditionalCase {
  std::vector<ConditionalSwitch> switches;
  double smooth_drift = 0.0;  ///< max |dE| over sample intervals without a switch, J
  double energy_scale = 0.0;  ///< J
};
ConditionalCase runConditionalCase(double duration);

// 7. NaN mid-run
struct NanCase {
  std::string integrator;
  bool stopped = false;
  std::string message;
  double time = 0.0, step = 0.0;
};
NanCase runNanCase(const std::string& integrator);

// 8. finger flick
/// runFlickStudy on models_dir/finger.osim with gravity, 0.2 kg in each of FDP and FDS for the
/// inertial variant; full: euler, symplectic, bdf1, sdirk2 at dt 1 ms and 0.5 ms; quick: euler
/// at 1 ms. The flick lasts 2 ms whatever the step, so impulse (N s) = force * 0.002.
std::vector<FlickStudyRow> runFlickCase(const std::string& models_dir, bool quick);

// 9. wrap contact changes
struct WrapContactChange {
  double time = 0.0;       ///< s, end of the 10 ms sample interval in which the penetration changed sign
  bool wrapping = false;   ///< true: the path starts to wrap (penetration became positive)
  double jump = 0.0;       ///< net energy change across the change, E(t_k+2) - E(t_k-3) (10 ms samples), J
  double transient = 0.0;  ///< max |E(t_j) - E(t_k-3)| for j in that window, J
};
struct WrapJumpCase {
  std::string model;       ///< "smooth", "exact_fd", "neural" (another WrapModel: "wrap model K")
  std::string scene;       ///< "osim" (double_pendulum_wrap.osim) or "in_box" (scenes::WrapPendulumSpec{})
  long evaluations = 0, fallbacks = 0;  ///< Neural: wrap-model evaluations, smooth fallbacks
  std::vector<WrapContactChange> changes;  ///< those with a full window inside the run
  int contact_changes = 0; ///< all sign changes of the penetration between samples
  double max_jump = 0.0;   ///< max |jump|, J
  double min_jump = 0.0;   ///< min |jump|, J
  double quiet_change = 0.0;  ///< largest |E_k - E_k-1| with no contact change within 4 samples, J
  double drift = 0.0;      ///< max |E(t) - E(0)|, J
  double energy0 = 0.0;    ///< J
  long steps = 0;
  double cpu_s = 0.0;
};
/// The wrapping double pendulum (makeWrapPendulum, 1 kg muscle) with the given path model,
/// released at q = (0.3, 0.35) rad, rk45 rtol = atol = 1e-12, total energy sampled every 10 ms.
WrapJumpCase runWrapJumpCase(const std::string& models_dir, WrapModel model, double duration);
/// The same measurement on the code-built pendulum scenes::WrapPendulumSpec{}
/// (validation/scenes/wrap_pendulums.hpp: end points 2.8 radii from the axis, inside the committed
/// networks' training box, where WrapModel::Neural runs without falling back) with wrap options
/// `wrap` (for Neural: its network; the integrator's fallback counts land in the result).
WrapJumpCase runWrapJumpCaseInBox(WrapMassOptions wrap, double duration);

struct HardCasesResult {
  struct Row {
    std::string name, setup, measured, bound;
    bool passed = false;
  };
  std::vector<Row> rows;
  double cpu_s = 0.0;
  std::vector<FlickStudyRow> flick;  ///< also in hard_flick.csv
  std::vector<WrapJumpCase> wrap_jumps;  ///< also in hard_wrap_jumps.csv (one row per contact change)
};

/// Every case (quick: shorter ladders and runs, the long run still 60 s). progress may be null.
HardCasesResult runHardCases(const std::string& models_dir, bool quick, std::ostream* progress);
/// report.md "Hard cases" table, hard_cases.csv, hard_flick.csv, hard_wrap_jumps.csv, summary.json
/// "hard_cases", one check per row.
void addHardCasesToReport(const HardCasesResult& r, Report& report);

}  // namespace redmax::validation
