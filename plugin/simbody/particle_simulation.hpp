#pragma once
// Forward simulation of a core model with inertial muscles in Simbody: the skeleton from
// makeSimbodyModel, the mass points as particles held on their paths (particle_muscles.hpp), an
// error-controlled Simbody integrator. Meant for `redmax simulate --engine simbody`-style drivers and
// for cross-checking the core's trajectories. Core constraints (locked or coupled coordinates,
// welds) are not carried over: the skeleton is the model's tree.
#include <memory>
#include <string>
#include <vector>

#include "core/dynamics/contact_force_terms.hpp"
#include "core/model/musculoskeletal_model.hpp"
#include "core/skeleton/model.hpp"
#include "core/skeleton/state.hpp"

namespace redmax::simbody {

struct ParticleSimulationOptions {
  /// "merson" (RungeKuttaMerson 4(5)), "feldberg" (RungeKuttaFeldberg 4(5)), "rk3"
  /// (RungeKutta3 3(2)), "verlet" (Verlet 2(3)) or "cpodes" (CPodesIntegrator: BDF with Newton
  /// iterations, Simbody's bundled CVODE descendant)
  std::string integrator = "merson";
  double accuracy = 1e-8;             ///< Simbody's relative accuracy
  double constraint_tolerance = 1e-10;  ///< path constraints (m, m/s)
  double max_step = 0.0;              ///< s; > 0 caps the step size (Integrator::setMaximumStepSize)
  /// Simbody's step error norm: false = its default RMS over all q (and over all u), the
  /// particles' included, so one skeleton coordinate's error is averaged with theirs; true = the
  /// largest weighted component (Integrator::setUseInfinityNorm)
  /// The finger (FDP, FDS 0.2 kg over 5 points each, 1 s) reaches 1e-6 rad against the core with
  /// the least CPU as feldberg, infinity_norm, accuracy 3e-12, constraint_tolerance 3e-13.
  bool infinity_norm = false;
  /// compliant contact as Simbody's own force elements (plugin/simbody/contact_forces.hpp)
  std::vector<HuntCrossleyForceTerm::Force> hunt_crossley;
  std::vector<SmoothSphereHalfSpaceForceTerm::Contact> smooth_contacts;
};

/// Simbody's integrator counters (Integrator::getNum*), summed over the run.
struct ParticleSimulationCounts {
  long steps = 0;            ///< accepted steps
  long realizations = 0;     ///< realizations to Stage::Acceleration (one per right-hand side)
  long failed_steps = 0;     ///< error-test and convergence failures
  long projections = 0;      ///< constraint projections
};

/// One run from an initial core state. The header is Simbody-free (pimpl).
class ParticleSimulation {
 public:
  /// Throws SimbodyBuildError (simbody_options.hpp) for a joint or a muscle Simbody cannot take
  /// (see particle_muscles.hpp), ModelError for an invalid muscle, std::invalid_argument for an
  /// unknown integrator name or non-positive tolerances.
  ParticleSimulation(const MusculoskeletalModel& model, const State& initial,
                     const ParticleSimulationOptions& options = {});
  ~ParticleSimulation();
  ParticleSimulation(const ParticleSimulation&) = delete;
  ParticleSimulation& operator=(const ParticleSimulation&) = delete;

  /// Advance to t_out (>= the current time) and return the skeleton's core state there. Throws
  /// std::runtime_error naming the time if Simbody fails or the state is not finite.
  const State& advance(double t_out);
  const State& state() const;
  /// Simbody's kinetic and potential energy of skeleton and particles (gravity, world origin)
  double kineticEnergy() const;
  double potentialEnergy() const;
  /// accepted integrator steps so far
  long steps() const;
  /// all of Simbody's counters so far
  ParticleSimulationCounts counts() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace redmax::simbody
