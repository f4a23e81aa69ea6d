#pragma once
// Side-by-side timing of the core and Simbody on the same tree (validation/bench/dynamics_bench.cpp
// and `redmax bench`). Each SpeedOp pairs a core operation with Simbody's equivalent; both act on
// the same state, and both start from scratch where the operation implies it (e.g. inverse
// dynamics recomputes kinematics on both sides). Timing here is for reports only: no test asserts
// on it.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/skeleton/model.hpp"
#include "plugin/simbody/simbody_options.hpp"

namespace redmax::simbody {

struct SpeedOptions {
  /// how SphericalEuler joints are mapped (Gimbal: u = qdot like the core; Ball: u = w_FM)
  SphericalAs spherical = SphericalAs::Gimbal;
  double dt = 1e-3;     // one integrator step (fixed-step methods) / reporting interval (adaptive)
  double rtol = 1e-6;   // adaptive methods: core rtol and Simbody accuracy
  double atol = 1e-8;   // core adaptive methods
  /// core integrators to time, each next to its closest Simbody integrator; names that
  /// makeIntegrator rejects are skipped and listed in SpeedComparison::skipped()
  std::vector<std::string> integrators = {"euler", "bdf1", "sdirk2", "rk45", "cvode"};
  /// integrator steps after which both sides restart from the initial state, so that long timing
  /// runs keep integrating the same stretch of motion on both sides
  int reset_every = 500;
  std::uint32_t seed = 1;  // initial state: defaults + seeded perturbation
};

/// one operation, timed on both sides
struct SpeedOp {
  std::string name;          // e.g. "mass_matrix", "step_rk45"
  std::string redmax_what;   // what the core side calls
  std::string simbody_what;  // what the Simbody side calls
  std::function<void()> redmax;
  std::function<void()> simbody;
  /// optional remark after timing (integrators: internal steps per call on each side)
  std::function<std::string()> remark;
};

/// The operations of one scene: kinematics (calcKinematics vs realize(Velocity)), mass_matrix
/// (calcSkeletonMass vs calcM, kinematics already done), id_redmax (System::inverseDynamics vs
/// realize(Dynamics) + calcResidualForceIgnoringConstraints), id_recursive
/// (inverseDynamicsRecursive vs the same Simbody call), forward_dynamics (System::forwardDynamics
/// on its Auto route, ABA on a bare tree, vs realize(Acceleration)), and step_<integrator> for each
/// available core integrator:
///   euler -> SemiExplicitEuler, bdf1 -> SemiExplicitEuler, sdirk2 -> SemiExplicitEuler2 (fixed
///   step dt), rk45 -> RungeKuttaMerson, cvode -> CPodes BDF (accuracy = rtol).
class SpeedComparison {
 public:
  /// throws SimbodyBuildError if the model has joints without a Simbody counterpart
  SpeedComparison(std::string scene, const Model& model, const SpeedOptions& opt = {});
  ~SpeedComparison();
  SpeedComparison(const SpeedComparison&) = delete;
  SpeedComparison& operator=(const SpeedComparison&) = delete;

  const std::string& scene() const;
  int dof() const;
  std::vector<SpeedOp>& ops();
  /// "name: reason" for every requested integrator that was not timed
  const std::vector<std::string>& skipped() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// one line of the comparison table (microseconds per call)
struct SpeedRow {
  std::string scene;
  int dof = 0;
  std::string op;
  std::string redmax_what, simbody_what;
  double redmax_us = 0.0;   // NaN when that side failed (see note)
  double simbody_us = 0.0;
  std::string note;         // why a side failed (e.g. an integrator's SimulationError); else empty
  /// redmax / Simbody; NaN when either side failed
  double ratio() const;
};

/// Times every op with a plain loop: a warm-up call, then `batches` batches of `repeats` calls per
/// side, alternating sides; reports the fastest batch mean of each side, in thread CPU time
/// (robust to other jobs on the machine; every op is single-threaded).
/// A side that throws (an integrator failing on the scene) gets NaN and the message in `note`.
/// Throws std::invalid_argument unless repeats >= 1 and batches >= 1.
std::vector<SpeedRow> timeSpeedComparison(SpeedComparison& cmp, int repeats, int batches = 5);

/// the table: scene, DoF, operation, redmax us, Simbody us, ratio (redmax / Simbody)
std::string formatSpeedTable(const std::vector<SpeedRow>& rows);

/// {"unit": "us", "threads": 1, "rows": [{"scene", "dof", "operation", "redmax_us", "simbody_us",
/// "ratio", "redmax", "simbody", "note"}]} (failed times and ratios are null), written to a temporary file beside `path`, then renamed.
/// Throws std::runtime_error naming the path if it cannot be written.
void writeSpeedJson(const std::vector<SpeedRow>& rows, const std::string& path);

}  // namespace redmax::simbody
