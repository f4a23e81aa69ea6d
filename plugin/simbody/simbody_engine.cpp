#include "plugin/simbody/simbody_engine.hpp"

#include <stdexcept>

#include <Eigen/Dense>

#include "plugin/simbody/model_to_simbody.hpp"

namespace redmax::simbody {

struct SimbodyEngine::Impl {
  Model model;
  std::unique_ptr<SimbodyModel> sm;
  SimTK::State sb;
  // integrator and whether it must restart from sb (after setState)
  std::unique_ptr<SimTK::Integrator> integ;
  double dt = 0.0;
  bool integ_stale = true;
  bool integ_initialized = false;  // Simbody asserts on step counts before initialize()
  // scratch for calcResidualForces
  mutable SimTK::Vector udot_sb, f_sb;

  const SimTK::State& current() const { return integ && !integ_stale ? integ->getState() : sb; }
};

SimbodyEngine::SimbodyEngine(const Model& model, const SimbodyBuildOptions& opt)
    : impl_(std::make_unique<Impl>()) {
  impl_->model = model;
  impl_->sm = makeSimbodyModel(impl_->model, opt);
  impl_->sb = impl_->sm->default_state;
}

SimbodyEngine::~SimbodyEngine() = default;

const Model& SimbodyEngine::model() const { return impl_->model; }
int SimbodyEngine::nu() const { return impl_->sm->nu; }

void SimbodyEngine::setState(const State& s) {
  setSimbodyState(*impl_->sm, impl_->model, s, impl_->sb);
  impl_->integ_stale = true;
}

State SimbodyEngine::coreState() const {
  State s;
  getCoreState(*impl_->sm, impl_->model, impl_->current(), s);
  return s;
}

void SimbodyEngine::mapVelocities(const VecX& qdot, const VecX& qddot, VecX& u, VecX& udot) const {
  State s = coreState();
  s.qdot = qdot;
  MatX T, Tdot;
  calcVelocityMap(*impl_->sm, impl_->model, s, T, &Tdot);
  u = T * qdot;
  udot = T * qddot + Tdot * qdot;
}

void SimbodyEngine::invalidatePositions() {
  // updQ() hands out writable q, which invalidates Stage::Position and everything above it
  (void)impl_->sm->matter.updQ(impl_->sb);
}

void SimbodyEngine::realizePosition() { impl_->sm->system.realize(impl_->sb, SimTK::Stage::Position); }
void SimbodyEngine::realizeVelocity() { impl_->sm->system.realize(impl_->sb, SimTK::Stage::Velocity); }
void SimbodyEngine::realizeDynamics() { impl_->sm->system.realize(impl_->sb, SimTK::Stage::Dynamics); }
void SimbodyEngine::realizeAcceleration() {
  impl_->sm->system.realize(impl_->sb, SimTK::Stage::Acceleration);
}

void SimbodyEngine::calcMassMatrix(MatX& M_u) const {
  SimTK::Matrix M;
  impl_->sm->matter.calcM(impl_->sb, M);
  M_u = fromSimTK(M);
}

void SimbodyEngine::calcResidualForces(const VecX& udot, VecX& f_u) const {
  const SimbodyModel& sm = *impl_->sm;
  SimTK::Vector& ud = impl_->udot_sb;
  ud.resize(static_cast<int>(udot.size()));
  for (int k = 0; k < udot.size(); ++k) ud[k] = udot[k];
  sm.matter.calcResidualForceIgnoringConstraints(
      impl_->sb, sm.system.getMobilityForces(impl_->sb, SimTK::Stage::Dynamics),
      sm.system.getRigidBodyForces(impl_->sb, SimTK::Stage::Dynamics), ud, impl_->f_sb);
  f_u.resize(impl_->f_sb.size());
  for (int k = 0; k < f_u.size(); ++k) f_u[k] = impl_->f_sb[k];
}

VecX SimbodyEngine::udot() const { return fromSimTK(impl_->sm->matter.getUDot(impl_->sb)); }

MatX SimbodyEngine::massMatrixCore(const State& s) {
  return calcSimbodyMassCore(*impl_->sm, impl_->model, s);
}
VecX SimbodyEngine::inverseDynamicsCore(const State& s, const VecX& qddot) {
  return calcSimbodyInverseDynamicsCore(*impl_->sm, impl_->model, s, qddot);
}
VecX SimbodyEngine::forwardDynamicsCore(const State& s) {
  return calcSimbodyForwardDynamicsCore(*impl_->sm, impl_->model, s);
}

std::vector<std::string> SimbodyEngine::integratorNames() {
  return {"semi-explicit-euler", "semi-explicit-euler2", "rk-merson", "cpodes"};
}

void SimbodyEngine::initIntegrator(const std::string& name, double dt, double accuracy) {
  if (!(dt > 0.0)) throw std::invalid_argument("Simbody integrator: dt must be positive");
  const SimTK::MultibodySystem& sys = impl_->sm->system;
  std::unique_ptr<SimTK::Integrator> integ;
  if (name == "semi-explicit-euler") {
    integ = std::make_unique<SimTK::SemiExplicitEulerIntegrator>(sys, dt);
  } else if (name == "semi-explicit-euler2") {
    integ = std::make_unique<SimTK::SemiExplicitEuler2Integrator>(sys);
    integ->setFixedStepSize(dt);
  } else if (name == "rk-merson") {
    integ = std::make_unique<SimTK::RungeKuttaMersonIntegrator>(sys);
    integ->setAccuracy(accuracy);
  } else if (name == "cpodes") {
    integ = std::make_unique<SimTK::CPodesIntegrator>(sys, SimTK::CPodes::BDF, SimTK::CPodes::Newton);
    integ->setAccuracy(accuracy);
  } else {
    throw std::invalid_argument("unknown Simbody integrator '" + name +
                                "' (expected semi-explicit-euler, semi-explicit-euler2, rk-merson or cpodes)");
  }
  impl_->integ = std::move(integ);
  impl_->dt = dt;
  impl_->integ_stale = true;
  impl_->integ_initialized = false;
}

void SimbodyEngine::stepIntegrator() {
  Impl& I = *impl_;
  if (!I.integ) throw std::logic_error("SimbodyEngine::stepIntegrator: no integrator (call initIntegrator)");
  if (I.integ_stale) {
    I.integ->initialize(I.sb);
    I.integ_stale = false;
    I.integ_initialized = true;
  }
  I.integ->stepTo(I.integ->getTime() + I.dt);
}

long SimbodyEngine::integratorSteps() const {
  return impl_->integ && impl_->integ_initialized ? impl_->integ->getNumStepsTaken() : 0;
}

}  // namespace redmax::simbody
