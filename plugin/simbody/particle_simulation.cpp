#include "plugin/simbody/particle_simulation.hpp"

#include <sstream>
#include <stdexcept>

#include "plugin/simbody/contact_forces.hpp"
#include "plugin/simbody/model_to_simbody.hpp"
#include "plugin/simbody/particle_muscles.hpp"

namespace redmax::simbody {

struct ParticleSimulation::Impl {
  Model model;
  std::unique_ptr<SimbodyModel> sm;
  std::unique_ptr<ParticleMuscles> particles;
  SimbodyContacts contacts;  // (before the integrator: Simbody's contact forces refer to it)
  std::unique_ptr<SimTK::Integrator> integ;
  std::unique_ptr<SimTK::TimeStepper> stepper;
  State state;
};

ParticleSimulation::ParticleSimulation(const MusculoskeletalModel& mm, const State& initial,
                                       const ParticleSimulationOptions& options)
    : impl_(std::make_unique<Impl>()) {
  const Model& model = mm.skeleton();
  Impl& m = *impl_;
  if (!(options.accuracy > 0.0) || !(options.constraint_tolerance > 0.0))
    throw std::invalid_argument("particle simulation: accuracy and constraint tolerance must be positive");
  if (options.integrator != "merson" && options.integrator != "feldberg" && options.integrator != "rk3" &&
      options.integrator != "verlet" && options.integrator != "cpodes")
    throw std::invalid_argument("particle simulation: unknown integrator '" + options.integrator +
                                "' (merson, feldberg, rk3, verlet or cpodes)");
  if (!(options.max_step >= 0.0)) throw std::invalid_argument("particle simulation: negative maximum step");
  m.model = model;
  m.sm = makeSimbodyModel(model);
  m.particles = std::make_unique<ParticleMuscles>(*m.sm, model, mm.muscles());
  m.contacts = addSimbodyContacts(*m.sm, model, ContactForces{options.hunt_crossley, options.smooth_contacts});
  SimTK::State st = m.sm->default_state;
  setSimbodyState(*m.sm, model, initial, st);
  m.particles->placeParticles(st);
  if (options.integrator == "merson")
    m.integ = std::make_unique<SimTK::RungeKuttaMersonIntegrator>(m.sm->system);
  else if (options.integrator == "feldberg")
    m.integ = std::make_unique<SimTK::RungeKuttaFeldbergIntegrator>(m.sm->system);
  else if (options.integrator == "rk3")
    m.integ = std::make_unique<SimTK::RungeKutta3Integrator>(m.sm->system);
  else if (options.integrator == "verlet")
    m.integ = std::make_unique<SimTK::VerletIntegrator>(m.sm->system);
  else
    m.integ = std::make_unique<SimTK::CPodesIntegrator>(m.sm->system, SimTK::CPodes::BDF, SimTK::CPodes::Newton);
  m.integ->setAccuracy(options.accuracy);
  if (options.max_step > 0.0) m.integ->setMaximumStepSize(options.max_step);
  m.integ->setConstraintTolerance(options.constraint_tolerance);
  m.integ->setUseInfinityNorm(options.infinity_norm);
  m.stepper = std::make_unique<SimTK::TimeStepper>(m.sm->system, *m.integ);
  m.stepper->initialize(st);
  m.state = m.particles->coreState(model, m.stepper->getState());
}

ParticleSimulation::~ParticleSimulation() = default;

const State& ParticleSimulation::advance(double t_out) {
  Impl& m = *impl_;
  if (t_out < m.state.t) throw std::invalid_argument("particle simulation: cannot go back in time");
  if (t_out == m.state.t) return m.state;
  try {
    m.stepper->stepTo(t_out);
  } catch (const std::exception& e) {
    std::ostringstream os;
    os << "Simbody particle simulation failed before t = " << t_out << " (reached t = "
       << m.stepper->getState().getTime() << "): " << e.what();
    throw std::runtime_error(os.str());
  }
  m.state = m.particles->coreState(m.model, m.stepper->getState());
  if (!m.state.q.allFinite() || !m.state.qdot.allFinite()) {
    std::ostringstream os;
    os << "Simbody particle simulation: non-finite state at t = " << m.state.t;
    throw std::runtime_error(os.str());
  }
  return m.state;
}

const State& ParticleSimulation::state() const { return impl_->state; }

double ParticleSimulation::kineticEnergy() const {
  const SimTK::State& s = impl_->stepper->getState();
  impl_->sm->system.realize(s, SimTK::Stage::Velocity);
  return impl_->sm->system.calcKineticEnergy(s);
}

double ParticleSimulation::potentialEnergy() const {
  const SimTK::State& s = impl_->stepper->getState();
  impl_->sm->system.realize(s, SimTK::Stage::Dynamics);
  return impl_->sm->system.calcPotentialEnergy(s);
}

long ParticleSimulation::steps() const { return impl_->integ->getNumStepsTaken(); }

ParticleSimulationCounts ParticleSimulation::counts() const {
  const SimTK::Integrator& in = *impl_->integ;
  ParticleSimulationCounts c;
  c.steps = in.getNumStepsTaken();
  c.realizations = in.getNumRealizations();
  c.failed_steps = in.getNumErrorTestFailures() + in.getNumConvergenceTestFailures();
  c.projections = in.getNumProjections();
  return c;
}

}  // namespace redmax::simbody
