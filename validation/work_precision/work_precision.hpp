#pragma once
// Work-precision report, integrators part (`redmax work-precision --report DIR [--quick]`): for the
// project's scenes, every integrator over a ladder of fixed steps (euler, symplectic, bdf1, sdirk2)
// or tolerances (rk45, cvode); error = max-norm of the state error (q and qdot) at the end against
// a tight reference run (rk45, rtol 1e-12, atol 1e-14); cost = CPU time of the run (this thread)
// and right-hand-side evaluations (IntegratorStats); energy drift per simulated second (all scenes
// here have only gravity and muscle inertia, no muscle force; Type II mass points passing a via point
// on a moving body make the energy jump, which the reference's own drift shows); runs that throw
// SimulationError are kept and marked diverged.
//
// Scenes (osim_models/, through the converter; the pendulums and the finger get the stated muscle
// mass on their points with addMusclePointMasses, on top of the bodies, as the dissertation's
// experiments state it; the running leg takes it from its bones):
//   pendulum_straight  double_pendulum_straight.osim, straight_muscle 1 kg (20 points), q = (0.8, -0.4)
//                 rad at rest (smooth and conservative: the order checks use it)
//   pendulum_via  double_pendulum_via.osim, via_muscle 1 kg (20 points), q = (0.8, -0.4) rad at rest
//   finger        finger.osim, FDP and FDS 0.2 kg each (the dissertation's 6.2.5), default flexed
//                 pose, released at rest under gravity, 0.3 s (light phalanges pulled by heavy muscles
//                 whip: over 1 s the state error of rk45 at rtol 1e-9 is still 3e-4 rad/s)
//   pendulum_wrap double_pendulum_wrap.osim, wrap_muscle (Type III, quadrant -x cylinder at the
//                 middle joint) with 1 kg on 20 points, smooth wrap model (the default), q = (0.3,
//                 0.35) rad at rest: wrapped at the start, q2 swings through the contact change
//                 (q2 about 0.1 rad) several times a run; conservative, so its drift is the method's
//   running_leg   running_leg.osim under gravity with physiological muscle mass taken from the bones
//                 (converter/build/muscle_mass.hpp: 60 N/cm^2, 1059.7 kg/m^3; soleus_r Type I,
//                 tib_ant_r Type II; the gastrocnemii stay lumped, Type III); the free-floating leg
//                 falls with hip/knee/ankle velocities (3, -4, 2) rad/s
//
// Outputs in DIR: <scene>.csv (one row per run), <scene>.png|svg (log-log error against CPU time,
// one line per integrator), report.md (tables, the recommended integrator and setting per scene
// with its numbers), summary.json ("work_precision" section). Everything is written atomically by
// validation/report/report.hpp.
#include <iosfwd>
#include <string>
#include <vector>

#include "core/dynamics/system.hpp"
#include "core/muscles/mass_points.hpp"
#include "validation/report/report.hpp"
#include "validation/scenes/wrap_pendulums.hpp"
#include "validation/work_precision/id_studies.hpp"

namespace redmax::validation {

struct WorkPrecisionOptions {
  std::string models_dir;              ///< folder holding the osim_models scenes
  bool quick = false;                  ///< runs of min(0.5 s, duration) and 3-rung ladders (CI)
  std::vector<std::string> scenes;     ///< empty = all (workPrecisionSceneNames())
  std::vector<std::string> integrators;  ///< empty = all (euler, symplectic, bdf1, sdirk2, rk45, cvode)
  std::string gnuplot;                 ///< findGnuplot hint ("" auto, "none" no plots)
  /// accuracy targets for the recommendations (max-norm state error)
  std::vector<double> targets = {1e-3, 1e-6};
  /// "integrators", "masspoints", "reduction" (validation/work_precision/id_studies.hpp); empty = all
  std::vector<std::string> studies;
  /// the shared data folder (holding opensim/) for the ID studies' trial, set F; "" or absent: the
  /// running leg stands in and the report says so
  std::string shared_dir;
};

/// One integrator run.
struct WorkPrecisionRun {
  std::string integrator;
  std::string knob;           ///< "dt" (fixed step) or "rtol" (adaptive; atol = 1e-2 rtol)
  double value = 0.0;         ///< the step (s) or relative tolerance
  bool ok = false;            ///< false: diverged or failed (see failure)
  std::string failure;        ///< SimulationError text with its time, or another exception's
  double error = 0.0;         ///< max |x - x_ref| over q and qdot at the end (rad, m, rad/s, m/s)
  double cpu_s = 0.0;         ///< CPU time of the run (thread)
  long rhs_evals = 0, steps = 0, failed_steps = 0;
  double energy_drift = 0.0;  ///< max |E(t) - E(0)| over the samples / duration, J/s
  double energy_drift_rel = 0.0;  ///< energy_drift / E_scale, 1/s
};

/// A scene, ready to integrate.
struct WorkPrecisionScene {
  std::string name, description;
  System system;
  State initial;
  double duration = 1.0;      ///< s (quick runs use min(0.5 s, duration))
  double energy_scale = 1.0;  ///< J: max(kinetic energy at t = 0, |V range|) used for relative drift
};

/// One scene's results.
struct WorkPrecisionSceneResult {
  std::string name, description;
  int ndof = 0;
  double duration = 0.0;
  double energy_scale = 0.0;
  double reference_cpu_s = 0.0;
  double reference_energy_drift = 0.0;   ///< J/s of the reference run
  std::vector<WorkPrecisionRun> runs;
  /// per target: the cheapest ok run (CPU time) with error <= target; index into runs or -1
  std::vector<int> recommended;
};

struct WorkPrecisionResult {
  std::vector<WorkPrecisionSceneResult> scenes;
  ReportFiles files;
  /// the ID studies (has_masspoints / has_reduction say which ran)
  IdStudiesResult id_studies;
};

/// "integrators", "masspoints", "reduction"
std::vector<std::string> workPrecisionStudyNames();

/// "pendulum_straight", "pendulum_via", "pendulum_wrap", "finger", "running_leg"
std::vector<std::string> workPrecisionSceneNames();

/// The wrapping double pendulum of osim_models/double_pendulum_wrap.osim (through the converter):
/// wrap_muscle with `muscle_kg` on 20 points whose path follows the cylinder by `model`
/// (core/muscles/wrap_muscle.hpp), gravity only, q = (0.3, 0.35) rad at rest.
struct WrapPendulum {
  System system;
  State initial;
  Muscle muscle;  ///< wrap_muscle with its mass points, as the system's MuscleTerm holds it
};
WrapPendulum makeWrapPendulum(const std::string& models_dir, WrapModel model, double muscle_kg = 1.0);

/// the penetration of a single-wrap muscle's straight segment (validation/scenes/wrap_pendulums.hpp)
using scenes::wrapPenetration;
/// Build a scene from models_dir. Throws std::invalid_argument for an unknown name and the
/// converter's ConvertError for a missing or bad model file.
WorkPrecisionScene makeWorkPrecisionScene(const std::string& name, const std::string& models_dir);

/// The step or tolerance ladder of an integrator (largest first).
std::vector<double> workPrecisionLadder(const std::string& integrator, bool quick);

/// Run one integrator setting on a scene from scene.initial to t_end; never throws for a
/// diverged run (marked !ok). x_ref: the reference end state [q; qdot].
WorkPrecisionRun runWorkPrecisionCase(const WorkPrecisionScene& scene, const std::string& integrator, double value,
                                      double t_end, const VecX& x_ref);

/// Everything: all scenes x integrators x ladder (study "integrators"), the ID studies
/// ("masspoints", "reduction"), then the report in report_dir. progress (may be
/// null) gets one line per scene and integrator. Throws std::invalid_argument for unknown scene,
/// integrator or study names, ReportError when DIR cannot be written.
WorkPrecisionResult runWorkPrecision(const std::string& report_dir, const WorkPrecisionOptions& options,
                                     std::ostream* progress = nullptr);

}  // namespace redmax::validation
