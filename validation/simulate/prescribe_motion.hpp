#pragma once
// Hybrid dynamics from a motion file (`redmax simulate --prescribe MOTION`, docs/deformable.md §6
// "Hybrid dynamics in the CLI"; [D Sec. 4.6.5, Eq. 4.109-4.110]): chosen coordinates follow the
// file, the others move forward under the forces, and the generalized force each prescription takes
// (the multiplier of its PrescribedCoordinate row) is recorded at every output row. With every
// coordinate prescribed those forces are the inverse dynamics of the motion.
//
// The file's columns become q(t) exactly as OpenSim's InverseDynamicsTool makes them (the same
// pipeline, converter/signal/coordinate_pipeline.hpp): optional padding and low-pass filtering, then
// one natural quintic spline per column (GCVSpline(5), error variance 0); q_p, qdot_p and qddot_p
// are the spline and its first two derivatives, so a run with every coordinate prescribed reproduces
// `redmax id` on the same file.
#include <memory>
#include <string>
#include <vector>

#include "converter/storage.hpp"
#include "validation/simulate/simulate.hpp"

namespace redmax::validation {

struct MotionPrescriptionOptions {
  /// coordinates to prescribe (names); empty: every coordinate of the model the file has a column
  /// for (matched by name or by /jointset/J/C/value, degrees converted as every reader does)
  std::vector<std::string> coordinates;
  /// low-pass cutoff (Hz) applied to the columns before the splines, as the ID tool's
  /// lowpass_cutoff_frequency_for_coordinates; < 0: none
  double lowpass_cutoff_hz = -1.0;
};

struct MotionPrescription {
  std::vector<std::string> coordinates;  ///< prescribed, in q order
  std::vector<int> q_index;              ///< their core indices
  std::vector<std::string> labels;       ///< output columns: <coord>_moment or <coord>_force
  double t_first = 0.0, t_last = 0.0;    ///< the motion's time range (the splines' data)
  std::vector<std::string> warnings;     ///< what the pipeline logs (e.g. no filtering done)
  /// q_p, qdot_p at t for every prescribed coordinate (q order)
  void values(double t, VecX& q, VecX& qdot) const;

  struct Splines;
  std::shared_ptr<const Splines> splines;
};

/// Add one PrescribedCoordinate per chosen coordinate to m.system. Throws osim::ConvertError naming
/// `file` (and the line of its column labels) for a coordinate that is not in the model or has no
/// column, a coordinate the model already locks, prescribes or couples (a dependent coordinate),
/// no coordinate to prescribe, or data the splines cannot take (too few rows, non-finite values).
MotionPrescription prescribeMotion(SimulationModel& m, const osim::Storage& motion, const std::string& file,
                                   const MotionPrescriptionOptions& options);

/// `s` (at s.t) with every prescribed coordinate's q and qdot from the motion, then projected onto
/// all constraints of m (positions, then velocities)
void applyPrescription(const SimulationModel& m, const MotionPrescription& p, State& s);

struct MarkerPrescription;  // validation/simulate/prescribe_markers.hpp

/// Records the forces of the prescriptions at each output row of a run: install it as
/// SimulateOptions::check (it chains to a check already there). `table()` then holds time and
/// - for a MotionPrescription: one column per prescribed coordinate (N m or N), named as `redmax id`
///   names its columns;
/// - for a MarkerPrescription: each marker's world force at the marker (<marker>_fx/_fy/_fz, N),
///   then the generalized force the markers take together, J^T lambda, on every coordinate
///   (<coord>_moment / <coord>_force, as above).
class PrescribedForceRecorder {
 public:
  PrescribedForceRecorder(const SimulationModel& m, const MotionPrescription& p);
  PrescribedForceRecorder(const SimulationModel& m, const MarkerPrescription& p);
  /// wraps `previous` (may be empty) into a check that records and then calls it
  std::function<std::string(const State&, double, double)> check(
      std::function<std::string(const State&, double, double)> previous = {});
  const osim::Storage& table() const { return table_; }
  /// markers only: per marker, the largest |force| (N) and the largest distance between the marker
  /// and its trajectory (m) over the recorded rows
  const std::vector<double>& markerPeakForce() const { return peak_force_; }
  const std::vector<double>& markerPeakDistance() const { return peak_distance_; }

 private:
  void record(const State& s);
  const SimulationModel& m_;
  std::vector<int> q_index_;      // motion: the prescribed coordinates, one column each
  std::vector<int> marker_row_;   // markers: the first constraint row of each
  std::vector<double> peak_force_, peak_distance_;
  std::shared_ptr<DynamicsWorkspace> ws_;
  osim::Storage table_;
};

}  // namespace redmax::validation
