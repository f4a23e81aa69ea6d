#include "plugin/simbody/model_to_simbody.hpp"

#include <cmath>
#include <type_traits>
#include <variant>

#include <Eigen/Dense>

#include "core/dynamics/speed_map.hpp"
#include "plugin/simbody/function_adapter.hpp"

namespace redmax::simbody {

namespace {

// a rotation whose column `col` is the unit vector a: the frame rotation that puts Simbody's fixed
// Pin (z) or Slider (x) axis on the core joint axis
Mat3 rotationWithColumn(const Vec3& a, int col) {
  const Vec3 n = a.normalized();
  // any unit vector orthogonal to n, made from the world axis least aligned with n
  int least = 0;
  n.cwiseAbs().minCoeff(&least);
  const Vec3 t = Vec3::Unit(least);
  const Vec3 b1 = (t - n * n.dot(t)).normalized();
  const Vec3 b2 = n.cross(b1);
  Mat3 R;
  // right-handed: columns (col, col+1, col+2) cyclic = (n, b1, b2)
  R.col(col) = n;
  R.col((col + 1) % 3) = b1;
  R.col((col + 2) % 3) = b2;
  return R;
}

SimTK::MassProperties massProperties(const Body& b) {
  // Simbody wants the inertia about the body origin: parallel-axis shift of I_c by m(|c|^2 1 - c c^T)
  const Vec3& c = b.com;
  const Mat3 I_o = b.inertia_com + b.mass * (c.squaredNorm() * Mat3::Identity() - c * c.transpose());
  const Mat3 Is = 0.5 * (I_o + I_o.transpose());
  const SimTK::SymMat33 sym(Is(0, 0), Is(1, 0), Is(1, 1), Is(2, 0), Is(2, 1), Is(2, 2));
  const SimTK::Vec3 com(c.x(), c.y(), c.z());
  try {
    return SimTK::MassProperties(b.mass, com, SimTK::Inertia(sym));
  } catch (const std::exception& e) {
    throw SimbodyBuildError("body '" + b.name + "': Simbody rejects its mass properties: " + e.what());
  }
}

// joint-type dispatch: which mobilizer, and the extra frame rotation for single-axis joints
struct MobilizerChoice {
  MobilizerKind kind = MobilizerKind::Weld;
  Mat3 R_frame = Mat3::Identity();  // F' = F R_frame, M' = M R_frame
  const FunctionBased* function_based = nullptr;  // kind == FunctionBased
  Vec3 radii = Vec3::Ones();                      // kind == Ellipsoid
  bool reversed = false;                          // Direction::Reverse
};

MobilizerChoice chooseMobilizer(const Joint& joint, const std::string& name, const SimbodyBuildOptions& opt) {
  return std::visit(
      [&](const auto& j) -> MobilizerChoice {
        using T = std::decay_t<decltype(j)>;
        MobilizerChoice c;
        if constexpr (std::is_same_v<T, Fixed>) {
          c.kind = MobilizerKind::Weld;
        } else if constexpr (std::is_same_v<T, Revolute>) {
          c.kind = MobilizerKind::Pin;
          c.R_frame = rotationWithColumn(j.axis, 2);
        } else if constexpr (std::is_same_v<T, Prismatic>) {
          c.kind = MobilizerKind::Slider;
          c.R_frame = rotationWithColumn(j.axis, 0);
        } else if constexpr (std::is_same_v<T, SphericalEuler>) {
          if (j.sequence != EulerSequence::XYZ)
            throw SimbodyBuildError("joint '" + name + "': Euler sequence " +
                                    eulerSequenceName(j.sequence) +
                                    " has no Simbody mobilizer (Gimbal and Ball use body-fixed XYZ)");
          c.kind = opt.spherical == SphericalAs::Ball ? MobilizerKind::Ball : MobilizerKind::Gimbal;
        } else if constexpr (std::is_same_v<T, Universal>) {
          c.kind = MobilizerKind::Universal;
        } else if constexpr (std::is_same_v<T, Free3D>) {
          const Free3D os = Free3D::opensim();
          if (j.rotation != os.rotation || j.sequence != os.sequence || j.order != os.order ||
              j.layout != os.layout)
            throw SimbodyBuildError("joint '" + name +
                                    "': only the OpenSim free-joint layout (Euler XYZ rotation first, "
                                    "X_FM = (R, p in F)) maps to Simbody's Free mobilizer");
          c.kind = MobilizerKind::Free;
        } else if constexpr (std::is_same_v<T, FunctionBased>) {
          // Simbody's FunctionBased has the approximate Hdot of OPENSIM_SEMANTICS 3.3; the core
          // joint matches it only with simbody_compat (exact mode differs for coupled rotations)
          c.kind = MobilizerKind::FunctionBased;
          c.function_based = &j;
        } else if constexpr (std::is_same_v<T, Ellipsoid>) {
          c.kind = MobilizerKind::Ellipsoid;
          c.radii = j.radii;
        } else if constexpr (std::is_same_v<T, Reversed>) {
          if (!j.inner) throw SimbodyBuildError("joint '" + name + "': reversed joint without an inner joint");
          c = chooseMobilizer(*j.inner, name, opt);
          if (c.reversed)
            throw SimbodyBuildError("joint '" + name + "': a reversed reversed joint has no Simbody mobilizer");
          // with Direction::Reverse Simbody's u is the forward mobilizer's u; the velocity map of
          // Ball/Free/Ellipsoid (u = angular velocity in F) would then refer to the other frame
          if (c.kind == MobilizerKind::Ball || c.kind == MobilizerKind::Free ||
              c.kind == MobilizerKind::Ellipsoid)
            throw SimbodyBuildError("joint '" + name + "': a reversed " + j.inner->typeName() +
                                    " joint maps to a reversed Simbody mobilizer whose u is not qdot; "
                                    "only joints with u = qdot (pin, slider, gimbal, universal, "
                                    "function-based, weld) are mapped reversed");
          c.reversed = true;
        } else {
          throw SimbodyBuildError("joint '" + name + "' of type " + joint.typeName() +
                                  " has no exact Simbody mobilizer counterpart");
        }
        return c;
      },
      joint.v);
}

// the FunctionBased mobilizer as OpenSim's CustomJoint builds it: six functions (rotations then
// translations) with their coordinate lists in mobility order, and the six (unit) axes
SimTK::MobilizedBody makeFunctionBased(SimTK::MobilizedBody& parent, const SimTK::Transform& X_PF,
                                       const SimTK::Body& body, const SimTK::Transform& X_BM,
                                       const FunctionBased& fb, SimTK::MobilizedBody::Direction dir) {
  std::vector<const SimTK::Function*> functions;
  std::vector<std::vector<int>> coords;
  std::vector<SimTK::Vec3> axes;
  for (const TransformAxis& ax : fb.axes()) {
    // Simbody takes ownership of the functions
    functions.push_back(new AxisFunctionAdapter(ax.function));
    coords.push_back(ax.coordinates);
    axes.emplace_back(ax.axis.x(), ax.axis.y(), ax.axis.z());
  }
  return SimTK::MobilizedBody::FunctionBased(parent, X_PF, body, X_BM, fb.nq(), functions, coords, axes, dir);
}

}  // namespace

SimTK::Vector toSimTK(const VecX& v) {
  SimTK::Vector out(static_cast<int>(v.size()));
  for (int k = 0; k < v.size(); ++k) out[k] = v[k];
  return out;
}

VecX fromSimTK(const SimTK::Vector& v) {
  VecX out(v.size());
  for (int k = 0; k < v.size(); ++k) out[k] = v[k];
  return out;
}

MatX fromSimTK(const SimTK::Matrix& m) {
  MatX out(m.nrow(), m.ncol());
  for (int r = 0; r < m.nrow(); ++r)
    for (int c = 0; c < m.ncol(); ++c) out(r, c) = m(r, c);
  return out;
}

std::unique_ptr<SimbodyModel> makeSimbodyModel(const Model& model, const SimbodyBuildOptions& opt) {
  auto sm = std::make_unique<SimbodyModel>();
  const int nb = model.nb();
  sm->mobods.reserve(nb);
  sm->map.resize(nb);

  for (int i = 0; i < nb; ++i) {
    const JointSlot& s = model.joints[i];
    const MobilizerChoice c = chooseMobilizer(s.joint, s.name, opt);
    SimTK::MobilizedBody& parent = s.parent < 0 ? sm->matter.updGround() : sm->mobods[s.parent];
    const Mat4 E_rot = makeE(c.R_frame, Vec3::Zero());
    const SimTK::Transform X_PF = toTransform(s.E_pf * E_rot);
    const SimTK::Transform X_BM = toTransform(inverseE(s.E_mi) * E_rot);
    const SimTK::Body::Rigid body(massProperties(model.bodies[i]));
    MobilizerMap& m = sm->map[i];
    m.kind = c.kind;
    m.q_index = s.q_index;
    m.nq = s.nq;
    m.reversed = c.reversed;
    const auto dir = c.reversed ? SimTK::MobilizedBody::Reverse : SimTK::MobilizedBody::Forward;
    try {
      switch (c.kind) {
        case MobilizerKind::Weld:
          // a weld has no direction
          sm->mobods.push_back(SimTK::MobilizedBody::Weld(parent, X_PF, body, X_BM));
          break;
        case MobilizerKind::Pin:
          sm->mobods.push_back(SimTK::MobilizedBody::Pin(parent, X_PF, body, X_BM, dir));
          break;
        case MobilizerKind::Slider:
          sm->mobods.push_back(SimTK::MobilizedBody::Slider(parent, X_PF, body, X_BM, dir));
          break;
        case MobilizerKind::Gimbal:
          sm->mobods.push_back(SimTK::MobilizedBody::Gimbal(parent, X_PF, body, X_BM, dir));
          break;
        case MobilizerKind::Ball:
          sm->mobods.push_back(SimTK::MobilizedBody::Ball(parent, X_PF, body, X_BM, dir));
          m.u_is_qdot = false;
          break;
        case MobilizerKind::Universal:
          sm->mobods.push_back(SimTK::MobilizedBody::Universal(parent, X_PF, body, X_BM, dir));
          break;
        case MobilizerKind::Free:
          sm->mobods.push_back(SimTK::MobilizedBody::Free(parent, X_PF, body, X_BM, dir));
          m.u_is_qdot = false;
          break;
        case MobilizerKind::FunctionBased:
          sm->mobods.push_back(makeFunctionBased(parent, X_PF, body, X_BM, *c.function_based, dir));
          break;
        case MobilizerKind::Ellipsoid: {
          // u = angular velocity of M in F, expressed in F (as Ball): calcVelocityMap
          const SimTK::Vec3 radii(c.radii.x(), c.radii.y(), c.radii.z());
          sm->mobods.push_back(SimTK::MobilizedBody::Ellipsoid(parent, X_PF, body, X_BM, radii, dir));
          m.u_is_qdot = false;
          break;
        }
      }
    } catch (const SimbodyBuildError&) {
      throw;
    } catch (const std::exception& e) {
      throw SimbodyBuildError("joint '" + s.name + "': Simbody rejects the mobilizer: " + e.what());
    }
  }

  if (opt.gravity) {
    const Vec3& g = model.gravity;
    SimTK::Force::UniformGravity(sm->forces, sm->matter, SimTK::Vec3(g.x(), g.y(), g.z()));
  }
  if (opt.joint_springs) {
    for (int i = 0; i < nb; ++i) {
      const MobilizerMap& m = sm->map[i];
      for (int k = 0; k < m.nq; ++k) {
        const Coordinate& cd = model.coordinates[m.q_index + k];
        if (cd.stiffness == 0.0 && cd.damping == 0.0) continue;
        // Free translations keep u = qdot; every Ball coordinate and Free rotation does not
        const bool exact = m.u_is_qdot || (m.kind == MobilizerKind::Free && k >= 3);
        if (!exact)
          throw SimbodyBuildError("coordinate '" + cd.name +
                                  "': a joint spring or damper on a Ball/Free rotation has no Simbody "
                                  "MobilityLinearSpring counterpart (q and u differ); map the joint "
                                  "to a Gimbal instead");
        if (cd.stiffness != 0.0)
          SimTK::Force::MobilityLinearSpring(sm->forces, sm->mobods[i], SimTK::MobilizerQIndex(k),
                                             cd.stiffness, cd.rest_value);
        if (cd.damping != 0.0)
          SimTK::Force::MobilityLinearDamper(sm->forces, sm->mobods[i], SimTK::MobilizerUIndex(k),
                                             cd.damping);
      }
    }
  }

  // topology, then Euler angles for Ball/Free so q matches the core coordinates
  try {
    sm->default_state = sm->system.realizeTopology();
    sm->matter.setUseEulerAngles(sm->default_state, true);
    sm->system.realizeModel(sm->default_state);
  } catch (const std::exception& e) {
    throw SimbodyBuildError(std::string("Simbody could not realize the model: ") + e.what());
  }
  SimTK::State& st = sm->default_state;
  sm->nq = st.getNQ();
  sm->nu = st.getNU();
  // Simbody keeps a slot for the quaternion's 4th q even with Euler angles, so nq may exceed nr;
  // each mobilizer's q count is checked below
  if (sm->nu != model.nr())
    throw SimbodyBuildError("Simbody system has nu = " + std::to_string(sm->nu) +
                            " but the core model has nr = " + std::to_string(model.nr()));
  for (int i = 0; i < nb; ++i) {
    MobilizerMap& m = sm->map[i];
    m.simbody_q = sm->mobods[i].getFirstQIndex(st);
    m.simbody_u = sm->mobods[i].getFirstUIndex(st);
    if (sm->mobods[i].getNumQ(st) != m.nq || sm->mobods[i].getNumU(st) != m.nq)
      throw SimbodyBuildError("joint '" + model.joints[i].name + "': Simbody mobilizer has " +
                              std::to_string(sm->mobods[i].getNumQ(st)) + " q, core joint has " +
                              std::to_string(m.nq));
  }
  // default configuration, zero velocity
  State s0;
  s0.q = model.defaultQ();
  s0.qdot = VecX::Zero(model.nr());
  setSimbodyState(*sm, model, s0, st);
  return sm;
}

void calcVelocityMap(const SimbodyModel& sm, const Model& model, const State& s, MatX& T, MatX* Tdot) {
  const int n = model.nr();
  T.setZero(n, n);
  if (Tdot) Tdot->setZero(n, n);
  MatJ Tj, Tdj;
  for (int i = 0; i < model.nb(); ++i) {
    const MobilizerMap& m = sm.map[i];
    if (m.nq == 0) continue;
    if (m.u_is_qdot) {
      T.block(m.simbody_u, m.q_index, m.nq, m.nq).setIdentity();
      continue;
    }
    // Ball/Free/Ellipsoid: u = (w_FM; v_FM) in F (Ellipsoid, Ball: w_FM only), the core's speed map
    const VecJ q = s.q.segment(m.q_index, m.nq);
    const VecJ qd = s.qdot.segment(m.q_index, m.nq);
    calcOpenSimSpeedMap(model.joints[i].joint, q, qd, Tj, Tdot ? &Tdj : nullptr);
    T.block(m.simbody_u, m.q_index, m.nq, m.nq) = Tj;
    if (Tdot) Tdot->block(m.simbody_u, m.q_index, m.nq, m.nq) = Tdj;
  }
}

void setSimbodyState(const SimbodyModel& sm, const Model& model, const State& s, SimTK::State& sb) {
  if (s.q.size() != model.nr() || s.qdot.size() != model.nr())
    throw std::invalid_argument("setSimbodyState: state has " + std::to_string(s.q.size()) + " q and " +
                                std::to_string(s.qdot.size()) + " qdot, model has nr = " +
                                std::to_string(model.nr()));
  MatX T;
  calcVelocityMap(sm, model, s, T);
  const VecX u = T * s.qdot;
  sb.setTime(s.t);
  SimTK::Vector& q_sb = sm.matter.updQ(sb);
  SimTK::Vector& u_sb = sm.matter.updU(sb);
  for (const MobilizerMap& m : sm.map)
    for (int k = 0; k < m.nq; ++k) q_sb[m.simbody_q + k] = s.q[m.q_index + k];
  for (int k = 0; k < sm.nu; ++k) u_sb[k] = u[k];
}

void getCoreState(const SimbodyModel& sm, const Model& model, const SimTK::State& sb, State& s) {
  const SimTK::Vector& q_sb = sm.matter.getQ(sb);
  const SimTK::Vector& u_sb = sm.matter.getU(sb);
  s.t = sb.getTime();
  s.q.resize(model.nr());
  for (const MobilizerMap& m : sm.map)
    for (int k = 0; k < m.nq; ++k) s.q[m.q_index + k] = q_sb[m.simbody_q + k];
  // T depends on q only
  s.qdot.setZero(model.nr());
  MatX T;
  calcVelocityMap(sm, model, s, T);
  s.qdot = T.partialPivLu().solve(fromSimTK(u_sb));
}

MatX calcSimbodyMassCore(const SimbodyModel& sm, const Model& model, const State& s) {
  SimTK::State sb = sm.default_state;
  setSimbodyState(sm, model, s, sb);
  sm.system.realize(sb, SimTK::Stage::Position);
  SimTK::Matrix M_u;
  sm.matter.calcM(sb, M_u);
  MatX T;
  calcVelocityMap(sm, model, s, T);
  return T.transpose() * fromSimTK(M_u) * T;
}

VecX calcSimbodyInverseDynamicsCore(const SimbodyModel& sm, const Model& model, const State& s,
                                    const VecX& qddot) {
  SimTK::State sb = sm.default_state;
  setSimbodyState(sm, model, s, sb);
  // gravity and mobility springs/dampers are the force subsystem's output at Stage::Dynamics
  sm.system.realize(sb, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& body_forces =
      sm.system.getRigidBodyForces(sb, SimTK::Stage::Dynamics);
  const SimTK::Vector& mobility_forces = sm.system.getMobilityForces(sb, SimTK::Stage::Dynamics);
  MatX T, Tdot;
  calcVelocityMap(sm, model, s, T, &Tdot);
  const VecX udot = T * qddot + Tdot * s.qdot;
  SimTK::Vector f_u;
  sm.matter.calcResidualForceIgnoringConstraints(sb, mobility_forces, body_forces, toSimTK(udot), f_u);
  // power balance tau . qdot = f_u . u with u = T qdot
  return T.transpose() * fromSimTK(f_u);
}

VecX calcSimbodyForwardDynamicsCore(const SimbodyModel& sm, const Model& model, const State& s) {
  SimTK::State sb = sm.default_state;
  setSimbodyState(sm, model, s, sb);
  sm.system.realize(sb, SimTK::Stage::Acceleration);
  const VecX udot = fromSimTK(sm.matter.getUDot(sb));
  MatX T, Tdot;
  calcVelocityMap(sm, model, s, T, &Tdot);
  return T.partialPivLu().solve(udot - Tdot * s.qdot);
}

}  // namespace redmax::simbody
