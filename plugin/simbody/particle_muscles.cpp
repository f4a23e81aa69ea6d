#include "plugin/simbody/particle_muscles.hpp"

#include <algorithm>
#include <map>
#include <memory>

#include <Eigen/LU>

#include "core/muscles/path_kinematics.hpp"
#include "core/muscles/path_map.hpp"
#include "plugin/simbody/muscle_inertia.hpp"

namespace redmax::simbody {

namespace {

// one muscle's 3N holonomic equations x_p - x_a(x, surfaces) = 0 (header). A moving point x_b(q_c)
// in body b reads q_c, qdot_c, qddot_c through its coordinate's mobilizer (a constrained mobilizer):
//   x = X_AB x_b,  xdot = v_station + R x_b' qdot_c,
//   xddot = a_station + 2 w x (R x_b' qdot_c) + R (x_b'' qdot_c^2 + x_b' qddot_c),
// and its constraint force gets the q-force (R x_b')^T F on q_c. Each wrap object's surface frame
// is a frame X_bs on a constrained body; the map is calcGeneralPathMap (core/muscles/path_map.hpp)
// over v = (xdot, (omega_w, pdot_w) per wrap).
class PathConstraint : public SimTK::Constraint::Custom::Implementation {
 public:
  // point_bodies: per path point; coord_mobods: per path point, the mobilizer of a moving point's
  // coordinate (or null) and the coordinate's index within it; surface_bodies: per wrap object of
  // the path, the body carrying its frame (Ground for a world surface)
  PathConstraint(SimTK::SimbodyMatterSubsystem& matter, const Muscle& mu,
                 const std::vector<SimTK::MobilizedBody>& point_bodies,
                 const std::vector<const SimTK::MobilizedBody*>& coord_mobods, const std::vector<int>& coord_in_mobod,
                 const std::vector<SimTK::MobilizedBody>& particles,
                 const std::vector<SimTK::MobilizedBody>& surface_bodies, std::shared_ptr<const std::vector<int>> active)
      : Implementation(matter, 3 * mu.mass_points.size(), 0, 0), mu_(mu), points_(mu.path.points),
        mp_(mu.mass_points), active_(std::move(active)) {
    // a body (mobilizer) carrying several points (coordinates) is constrained once
    std::map<int, SimTK::ConstrainedBodyIndex> cb_of;
    std::map<int, SimTK::ConstrainedMobilizerIndex> cm_of;
    const int P = static_cast<int>(point_bodies.size());
    cm_.resize(P);
    mq_.resize(P);
    for (int i = 0; i < P; ++i) {
      const int b = point_bodies[i].getMobilizedBodyIndex();
      auto it = cb_of.find(b);
      if (it == cb_of.end()) it = cb_of.emplace(b, addConstrainedBody(point_bodies[i])).first;
      point_cb_.push_back(it->second);
      if (!coord_mobods[i]) continue;
      const int c = coord_mobods[i]->getMobilizedBodyIndex();
      auto jt = cm_of.find(c);
      if (jt == cm_of.end()) jt = cm_of.emplace(c, addConstrainedMobilizer(*coord_mobods[i])).first;
      cm_[i] = jt->second;
      mq_[i] = SimTK::MobilizerQIndex(coord_in_mobod[i]);
    }
    for (size_t w = 0; w < surface_bodies.size(); ++w) {
      const int b = surface_bodies[w].getMobilizedBodyIndex();
      auto it = cb_of.find(b);
      if (it == cb_of.end()) it = cb_of.emplace(b, addConstrainedBody(surface_bodies[w])).first;
      surface_cb_.push_back(it->second);
      X_bs_.push_back(toTransform(mu.path.wraps.at(w).E_bs));
    }
    for (const SimTK::MobilizedBody& p : particles) particle_cb_.push_back(addConstrainedBody(p));
    x_b_.resize(P);
    dx_b_.resize(P);
    ddx_b_.resize(P);
    frames_.resize(surface_cb_.size());
  }

  Implementation* clone() const override { return new PathConstraint(*this); }

  void calcPositionErrors(const SimTK::State& s, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& cq,
                          SimTK::Array_<SimTK::Real>& perr) const override {
    const std::vector<int>& act = *active_;
    x_.resize(act.size());
    for (size_t j = 0; j < act.size(); ++j) {
      const int i = act[j];
      locate(i, moving(i) ? getOneQ(s, cq, cm_[i], mq_[i]) : 0.0);
      x_[j] = fromSimTKVec3(findStationLocation(X_AB, point_cb_[i], toSimTKVec3(x_b_[i])));
    }
    for (size_t w = 0; w < frames_.size(); ++w) setPose(w, X_AB[surface_cb_[w]]);
    mapPositions();
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& p = X_AB[particle_cb_[a]].p();
      for (int k = 0; k < 3; ++k) perr[3 * a + k] = p[k] - map_.x_a[a][k];
    }
  }

  void calcPositionDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& cqdot,
                             SimTK::Array_<SimTK::Real>& pverr) const override {
    const std::vector<int>& act = *active_;
    x_.resize(act.size());
    xdot_.resize(act.size());
    for (size_t j = 0; j < act.size(); ++j) {
      const int i = act[j];
      locate(i, moving(i) ? getOneQFromState(s, cm_[i], mq_[i]) : 0.0);
      const SimTK::Vec3 station = toSimTKVec3(x_b_[i]);
      x_[j] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], station));
      SimTK::Vec3 v = findStationVelocity(s, V_AB, point_cb_[i], station);
      if (moving(i))
        v += getBodyRotationFromState(s, point_cb_[i]) * toSimTKVec3(dx_b_[i]) * getOneQDot(s, cqdot, cm_[i], mq_[i]);
      xdot_[j] = fromSimTKVec3(v);
    }
    // xdot_a = J v [D Eq. 5.4], v = (xdot, (omega_w, pdot_w) per wrap) (path_map.hpp)
    for (size_t w = 0; w < frames_.size(); ++w) {
      setPose(w, getBodyTransformFromState(s, surface_cb_[w]));
      frames_[w].omega = fromSimTKVec3(getBodyAngularVelocity(V_AB, surface_cb_[w]));
      frames_[w].pdot = fromSimTKVec3(findStationVelocity(s, V_AB, surface_cb_[w], X_bs_[w].p()));
    }
    mapPositions();
    const VecX xdot_a = map_.J * stackGeneralVelocities(xdot_, frames_);
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& v = V_AB[particle_cb_[a]][1];
      for (int k = 0; k < 3; ++k) pverr[3 * a + k] = v[k] - xdot_a[3 * a + k];
    }
  }

  void calcPositionDotDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                                const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& cqddot,
                                SimTK::Array_<SimTK::Real>& paerr) const override {
    const std::vector<int>& act = *active_;
    const int P = static_cast<int>(act.size()), W = static_cast<int>(frames_.size());
    x_.resize(P);
    xdot_.resize(P);
    VecX vdot(3 * P + 6 * W);
    for (int j = 0; j < P; ++j) {
      const int i = act[j];
      locate(i, moving(i) ? getOneQFromState(s, cm_[i], mq_[i]) : 0.0);
      const SimTK::Vec3 station = toSimTKVec3(x_b_[i]);
      x_[j] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], station));
      SimTK::Vec3 v = findStationVelocityFromState(s, point_cb_[i], station);
      SimTK::Vec3 acc = findStationAcceleration(s, A_AB, point_cb_[i], station);
      if (moving(i)) {
        const SimTK::Rotation& R = getBodyRotationFromState(s, point_cb_[i]);
        const double qd = getOneQDotFromState(s, cm_[i], mq_[i]);
        const double qdd = getOneQDotDot(s, cqddot, cm_[i], mq_[i]);
        const SimTK::Vec3 v_rel = R * toSimTKVec3(dx_b_[i]) * qd;
        v += v_rel;
        acc += 2.0 * SimTK::cross(getBodyAngularVelocityFromState(s, point_cb_[i]), v_rel) +
               R * toSimTKVec3(ddx_b_[i] * qd * qd + dx_b_[i] * qdd);
      }
      xdot_[j] = fromSimTKVec3(v);
      vdot.segment<3>(3 * j) = fromSimTKVec3(acc);
    }
    // a_a = J vdot + bias [D Eq. 5.5], vdot = (xddot, (alpha_w, pddot_w) per wrap) (path_map.hpp)
    for (int w = 0; w < W; ++w) {
      const SimTK::ConstrainedBodyIndex cb = surface_cb_[w];
      setPose(w, getBodyTransformFromState(s, cb));
      frames_[w].omega = fromSimTKVec3(getBodyAngularVelocityFromState(s, cb));
      frames_[w].pdot = fromSimTKVec3(findStationVelocityFromState(s, cb, X_bs_[w].p()));
      vdot.segment<6>(3 * P + 6 * w) << fromSimTKVec3(getBodyAngularAcceleration(A_AB, cb)),
          fromSimTKVec3(findStationAcceleration(s, A_AB, cb, X_bs_[w].p()));
    }
    calcGeneralPathMap(mu_, act, x_, &xdot_, frames_, map_);
    keyMap();
    const VecX a_a = map_.J * vdot + map_.bias;
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& acc = A_AB[particle_cb_[a]][1];
      for (int k = 0; k < 3; ++k) paerr[3 * a + k] = acc[k] - a_a[3 * a + k];
    }
  }

  void addInPositionConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& lambda,
                                     SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
                                     SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& qForces) const override {
    const std::vector<int>& act = *active_;
    const int P = static_cast<int>(act.size());
    x_.resize(P);
    for (int j = 0; j < P; ++j) {
      const int i = act[j];
      locate(i, moving(i) ? getOneQFromState(s, cm_[i], mq_[i]) : 0.0);
      x_[j] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], toSimTKVec3(x_b_[i])));
    }
    for (size_t w = 0; w < frames_.size(); ++w) setPose(w, getBodyTransformFromState(s, surface_cb_[w]));
    mapPositions();
    // G^T lambda with G = (I on the particles, -J on v): forces at the path points and, per wrap,
    // a torque and a force at its surface origin
    VecX l(3 * mp_.size());
    for (int r = 0; r < l.size(); ++r) l[r] = lambda[r];
    for (int a = 0; a < mp_.size(); ++a)
      addInStationForce(s, particle_cb_[a], SimTK::Vec3(0), toSimTKVec3(l.segment<3>(3 * a)), bodyForcesInA);
    const VecX F = -(map_.J.transpose() * l);
    for (size_t w = 0; w < frames_.size(); ++w) {
      const int c = 3 * P + 6 * static_cast<int>(w);
      addInBodyTorque(s, surface_cb_[w], toSimTKVec3(F.segment<3>(c)), bodyForcesInA);
      addInStationForce(s, surface_cb_[w], X_bs_[w].p(), toSimTKVec3(F.segment<3>(c + 3)), bodyForcesInA);
    }
    for (int j = 0; j < P; ++j) {
      const int i = act[j];
      const SimTK::Vec3 Fi = toSimTKVec3(F.segment<3>(3 * j));
      addInStationForce(s, point_cb_[i], toSimTKVec3(x_b_[i]), Fi, bodyForcesInA);
      // a moving point's column through its coordinate: (R x_b')^T F
      if (moving(i))
        addInOneQForce(s, cm_[i], mq_[i], ~(getBodyRotationFromState(s, point_cb_[i]) * toSimTKVec3(dx_b_[i])) * Fi, qForces);
    }
  }

 private:
  bool moving(size_t i) const { return cm_[i].isValid(); }
  // the position-level map (x_a, J) for x_ and the frames' poses. Simbody asks for it once per
  // constraint row while it assembles G M^-1 G^T (30 rows on the finger), always at the same
  // positions: reuse the last map when its inputs are bit-identical (it is a function of them)
  void mapPositions() const {
    bool same = map_valid_ && map_active_ == *active_ && map_x_ == x_ && map_frames_.size() == frames_.size();
    for (size_t w = 0; same && w < frames_.size(); ++w)
      same = map_frames_[w].R == frames_[w].R && map_frames_[w].p == frames_[w].p;
    if (same) return;
    calcGeneralPathMap(mu_, *active_, x_, nullptr, frames_, map_);
    keyMap();
  }
  void keyMap() const {
    map_active_ = *active_;
    map_x_ = x_;
    map_frames_ = frames_;
    map_valid_ = true;
  }
  // surface frame w's pose from its body's pose X_AB (ancestor = Ground)
  void setPose(size_t w, const SimTK::Transform& X_AB) const {
    const SimTK::Transform X_AS = X_AB * X_bs_[w];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) frames_[w].R(r, c) = X_AS.R()[r][c];
    frames_[w].p = fromSimTKVec3(X_AS.p());
  }
  // x_b and its derivatives along the coordinate, for the coordinate's value q_c (moving points)
  void locate(size_t i, double q_c) const {
    const PathPoint& p = points_[i];
    if (p.kind != PathPointKind::Moving || p.coordinate < 0) {
      calcPointLocation(p, VecX(), x_b_[i], dx_b_[i], ddx_b_[i]);
      return;
    }
    if (q_.size() <= p.coordinate) q_.setZero(p.coordinate + 1);
    q_[p.coordinate] = q_c;
    calcPointLocation(p, q_, x_b_[i], dx_b_[i], ddx_b_[i]);
  }

  Muscle mu_;
  std::vector<PathPoint> points_;
  MassPoints mp_;
  // the active points (indices into points_): ParticleMuscles's, changed only by placeParticles
  // (at the start and at a conditional point's switch), so the constraint is smooth between switches
  std::shared_ptr<const std::vector<int>> active_;
  std::vector<SimTK::ConstrainedBodyIndex> point_cb_, particle_cb_;
  std::vector<SimTK::ConstrainedMobilizerIndex> cm_;  // per point; invalid for non-moving points
  std::vector<SimTK::MobilizerQIndex> mq_;
  mutable std::vector<Vec3> x_, xdot_, x_b_, dx_b_, ddx_b_;
  mutable VecX q_;  // scratch core q holding only the coordinate being evaluated
  // per wrap object: the constrained body carrying its frame, the frame on it, its state
  std::vector<SimTK::ConstrainedBodyIndex> surface_cb_;
  std::vector<SimTK::Transform> X_bs_;
  mutable std::vector<SurfaceFrameState> frames_;
  mutable GeneralPathMap map_;
  // the inputs map_ was computed for (mapPositions)
  mutable bool map_valid_ = false;
  mutable std::vector<int> map_active_;
  mutable std::vector<Vec3> map_x_;
  mutable std::vector<SurfaceFrameState> map_frames_;
};

// a conditional point's switch: the witness q_c - bound changes sign where the point turns on or
// off (bound: an end of its range widened by kConditionalTolerance, isPathPointActive's rule);
// Simbody localizes the crossing, then the handler takes the new active sets and puts the
// particles on the new paths with the skeleton's q and u unchanged, as the core's q and qdot are
class ConditionalSwitch : public SimTK::TriggeredEventHandler {
 public:
  ConditionalSwitch(std::shared_ptr<const detail::ParticlePlacer> placer, int simbody_q, double bound)
      : TriggeredEventHandler(SimTK::Stage::Position), placer_(std::move(placer)), q_(simbody_q), bound_(bound) {}
  SimTK::Real getValue(const SimTK::State& s) const override { return placer_->sm->matter.getQ(s)[q_] - bound_; }
  void handleEvent(SimTK::State& s, SimTK::Real, bool& terminate) const override {
    terminate = false;
    placer_->place(s);
  }

 private:
  std::shared_ptr<const detail::ParticlePlacer> placer_;
  int q_;
  double bound_;
};

// the Simbody q index of core coordinate c (Euler angles on: Simbody q = core q per mobilizer)
int simbodyQOf(const SimbodyModel& sm, int c) {
  for (const MobilizerMap& m : sm.map)
    if (c >= m.q_index && c < m.q_index + m.nq) return m.simbody_q + (c - m.q_index);
  return -1;
}

}  // namespace

namespace detail {

void ParticlePlacer::place(SimTK::State& sb) const {
  // the active sets at this q (isPathPointActive, the core's rule), which the constraints then keep
  const SimTK::Vector& q_sb = sm->matter.getQ(sb);
  for (const MobilizerMap& m : sm->map)
    for (int k = 0; k < m.nq; ++k) q_core[m.q_index + k] = q_sb[m.simbody_q + k];
  for (size_t e = 0; e < massive.size(); ++e) {
    const auto& pts = muscles[massive[e]].path.points;
    std::vector<int>& act = *active[e];
    act.clear();
    for (int k = 0; k < static_cast<int>(pts.size()); ++k)
      if (isPathPointActive(pts[k], q_core)) act.push_back(k);
  }
  sm->system.realize(sb, SimTK::Stage::Velocity);
  // the mass points' positions and velocities as inverse dynamics computes them (same path maps)
  std::vector<Vec3> x, xdot;
  motion->calcMassPointMotion(sb, x, xdot);
  // set after every read: writing q invalidates the stage the reads above need
  for (size_t k = 0; k < particles.size(); ++k) {
    particles[k].setQToFitTranslation(sb, toSimTKVec3(x[k]));
    particles[k].setUToFitLinearVelocity(sb, toSimTKVec3(xdot[k]));
  }
}

}  // namespace detail

ParticleMuscles::ParticleMuscles(SimbodyModel& sm, const Model& model, std::vector<Muscle> muscles)
    : sm_(sm), placer_(std::make_shared<detail::ParticlePlacer>()) {
  detail::ParticlePlacer& placer = *placer_;
  placer.sm = &sm;
  placer.muscles = std::move(muscles);
  placer.q_core.setZero(model.nr());
  for (int mi = 0; mi < static_cast<int>(placer.muscles.size()); ++mi) {
    const Muscle& mu = placer.muscles[mi];
    validateMuscle(model, mu);
    if (mu.mass_points.size() == 0) continue;
    const std::string why = simbodyWrapShapeUnsupportedReason(mu);
    if (!why.empty()) throw SimbodyBuildError(why);
    for (double m : mu.mass_points.mass)
      if (!(m > 0.0))
        throw SimbodyBuildError("muscle '" + mu.name + "': a mass point without mass cannot be a Simbody particle");

    // particles: point masses translating freely from Ground, placed by placeParticles
    std::vector<SimTK::MobilizedBody> mine;
    for (double m : mu.mass_points.mass) {
      SimTK::Body::Rigid body(SimTK::MassProperties(m, SimTK::Vec3(0), SimTK::Inertia(0)));
      SimTK::MobilizedBody::Translation p(sm.matter.updGround(), SimTK::Transform(), body, SimTK::Transform());
      mine.push_back(p);
      placer.particles.push_back(p);
    }
    std::vector<SimTK::MobilizedBody> point_bodies;
    std::vector<const SimTK::MobilizedBody*> coord_mobods;
    std::vector<int> coord_in_mobod;
    for (const PathPoint& p : mu.path.points) {
      point_bodies.push_back(p.body >= 0 ? sm.mobods[p.body] : SimTK::MobilizedBody(sm.matter.updGround()));
      // a moving point's coordinate: the mobilizer holding it (Simbody q = core q, Euler angles)
      const SimTK::MobilizedBody* mob = nullptr;
      int k_in = 0;
      if (p.kind == PathPointKind::Moving && p.coordinate >= 0)
        for (size_t j = 0; j < sm.map.size(); ++j) {
          const MobilizerMap& mm = sm.map[j];
          if (p.coordinate < mm.q_index || p.coordinate >= mm.q_index + mm.nq) continue;
          mob = &sm.mobods[j];
          k_in = p.coordinate - mm.q_index;
        }
      coord_mobods.push_back(mob);
      coord_in_mobod.push_back(k_in);
    }
    // Type III: each wrap object's body is constrained too
    std::vector<SimTK::MobilizedBody> surface_bodies;
    for (const PathWrap& w : mu.path.wraps)
      surface_bodies.push_back(w.body >= 0 ? sm.mobods[w.body] : SimTK::MobilizedBody(sm.matter.updGround()));
    // the active set, all points until placeParticles reads q
    auto active = std::make_shared<std::vector<int>>();
    for (int k = 0; k < static_cast<int>(mu.path.points.size()); ++k) active->push_back(k);
    placer.massive.push_back(mi);
    placer.active.push_back(active);
    SimTK::Constraint::Custom(
        new PathConstraint(sm.matter, mu, point_bodies, coord_mobods, coord_in_mobod, mine, surface_bodies, active));
    // conditional points: an event at each end of the range (an unconnected one is never active)
    for (const PathPoint& p : mu.path.points) {
      if (p.kind != PathPointKind::Conditional || p.coordinate < 0) continue;
      const int q_sb = simbodyQOf(sm, p.coordinate);
      if (q_sb < 0)
        throw SimbodyBuildError("muscle '" + mu.name + "': point '" + p.name + "' is conditional on a coordinate "
                                "the Simbody system has no q for");
      for (double bound : {p.range_lo - kConditionalTolerance, p.range_hi + kConditionalTolerance})
        sm.system.addEventHandler(new ConditionalSwitch(placer_, q_sb, bound));
    }
  }
  // the mass points' motion on the skeleton (placeParticles): the skeleton's bodies and q slots,
  // which the particles added above do not move
  placer.motion = std::make_unique<MatterMuscleInertia>(sm.matter, makeMatterMap(sm, model), model,
                                                        placer.muscles, model.gravity());
  // the topology changed: a new default state, Euler angles on as makeSimbodyModel sets them
  try {
    sm.default_state = sm.system.realizeTopology();
    sm.matter.setUseEulerAngles(sm.default_state, true);
    sm.system.realizeModel(sm.default_state);
  } catch (const std::exception& e) {
    throw SimbodyBuildError(std::string("Simbody could not realize the model with muscle particles: ") + e.what());
  }
}

void ParticleMuscles::placeParticles(SimTK::State& sb) const { placer_->place(sb); }

State ParticleMuscles::coreState(const Model& model, const SimTK::State& sb) const {
  const SimTK::Vector& q_sb = sm_.matter.getQ(sb);
  const SimTK::Vector& u_sb = sm_.matter.getU(sb);
  State s;
  s.t = sb.getTime();
  s.q.resize(model.nr());
  for (const MobilizerMap& m : sm_.map)
    for (int k = 0; k < m.nq; ++k) s.q[m.q_index + k] = q_sb[m.simbody_q + k];
  // the skeleton's u come first (the particles were added after it); T depends on q only
  s.qdot.setZero(model.nr());
  MatX T;
  calcVelocityMap(sm_, model, s, T);
  VecX u(sm_.nu);
  for (int k = 0; k < sm_.nu; ++k) u[k] = u_sb[k];
  s.qdot = T.partialPivLu().solve(u);
  return s;
}

}  // namespace redmax::simbody
