#pragma once
// Prescribed markers from a TRC file (`redmax simulate --prescribe-markers TRIAL.trc`,
// docs/deformable.md §6; [D Sec. 4.6.5, Eq. 4.109-4.110], maximal-coordinate inverse dynamics):
// each chosen marker of the model's MarkerSet becomes a PrescribedPoint
// (core/dynamics/constraints/prescribed_point.hpp) whose trajectory x_p(t) is the file's samples
// through one natural quintic spline per component (GCVSpline(5), error variance 0, as
// `--prescribe` splines its coordinates; optional low-pass first), so x_p, xdot_p and xddot_p are
// the spline and its first two derivatives. The other coordinates move forward under the forces;
// the multipliers are the world force each marker takes (N, at the marker).
//
// Gaps. A marker's spline runs through the file's rows around the run's window up to the nearest
// gap on each side; a gap inside the window (or in a row bracketing its ends) is refused: the
// splines never bridge missing samples.
//
// Over-constraint. Each marker adds three rows. Rows the coordinates cannot move independently
// (three rows on a one-coordinate pendulum) are dependent: the System's KKT solve
// (System::solveKKT) meets them with the minimum-norm multiplier, i.e. only the force components
// the coordinates feel, and a trajectory the model cannot follow in the least-squares sense.
// MarkerStart reports the rows and how many are independent at the start.
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "converter/trc_file.hpp"
#include "core/dynamics/constraints/prescribed_point.hpp"
#include "validation/simulate/simulate.hpp"

namespace redmax::validation {

struct MarkerPrescriptionOptions {
  /// markers to prescribe (names in the model's MarkerSet); empty: every marker of the model the
  /// file has a column for
  std::vector<std::string> markers;
  /// low-pass cutoff (Hz) applied to each marker's samples before its splines (the ID tool's
  /// coordinate filter, converter/signal/coordinate_pipeline.hpp); < 0: none
  double lowpass_cutoff_hz = -1.0;
  /// the run's window [t_begin, t_end] (s); NaN: the file's first / last time
  double t_begin = std::numeric_limits<double>::quiet_NaN();
  double t_end = std::numeric_limits<double>::quiet_NaN();
};

struct MarkerPrescription {
  std::vector<std::string> markers;  ///< prescribed, in the order given (or the MarkerSet's)
  std::vector<int> body;             ///< core body of each marker
  std::vector<Vec3> point;           ///< the marker in its core body's frame (m)
  std::vector<std::shared_ptr<const PrescribedPoint>> constraints;  ///< one per marker, in m.system
  std::vector<std::string> labels;   ///< output columns: <marker>_fx/_fy/_fz, then <coord>_moment|_force
  double t_first = 0.0, t_last = 0.0;  ///< the file's time range
  int rows = 0;                      ///< constraint rows the markers add (3 each)
  int free_coordinates = 0;          ///< coordinates less the rows of the model's other constraints
  std::vector<std::string> warnings;  ///< what the pipeline logs, the reader's warnings
  /// the marker's trajectory (spline) at t
  PointSample target(int k, double t) const { return constraints[k]->target(t); }
};

/// Add one PrescribedPoint per chosen marker to m.system. Throws osim::ConvertError naming `file`
/// (and the line where it helps) for a marker not in the model's MarkerSet or not in the file, a
/// marker named twice, one fixed to ground, no marker to prescribe, a window outside the file's
/// times (the splines would extrapolate), a gap in the window, or samples the splines cannot take.
MarkerPrescription prescribeMarkers(SimulationModel& m, const osim::MarkerTable& trc, const std::string& file,
                                    const MarkerPrescriptionOptions& options);

/// What the start of a marker-prescribed run looks like.
struct MarkerStart {
  std::vector<double> distance;  ///< each marker's distance to its trajectory after the solve (m)
  int independent_rows = 0;      ///< marker rows independent of each other and of the other constraints
};

/// Put the markers on their trajectories at s.t: s's coordinates are the first guess, then
/// Gauss-Newton steps of least kinetic metric on all constraints (System::projectPositions) and the
/// velocity projection. Throws osim::ConvertError naming `file` and the marker when a marker stays
/// farther than `tolerance_m` from its trajectory (it cannot be reached from that pose), with the
/// distance.
MarkerStart applyMarkerPrescription(const SimulationModel& m, const MarkerPrescription& p, const std::string& file,
                                    State& s, double tolerance_m = 1e-6);

}  // namespace redmax::validation
