#pragma once
// Muscle-mass sweeps for `redmax validate --mass-sweep` (issue 6, graceful degradation;
// [D Sec. 6.2.8-6.2.9], Figs. 6.16-6.17): one inverse-dynamics trial, processed once by the
// InverseDynamicsTool, solved by the core once per sweep value with the muscle mass that value
// gives, and compared with the zero-mass core result.
//
// Sweep values s:
//   transfer        s is the fraction of the transfer body's mass moved into the muscles that span
//                   it (MuscleMassOptions::transfer_fraction = s), e.g. 0, 0.2, ..., 0.8
//   physiological   s scales every muscle's physiological mass (the density is s * density), e.g.
//                   0, 1e-3, 0.01, 0.1, 1
// Every value runs the muscle-mass code path, s = 0 included: there the muscles keep the mass
// points a positive value gives them, each with zero mass, and the bodies keep their masses
// (makeCoreMassEngineFactory). So the zero check compares two different computations (the
// MuscleTerm with massless points against the plain skeleton), not a run with itself.
//
// Analysis per output column c (tau_0 = the zero-mass core result, y_k(s) = tau_s(k) - tau_0(k)):
//   peak(s)            max_k |tau_s(k)|; peak_change_rel(s) = (peak(s) - peak(0)) / peak(0)
//   max_diff_rel(s)    max_k |y_k(s)| / peak(0)  (the largest change at any frame, "inertial effect")
//   linear fit         per frame k, y_k(s) = b_k s by least squares through the origin (the
//                      difference must vanish at s = 0); pooled over every frame and value:
//                        R^2 = 1 - sum (y - b_k s)^2 / sum (y - mean_s y_k)^2
//                      and nonlinearity_rel = max |y - b_k s| / peak(0)
//   zero check         a value s = 0 must reproduce tau_0: max_k |y_k(0)| <= zero_tolerance * peak(0)
//                      for every column
//
// Independent references (MassSweepOptions::simbody_check, references), which is what shows the
// graceful degradation; the core's own fit below is linear by construction and shows nothing:
//   Simbody            every value solved by SimbodyIdEngine with plugin/simbody's MuscleInertia
//                      (its own mass-point kinematics on Simbody stations, not the core's
//                      MuscleTerm): core vs Simbody at each value (engine tolerance of the column
//                      peak), and the inertial effect tau(s) - tau(0) of each engine against the
//                      other's, so the effect's decay toward s = 0 is seen by both
//   OpenSim            the value 0 (massless points) against OpenSim's own inverse-dynamics result
//                      of the trial where one is given, at the reference tolerance
//
// Linearity by construction. The masses the sweep moves (transfer: (1 - s) m_body and s m_body
// split over the muscles; physiological: s times each muscle's mass, removed from the bodies by
// the parallel-axis theorem) enter the body spatial inertias and the mass-point masses affinely,
// and the mass points stay at the same path fractions. Inverse dynamics
// tau = M(q) qddot - f(q, qdot) [D Eq. 5.7] is linear in those masses at fixed (q, qdot, qddot),
// so tau_s - tau_0 is exactly s times a per-frame vector: R^2 = 1 and nonlinearity_rel = 0 up to
// round-off (~1e-15). A measurable departure would mean a bug, not physics.
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "converter/build/muscle_mass.hpp"
#include "converter/id/inverse_dynamics_tool.hpp"
#include "validation/compare/metrics.hpp"
#include "validation/report/report.hpp"

namespace redmax::validation {

struct MassSweepOptions {
  /// Transfer (values are fractions in [0, 1), transfer_body required) or Physiological (values
  /// are scales >= 0 of the physiological mass); the other fields (muscles, mass points, region,
  /// tension, density) apply to every value
  osim::MuscleMassOptions base;
  std::vector<double> values;  ///< sorted and checked by checkMassSweepValues; 0 is added if absent
  /// columns plotted as torque curves and peak changes; empty: chosen by chooseMainColumns
  std::vector<std::string> main_columns;
  double zero_tolerance = 1e-12;  ///< the zero check, relative to each column's zero-mass peak
  double r2_min = 0.999;          ///< the acceptance R^2 (reported per column, not pass/fail)
  bool progress = false;          ///< progress lines on stderr
  /// also solve every value with Simbody's muscle inertia (SimbodyIdEngine with muscles)
  bool simbody_check = false;
  double engine_rel = 1e-9, engine_abs = 1e-10;  ///< its tolerance against the core (as core_vs_simbody)
  /// results of the trial computed elsewhere (OpenSim's own ID): the value 0 is compared with each
  /// (columns by name, the reference's rows as the grid) at reference_tolerance, a check in the verdict
  struct Reference {
    std::string label;  ///< "opensim"
    osim::Storage table;
  };
  std::vector<Reference> references;
  Tolerance reference_tolerance{1e-9, 1e-6, 1e-9, std::numeric_limits<double>::infinity()};
  Interpolation interpolation = Interpolation::Linear;
};

/// The muscle-mass options of one sweep value: transfer_fraction = value, or density * value
/// (physiological scale 0 is density 0, which osim::applyMuscleMass refuses: engine factories give
/// it the points of a positive density with zero mass, see hasZeroMuscleMass).
osim::MuscleMassOptions massOptionsForValue(const osim::MuscleMassOptions& base, double value);

/// Options that move no mass: physiological with density 0 or transfer of fraction 0.
bool hasZeroMuscleMass(const osim::MuscleMassOptions& options);

/// Sort, check and complete sweep values: finite, distinct, in [0, 1) for transfer and >= 0 for
/// physiological, 0 added when absent. Throws std::invalid_argument naming the bad value, or when
/// the source is None.
std::vector<double> checkMassSweepValues(const osim::MuscleMassOptions& base, std::vector<double> values);

/// Parse "0,0.2,0.4" (commas or spaces); throws std::invalid_argument for a bad number or an
/// empty list.
std::vector<double> parseMassSweepValues(const std::string& text);

/// The columns the figures show: for each of ankle, knee and hip, the labels that contain the
/// word and the side of the transfer body ("_r" or "_l" suffix of its name; both sides when the
/// body has none or for physiological sweeps); all labels when none matches.
std::vector<std::string> chooseMainColumns(const std::vector<std::string>& labels, const std::string& transfer_body);

/// One engine for one sweep value, with what the muscle-mass step did.
struct MassSweepEngine {
  std::unique_ptr<osim::IdEngine> engine;
  double muscle_mass = 0.0;      ///< kg carried by mass points
  int muscles_with_mass = 0;
  std::string description;       ///< osim::describeMuscleMass of the plan
  osim::WrapMassCount wrap;      ///< wrapping (Type III) muscles: how many carry mass, why the others do not
  /// the model with the mass taken from the bodies and its muscles with their mass points (for a
  /// second engine, e.g. Simbody with muscle inertia); null when the factory does not give it
  std::shared_ptr<const MusculoskeletalModel> model;
};

/// Makes the engine of one value's options for the tool's model (same coordinates, same velocity
/// convention). Throws ConvertError / std::invalid_argument for options the model rejects.
using MassSweepEngineFactory = std::function<MassSweepEngine(const osim::MuscleMassOptions&)>;

/// The default factory: osim::applyMuscleMass on the tool's description (its build options), the
/// core engine over the resulting model with the muscles' mass points. Options with zero mass
/// (hasZeroMuscleMass) give the tool's bodies unchanged and the muscles the mass points that a
/// positive value would place, each with mass 0, so the mass-point code still runs.
MassSweepEngineFactory makeCoreMassEngineFactory(const osim::InverseDynamicsTool& tool);

/// Per column results (see the file comment for the definitions).
struct MassSweepColumn {
  std::string name;
  double peak_zero = 0;                 ///< max_k |tau_0(k)|
  std::vector<double> peak;             ///< per value
  std::vector<double> peak_change_rel;  ///< per value
  std::vector<double> max_diff_rel;     ///< per value
  /// false when the column does not change at any value (|y| <= 1e-12 * peak(0) + 1e-12): the
  /// fit is then undefined and r2 is NaN
  bool has_effect = false;
  double r2 = std::numeric_limits<double>::quiet_NaN();
  double nonlinearity_rel = 0;          ///< max |y - b_k s| / peak(0)
  double slope_max_rel = 0;             ///< max_k |b_k| / peak(0): change per unit of s
};

/// The analysis of a sweep, pure (no engines).
struct MassSweepAnalysis {
  std::vector<MassSweepColumn> columns;  ///< every column, in table order
  int zero_index = -1;                   ///< index of the value 0 (-1 if absent)
  double zero_max_rel = 0;               ///< worst column of the zero check (0 if no zero value)
  bool zero_passed = true;
  double r2_min_observed = std::numeric_limits<double>::quiet_NaN();  ///< over columns with an effect
  double nonlinearity_max = 0;           ///< over columns
};

/// Analyse the torques of a sweep: values (n, distinct), tau[j] the result at values[j] and tau0
/// the zero-mass result, all frames x columns with the same shape. Columns are unnamed (the caller
/// names them). Throws std::invalid_argument on shape mismatches or when no value is nonzero.
MassSweepAnalysis analyzeMassSweep(const std::vector<double>& values, const std::vector<MatX>& tau, const MatX& tau0,
                                   double zero_tolerance = 1e-12);

/// One value of a finished sweep.
struct MassSweepPoint {
  double value = 0;
  double muscle_mass = 0;  ///< kg
  int muscles_with_mass = 0;
  double seconds = 0;      ///< solving every frame
  std::string description;
  osim::WrapMassCount wrap;  ///< from the engine (MassSweepEngine::wrap)
};

/// The Simbody engine with muscle inertia (plugin/simbody) at the sweep's largest value, solved on
/// the same inputs and compared with the core at that value: an engine cross-check
/// (addSimbodyMassCheck), counted in the verdict unless simbodyMassCheckNotCountedReason says why not.
struct MassSweepSimbodyCheck {
  bool ran = false;
  bool failed = false;     ///< it was built but failed on a frame
  std::string skipped;     ///< why not ("" if it ran)
  double value = 0;
  osim::Storage result;
  Comparison comparison;   ///< core_mass_vs_simbody_mass (when it ran)
  /// when Simbody needed OpenSim's fallback inertia (validation/simbody_cross_check.hpp): the core
  /// on that same model at this value, and the note that says so; empty otherwise
  osim::Storage core_result;
  std::string note;
  std::string not_counted;  ///< simbodyMassCheckNotCountedReason at this value ("" = counted)
  /// the inertial effects tau(s) - tau(0) of both engines (each against its own value 0), worst
  /// column max_k |effect_core - effect_simbody| / zero-mass peak; NaN until filled (both values ran)
  double effect_max_rel = std::numeric_limits<double>::quiet_NaN();
  /// the same difference relative to the core's largest effect at this value (NaN at s = 0 or when
  /// there is no effect)
  double effect_rel_to_effect = std::numeric_limits<double>::quiet_NaN();
  /// the core torques this check compares with: core_result, or the sweep's own at this value
  const osim::Storage& coreTorques(const osim::Storage& sweep_value) const {
    return core_result.numRows() > 0 ? core_result : sweep_value;
  }
};

struct MassSweepResult {
  MassSweepOptions options;          ///< values completed and sorted
  std::vector<MassSweepPoint> points;
  std::vector<osim::Storage> torques;  ///< per value, the tool's output table
  std::vector<std::string> main_columns;
  MassSweepAnalysis analysis;
  MassSweepSimbodyCheck simbody;  ///< the largest value's Simbody check (simbody_values.back())
  /// MassSweepOptions::simbody_check: one Simbody check per value, in value order
  std::vector<MassSweepSimbodyCheck> simbody_values;
  /// the value 0 against each MassSweepOptions::references entry ("mass_sweep_zero_vs_<label>")
  std::vector<Comparison> zero_vs_references;
};

/// Run the sweep on the tool's processed inputs (the tool is not re-run: the same splines and
/// loads serve every value). zero_mass is the plain zero-mass core result of the same tool.
/// factory = {} uses makeCoreMassEngineFactory(tool). Throws std::invalid_argument (bad values),
/// osim::ConvertError (options the model rejects: exit 2) and osim::IdEngineError (a frame the
/// core cannot solve: exit 1).
MassSweepResult runMassSweep(const osim::InverseDynamicsTool& tool, const osim::Storage& zero_mass,
                             const MassSweepOptions& options, const MassSweepEngineFactory& factory = {});

/// Everything into the report: per value mass_sweep_tau_<v>.csv (time and every column),
/// mass_sweep_simbody.csv (per value: core vs Simbody and the effects' agreement; a check in the
/// verdict unless not counted), the comparisons of the value 0 with the references (checks),
/// mass_sweep_peaks.csv, mass_sweep_fit.csv, figures mass_sweep_torques (the main columns, one
/// line per value) and mass_sweep_peak_change (change of peak and largest change against the
/// swept mass, Figs. 6.16-6.17), summary.json "mass_sweep", a report.md section, and the zero
/// check (summary.checks; it fails the run when violated).
void addMassSweepToReport(const MassSweepResult& r, const osim::Storage& zero_mass, Report& report);

/// Why core vs Simbody with muscle mass does not count in the verdict, "" when it does. It counts
/// unless wrapping muscles carry mass over the exact wrap model: both engines then take its J by
/// finite differences, in different variables (the core in q over OpenSim's whole path, Simbody in
/// the path points and surface frames), and agree only to the differences' truncation error
/// (2.7e-8 of the peak on the running leg), not to round-off.
std::string simbodyMassCheckNotCountedReason(const osim::MuscleMassOptions& options, const osim::WrapMassCount& wrap);

/// Record an engine cross-check with muscle mass (core_mass_vs_simbody_mass): <name>_metrics.csv
/// (per column, PASS/DIFFERS against its tolerance), an overlay <name>_overlay, summary.json
/// "simbody_mass_check", a report.md section, and, when `not_counted` is empty, a check in the
/// verdict (summary.checks: a disagreement fails the run); otherwise the reason is recorded.
void addSimbodyMassCheck(const Comparison& c, const osim::Storage& core_mass, const osim::Storage& simbody_mass,
                         Report& report, const std::string& not_counted = "");

/// One line: "<name>: worst COL max/peak X -> agrees | DIFFERS" and "(not counted: ...)" when not counted.
std::string formatSimbodyMassCheck(const Comparison& c, const std::string& not_counted = "");

/// The wrapping muscles at the sweep's largest value in one line per reason: "wrapping (Type III):
/// W of N carry mass" then "  lumped K: REASON (names...)" (names up to 6 per reason). Empty when
/// the model has no wrapping muscle.
std::string formatWrapMassCount(const osim::WrapMassCount& c);

/// The lines `redmax validate` prints: per value the muscle mass; per main column the peak change
/// at the largest value and R^2; the zero check.
std::string formatMassSweepSummary(const MassSweepResult& r);

}  // namespace redmax::validation
