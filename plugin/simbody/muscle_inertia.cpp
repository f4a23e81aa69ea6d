#include "plugin/simbody/muscle_inertia.hpp"

#include "core/muscles/path_kinematics.hpp"

namespace redmax::simbody {

namespace {

SimTK::Vec3 toSimTKVec3(const Vec3& v) { return SimTK::Vec3(v.x(), v.y(), v.z()); }
Vec3 fromSimTKVec3(const SimTK::Vec3& v) { return Vec3(v[0], v[1], v[2]); }

}  // namespace

std::string simbodyWrapShapeUnsupportedReason(const Muscle& mu) {
  if (mu.mass_points.size() == 0 || pathType(mu.path) != PathType::III) return "";
  const MusclePath& path = mu.path;
  if (path.wraps.size() != 1 || path.points.size() != 2)
    return "muscle '" + mu.name + "': the Simbody side carries Type III mass points only for origin -> one wrap "
           "surface -> insertion (this path has " + std::to_string(path.points.size()) + " points and " +
           std::to_string(path.wraps.size()) + " wrap objects); use the core";
  for (const PathPoint& p : path.points)
    if (p.kind == PathPointKind::Conditional)
      return "muscle '" + mu.name + "': conditional end point '" + p.name + "' on a wrapping path with mass points";
  return "";
}

MuscleInertia::MuscleInertia(const SimbodyModel& sm, const Model& model, std::vector<Muscle> muscles)
    : MuscleInertia(sm, model, std::move(muscles), model.gravity) {}

MuscleInertia::MuscleInertia(const SimbodyModel& sm, const Model& model, std::vector<Muscle> muscles,
                             const Vec3& gravity)
    : sm_(sm), muscles_(std::move(muscles)), gravity_(gravity) {
  for (int m = 0; m < static_cast<int>(muscles_.size()); ++m) {
    validateMuscle(model, muscles_[m]);
    if (muscles_[m].mass_points.size() == 0) continue;
    const std::string why = simbodyWrapShapeUnsupportedReason(muscles_[m]);
    if (!why.empty()) throw ModelError(why);
    Entry e;
    e.muscle = m;
    // Type III: validateMuscle accepted the supported shape (one wrap surface, two points)
    if (pathType(muscles_[m].path) == PathType::III) {
      const PathWrap& w = muscles_[m].path.wraps.at(0);
      e.wrap = true;
      e.surface_body = w.body;
      e.X_bs = toTransform(w.E_bs);
    }
    entries_.push_back(std::move(e));
  }
  // core coordinate -> Simbody q (Euler angles: the same numbers, possibly another order)
  simbody_q_of_.assign(model.nr(), -1);
  for (const MobilizerMap& mm : sm.map)
    for (int k = 0; k < mm.nq; ++k) simbody_q_of_[mm.q_index + k] = mm.simbody_q + k;
  q_core_.setZero(model.nr());
}

double MuscleInertia::totalMass() const {
  double m = 0.0;
  for (const Muscle& mu : muscles_) m += mu.mass_points.totalMass();
  return m;
}

void MuscleInertia::evaluate(const SimTK::State& state, bool velocity) {
  const SimTK::Vector& q = sm_.matter.getQ(state);
  for (int c = 0; c < q_core_.size(); ++c) q_core_[c] = simbody_q_of_[c] >= 0 ? q[simbody_q_of_[c]] : 0.0;
  const SimTK::Vector* qdot = velocity ? &sm_.matter.getQDot(state) : nullptr;

  for (Entry& e : entries_) {
    const Muscle& mu = muscles_[e.muscle];
    const auto& points = mu.path.points;
    // active set: conditional points by OpenSim's rule, on the state's q
    e.active.clear();
    for (int k = 0; k < static_cast<int>(points.size()); ++k)
      if (isPathPointActive(points[k], q_core_)) e.active.push_back(k);
    const int P = static_cast<int>(e.active.size());
    e.x.resize(P);
    e.x_b.resize(P);
    e.dx_b.resize(P);
    e.ddx_b.resize(P);
    if (velocity) e.xdot.resize(P);

    for (int i = 0; i < P; ++i) {
      const PathPoint& pt = points[e.active[i]];
      calcPointLocation(pt, q_core_, e.x_b[i], e.dx_b[i], e.ddx_b[i]);
      const SimTK::MobilizedBody& B = pt.body >= 0 ? sm_.mobods[pt.body] : sm_.matter.getGround();
      const SimTK::Vec3 station = toSimTKVec3(e.x_b[i]);
      e.x[i] = fromSimTKVec3(B.findStationLocationInGround(state, station));
      if (!velocity) continue;
      SimTK::Vec3 v = B.findStationVelocityInGround(state, station);
      // moving point: the location's own rate through its coordinate, R x_b' qdot_c
      if (pt.kind == PathPointKind::Moving && pt.coordinate >= 0)
        v += B.getBodyRotation(state) * toSimTKVec3(e.dx_b[i]) * (*qdot)[simbody_q_of_[pt.coordinate]];
      e.xdot[i] = fromSimTKVec3(v);
    }
    if (!e.wrap) {
      calcPathMap(e.x, velocity ? &e.xdot : nullptr, mu.mass_points, e.map, mu.name);
      continue;
    }
    // the surface frame S on its body: pose, angular velocity and origin velocity (Ground)
    if (P != 2) throw MuscleError("muscle '" + mu.name + "': a wrapping muscle needs its two end points active");
    const SimTK::MobilizedBody& S = e.surface_body >= 0 ? sm_.mobods[e.surface_body] : sm_.matter.getGround();
    const SimTK::Transform X_GS = S.getBodyTransform(state) * e.X_bs;
    Mat3 R;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) R(r, c) = X_GS.R()[r][c];
    WrapSegmentVelocity v;
    if (velocity) {
      v.xdot1 = e.xdot[0];
      v.xdot2 = e.xdot[1];
      v.omega = fromSimTKVec3(S.getBodyAngularVelocity(state));
      v.pdot = fromSimTKVec3(S.findStationVelocityInGround(state, e.X_bs.p()));
    }
    calcWrapPathMap(mu.path.wraps[0].surface, mu.wrap, mu.mass_points, e.x[0], e.x[1], R, fromSimTKVec3(X_GS.p()),
                    velocity ? &v : nullptr, e.wmap, mu.name);
  }
}

void MuscleInertia::calcGeneralizedForces(const SimTK::State& state, const SimTK::Vector& udot,
                                          SimTK::Vector& f_u) {
  const int nu = sm_.matter.getNumMobilities();
  f_u.resize(nu);
  f_u = 0.0;
  if (entries_.empty()) return;
  evaluate(state, true);

  // one batch of stations over every muscle: JS udot and the bias JSdot u [D Eq. 5.5]
  bodies_.clear();
  stations_.clear();
  bool any_moving = false;
  for (const Entry& e : entries_) {
    const auto& points = muscles_[e.muscle].path.points;
    for (size_t i = 0; i < e.active.size(); ++i) {
      const PathPoint& pt = points[e.active[i]];
      const SimTK::MobilizedBody& B = pt.body >= 0 ? sm_.mobods[pt.body] : sm_.matter.getGround();
      bodies_.push_back(B.getMobilizedBodyIndex());
      stations_.push_back(toSimTKVec3(e.x_b[i]));
      any_moving = any_moving || (pt.kind == PathPointKind::Moving && pt.coordinate >= 0);
    }
  }
  sm_.matter.multiplyByStationJacobian(state, bodies_, stations_, udot, JSudot_);
  sm_.matter.calcBiasForStationJacobian(state, bodies_, stations_, bias_);
  forces_.resize(static_cast<int>(bodies_.size()));
  // Type III surfaces: one frame each, spatial acceleration JF udot + JFdot u = (alpha, pddot)
  frame_bodies_.clear();
  frame_origins_.clear();
  for (const Entry& e : entries_) {
    if (!e.wrap) continue;
    const SimTK::MobilizedBody& S = e.surface_body >= 0 ? sm_.mobods[e.surface_body] : sm_.matter.getGround();
    frame_bodies_.push_back(S.getMobilizedBodyIndex());
    frame_origins_.push_back(e.X_bs.p());
  }
  if (!frame_bodies_.empty()) {
    sm_.matter.multiplyByFrameJacobian(state, frame_bodies_, frame_origins_, udot, JFudot_);
    sm_.matter.calcBiasForFrameJacobian(state, frame_bodies_, frame_origins_, frame_bias_);
    frame_forces_.resize(static_cast<int>(frame_bodies_.size()));
  }
  int frame = 0;  // the current Type III entry's frame
  SimTK::Vector qddot, f_q;
  if (any_moving) {
    sm_.matter.calcQDotDot(state, udot, qddot);
    f_q.resize(sm_.matter.getQ(state).size());
    f_q = 0.0;
  }
  const SimTK::Vector& qdot = sm_.matter.getQDot(state);

  int row = 0;  // first station of the current muscle in the batch
  for (Entry& e : entries_) {
    const Muscle& mu = muscles_[e.muscle];
    const int P = static_cast<int>(e.active.size());
    VecX xddot(3 * P);
    for (int i = 0; i < P; ++i) {
      SimTK::Vec3 a = JSudot_[row + i] + bias_[row + i];
      const PathPoint& pt = mu.path.points[e.active[i]];
      if (pt.kind == PathPointKind::Moving && pt.coordinate >= 0) {
        // 2 w x (R x_b' qdot_c) + R (x_b'' qdot_c^2 + x_b' qddot_c)
        const SimTK::MobilizedBody& B = pt.body >= 0 ? sm_.mobods[pt.body] : sm_.matter.getGround();
        const SimTK::Rotation& R = B.getBodyRotation(state);
        const int sq = simbody_q_of_[pt.coordinate];
        const double qd = qdot[sq], qdd = qddot[sq];
        const SimTK::Vec3 v_rel = R * toSimTKVec3(e.dx_b[i]) * qd;
        a += 2.0 * SimTK::cross(B.getBodyAngularVelocity(state), v_rel) +
             R * toSimTKVec3(e.ddx_b[i] * qd * qd + e.dx_b[i] * qdd);
      }
      xddot.segment<3>(3 * i) = fromSimTKVec3(a);
    }
    // f_a = m_a (a_a - g) [D Eq. 5.6-5.7], pulled back to the path points by J_ax^T
    VecX a_a;
    if (!e.wrap) {
      a_a = calcMassPointAccelerations(e.map, xddot);
    } else {
      // vdot = (xddot1, xddot2, alpha, pddot); a_a = J vdot + b (path_map.hpp)
      const SimTK::SpatialVec A = JFudot_[frame] + frame_bias_[frame];
      VecX vdot(12);
      vdot << xddot, fromSimTKVec3(A[0]), fromSimTKVec3(A[1]);
      a_a = e.wmap.J * vdot + e.wmap.bias;
    }
    VecX f_a(a_a.size());
    for (int a = 0; a < mu.mass_points.size(); ++a)
      f_a.segment<3>(3 * a) = mu.mass_points.mass[a] * (a_a.segment<3>(3 * a) - gravity_);
    VecX F_x;
    if (!e.wrap) {
      F_x = e.map.J_ax.transpose() * f_a;
    } else {
      // the (omega, pdot) columns give a torque and a force at the surface origin
      const VecX F = e.wmap.J.transpose() * f_a;
      F_x = F.head<6>();
      frame_forces_[frame] = SimTK::SpatialVec(toSimTKVec3(F.segment<3>(6)), toSimTKVec3(F.segment<3>(9)));
      ++frame;
    }
    for (int i = 0; i < P; ++i) {
      const Vec3 F = F_x.segment<3>(3 * i);
      forces_[row + i] = toSimTKVec3(F);
      const PathPoint& pt = mu.path.points[e.active[i]];
      if (pt.kind == PathPointKind::Moving && pt.coordinate >= 0) {
        // the point's column through q_c: (R x_b')^T F, conjugate to qdot_c
        const SimTK::MobilizedBody& B = pt.body >= 0 ? sm_.mobods[pt.body] : sm_.matter.getGround();
        f_q[simbody_q_of_[pt.coordinate]] += ~(B.getBodyRotation(state) * toSimTKVec3(e.dx_b[i])) * toSimTKVec3(F);
      }
    }
    row += P;
  }
  // station forces to u space: JS^T F; the q-space part through qdot = N u: N^T f_q
  sm_.matter.multiplyByStationJacobianTranspose(state, bodies_, stations_, forces_, f_u);
  if (!frame_bodies_.empty()) {
    SimTK::Vector f_frames;
    sm_.matter.multiplyByFrameJacobianTranspose(state, frame_bodies_, frame_origins_, frame_forces_, f_frames);
    f_u += f_frames;
  }
  if (any_moving) {
    SimTK::Vector f_extra;
    sm_.matter.multiplyByN(state, true, f_q, f_extra);
    f_u += f_extra;
  }
}

VecX MuscleInertia::calcGeneralizedForces(const SimTK::State& state, const VecX& udot) {
  SimTK::Vector f_u;
  calcGeneralizedForces(state, toSimTK(udot), f_u);
  return fromSimTK(f_u);
}

VecX MuscleInertia::wrapVelocity(const SimTK::State& state, const Entry& e) const {
  const SimTK::MobilizedBody& S = e.surface_body >= 0 ? sm_.mobods[e.surface_body] : sm_.matter.getGround();
  VecX v(12);
  v << e.xdot[0], e.xdot[1], fromSimTKVec3(S.getBodyAngularVelocity(state)),
      fromSimTKVec3(S.findStationVelocityInGround(state, e.X_bs.p()));
  return v;
}

double MuscleInertia::kineticEnergy(const SimTK::State& state) {
  evaluate(state, true);
  double T = 0.0;
  for (const Entry& e : entries_) {
    const MassPoints& mp = muscles_[e.muscle].mass_points;
    const VecX xdot_a = e.wrap ? VecX(e.wmap.J * wrapVelocity(state, e)) : VecX(e.map.J_ax * stackPoints(e.xdot));
    for (int a = 0; a < mp.size(); ++a) T += 0.5 * mp.mass[a] * xdot_a.segment<3>(3 * a).squaredNorm();
  }
  return T;
}

double MuscleInertia::potentialEnergy(const SimTK::State& state) {
  evaluate(state, false);
  double V = 0.0;
  for (const Entry& e : entries_) {
    const MassPoints& mp = muscles_[e.muscle].mass_points;
    const std::vector<Vec3>& x_a = e.wrap ? e.wmap.x_a : e.map.x_a;
    for (int a = 0; a < mp.size(); ++a) V -= mp.mass[a] * gravity_.dot(x_a[a]);
  }
  return V;
}

}  // namespace redmax::simbody
