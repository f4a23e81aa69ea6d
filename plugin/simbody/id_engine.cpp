#include "plugin/simbody/id_engine.hpp"

#include <variant>

#include "plugin/simbody/model_to_simbody.hpp"
#include "plugin/simbody/muscle_inertia.hpp"

namespace redmax::simbody {

namespace {

// the joint a marked slot stands for (Reversed is not mapped to Simbody)
bool isSpherical(const Joint& j) { return std::holds_alternative<SphericalEuler>(j.v); }

Mat4 toMat4(const SimTK::Transform& X) {
  Mat4 E = Mat4::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) E(r, c) = X.R().asMat33()(r, c);
    E(r, 3) = X.p()[r];
  }
  return E;
}

}  // namespace

struct SimbodyIdEngine::Impl {
  Model model;
  IdEngineOptions options;
  std::unique_ptr<SimbodyModel> sm;
  SimTK::State state;
  std::vector<Mat4> E_wi;
  std::vector<PointForce> point_forces;
  std::vector<BodyWrench> wrenches;
  MatX T, Tdot;
  std::unique_ptr<MuscleInertia> muscles;  // null without muscle mass
  SimTK::Vector f_muscles;
};

SimbodyIdEngine::SimbodyIdEngine(const Model& model, const IdEngineOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.model = model;
  m.options = options;
  if (!options.rates_as_u.empty() && static_cast<int>(options.rates_as_u.size()) != model.nb())
    throw SimbodyBuildError("engine options name " + std::to_string(options.rates_as_u.size()) +
                            " joints; the model has " + std::to_string(model.nb()));
  // a marked spherical joint must be Simbody's Ball, whose u is w_FM in F: then every spherical
  // joint is a Ball, and unmarked ones go through the velocity map (exact either way)
  SimbodyBuildOptions opt;
  opt.spherical = SphericalAs::Gimbal;
  for (int j = 0; j < model.nb(); ++j)
    if (options.marked(j) && isSpherical(model.joints()[j].joint)) opt.spherical = SphericalAs::Ball;
  m.sm = makeSimbodyModel(model, opt);
  for (int j = 0; j < model.nb(); ++j) {
    if (!options.marked(j)) continue;
    // Ball, Free (and any mobilizer whose u is not qdot, e.g. Ellipsoid): u = w_FM in F
    if (m.sm->map[j].u_is_qdot)
      throw SimbodyBuildError("joint '" + model.joints()[j].name +
                              "': OpenSim's Euler-rate speeds need a Simbody mobilizer whose u is the "
                              "angular velocity (Ball, Free), not its q rates");
  }
  m.state = m.sm->default_state;
  m.E_wi.resize(model.nb());
}

SimbodyIdEngine::SimbodyIdEngine(const MusculoskeletalModel& model, const IdEngineOptions& options)
    : SimbodyIdEngine(model.skeleton(), options) {
  bool any = false;
  for (const Muscle& mu : model.muscles()) any = any || mu.mass_points.size() > 0;
  if (any) impl_->muscles = std::make_unique<MuscleInertia>(*impl_->sm, model);
}

SimbodyIdEngine::~SimbodyIdEngine() = default;

void SimbodyIdEngine::calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                                            const std::vector<IdLoadSample>& loads, VecX& tau) {
  Impl& m = *impl_;
  const SimbodyModel& sm = *m.sm;
  const int nr = m.model.nr();
  if (q.size() != nr || v.size() != nr || vdot.size() != nr)
    throw IdEngineError("inverse dynamics needs " + std::to_string(nr) +
                              " coordinates, speeds and accelerations");

  // u and udot: the given rates as they are for marked joints (OpenSim), T qdot elsewhere
  State s;
  s.t = t;
  s.q = q;
  s.qdot = v;
  calcVelocityMap(sm, m.model, s, m.T, &m.Tdot);
  VecX u = m.T * v, udot = m.T * vdot + m.Tdot * v;
  for (int j = 0; j < m.model.nb(); ++j) {
    if (!m.options.marked(j)) continue;
    const MobilizerMap& mm = sm.map[j];
    u.segment(mm.simbody_u, mm.nq) = v.segment(mm.q_index, mm.nq);
    udot.segment(mm.simbody_u, mm.nq) = vdot.segment(mm.q_index, mm.nq);
  }
  SimTK::State& sb = m.state;
  sb.setTime(t);
  SimTK::Vector& q_sb = sm.matter.updQ(sb);
  for (const MobilizerMap& mm : sm.map)
    for (int k = 0; k < mm.nq; ++k) q_sb[mm.simbody_q + k] = q[mm.q_index + k];
  SimTK::Vector& u_sb = sm.matter.updU(sb);
  for (int k = 0; k < sm.nu; ++k) u_sb[k] = u[k];

  // applied forces: the force subsystem's (gravity, springs) plus the external loads at
  // Simbody's own poses
  sm.system.realize(sb, SimTK::Stage::Dynamics);
  SimTK::Vector_<SimTK::SpatialVec> body_forces = sm.system.getRigidBodyForces(sb, SimTK::Stage::Dynamics);
  const SimTK::Vector& mobility_forces = sm.system.getMobilityForces(sb, SimTK::Stage::Dynamics);
  for (int i = 0; i < m.model.nb(); ++i) m.E_wi[i] = toMat4(sm.mobods[i].getBodyTransform(sb));
  resolveLoads(loads, m.E_wi, m.point_forces, m.wrenches);
  for (const PointForce& f : m.point_forces)
    sm.matter.addInStationForce(sb, sm.mobods[f.body].getMobilizedBodyIndex(),
                                SimTK::Vec3(f.point_i.x(), f.point_i.y(), f.point_i.z()),
                                SimTK::Vec3(f.force_w.x(), f.force_w.y(), f.force_w.z()), body_forces);
  for (const BodyWrench& w : m.wrenches) {
    sm.matter.addInBodyTorque(sb, sm.mobods[w.body].getMobilizedBodyIndex(),
                              SimTK::Vec3(w.torque_w.x(), w.torque_w.y(), w.torque_w.z()), body_forces);
    if (!w.force_w.isZero(0.0))
      sm.matter.addInStationForce(sb, sm.mobods[w.body].getMobilizedBodyIndex(), SimTK::Vec3(0),
                                  SimTK::Vec3(w.force_w.x(), w.force_w.y(), w.force_w.z()), body_forces);
  }

  SimTK::Vector f_u;
  const SimTK::Vector udot_sb = toSimTK(udot);
  sm.matter.calcResidualForceIgnoringConstraints(sb, mobility_forces, body_forces, udot_sb, f_u);
  // muscle mass points: their share of the residual, in the same u space
  if (m.muscles) {
    try {
      m.muscles->calcGeneralizedForces(sb, udot_sb, m.f_muscles);
    } catch (const MuscleError& e) {
      // a degenerate path at this frame: the frame cannot be solved (IdEngine contract)
      throw IdEngineError("at t = " + std::to_string(t) + ": " + e.what());
    }
    f_u += m.f_muscles;
  }
  const VecX fu = fromSimTK(f_u);
  // back to the caller's convention: tau = T^T f_u (power balance), f_u itself for marked joints
  tau = m.T.transpose() * fu;
  for (int j = 0; j < m.model.nb(); ++j) {
    if (!m.options.marked(j)) continue;
    const MobilizerMap& mm = sm.map[j];
    tau.segment(mm.q_index, mm.nq) = fu.segment(mm.simbody_u, mm.nq);
  }
}

}  // namespace redmax::simbody
