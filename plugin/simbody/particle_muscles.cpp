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

SimTK::Vec3 toSimTKVec3(const Vec3& v) { return SimTK::Vec3(v.x(), v.y(), v.z()); }
Vec3 fromSimTKVec3(const SimTK::Vec3& v) { return Vec3(v[0], v[1], v[2]); }

// one muscle's 3N holonomic equations x_p - x_a(x) = 0 (header). A moving point x_b(q_c) in body b
// reads q_c, qdot_c, qddot_c through its coordinate's mobilizer (a constrained mobilizer):
//   x = X_AB x_b,  xdot = v_station + R x_b' qdot_c,
//   xddot = a_station + 2 w x (R x_b' qdot_c) + R (x_b'' qdot_c^2 + x_b' qddot_c),
// and its constraint force gets the q-force (R x_b')^T F on q_c.
class PathConstraint : public SimTK::Constraint::Custom::Implementation {
 public:
  // point_bodies: per path point; coord_mobods: per path point, the mobilizer of a moving point's
  // coordinate (or null) and the coordinate's index within it
  // surface_body: a Type III muscle's wrap surface body (Ground for a world surface), else null
  PathConstraint(SimTK::SimbodyMatterSubsystem& matter, const Muscle& mu,
                 const std::vector<SimTK::MobilizedBody>& point_bodies,
                 const std::vector<const SimTK::MobilizedBody*>& coord_mobods, const std::vector<int>& coord_in_mobod,
                 const std::vector<SimTK::MobilizedBody>& particles, const SimTK::MobilizedBody* surface_body)
      : Implementation(matter, 3 * mu.mass_points.size(), 0, 0),
        points_(mu.path.points), mp_(mu.mass_points), name_(mu.name), wrap_opt_(mu.wrap) {
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
    if (surface_body) {
      const PathWrap& w = mu.path.wraps.at(0);
      wrap_ = true;
      surface_ = w.surface;
      X_bs_ = toTransform(w.E_bs);
      const int b = surface_body->getMobilizedBodyIndex();
      auto it = cb_of.find(b);
      if (it == cb_of.end()) it = cb_of.emplace(b, addConstrainedBody(*surface_body)).first;
      surface_cb_ = it->second;
    }
    for (const SimTK::MobilizedBody& p : particles) particle_cb_.push_back(addConstrainedBody(p));
    x_.resize(P);
    xdot_.resize(P);
    x_b_.resize(P);
    dx_b_.resize(P);
    ddx_b_.resize(P);
  }

  Implementation* clone() const override { return new PathConstraint(*this); }

  void calcPositionErrors(const SimTK::State& s, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& cq,
                          SimTK::Array_<SimTK::Real>& perr) const override {
    for (size_t i = 0; i < x_.size(); ++i) {
      locate(i, moving(i) ? getOneQ(s, cq, cm_[i], mq_[i]) : 0.0);
      x_[i] = fromSimTKVec3(findStationLocation(X_AB, point_cb_[i], toSimTKVec3(x_b_[i])));
    }
    const std::vector<Vec3>& x_a = mapPositions(wrap_ ? X_AB[surface_cb_] : SimTK::Transform());
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& p = X_AB[particle_cb_[a]].p();
      for (int k = 0; k < 3; ++k) perr[3 * a + k] = p[k] - x_a[a][k];
    }
  }

  void calcPositionDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& cqdot,
                             SimTK::Array_<SimTK::Real>& pverr) const override {
    for (size_t i = 0; i < x_.size(); ++i) {
      locate(i, moving(i) ? getOneQFromState(s, cm_[i], mq_[i]) : 0.0);
      const SimTK::Vec3 station = toSimTKVec3(x_b_[i]);
      x_[i] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], station));
      SimTK::Vec3 v = findStationVelocity(s, V_AB, point_cb_[i], station);
      if (moving(i))
        v += getBodyRotationFromState(s, point_cb_[i]) * toSimTKVec3(dx_b_[i]) * getOneQDot(s, cqdot, cm_[i], mq_[i]);
      xdot_[i] = fromSimTKVec3(v);
    }
    // xdot_a = J_ax xdot [D Eq. 5.4]; Type III: J (xdot, omega, pdot) (path_map.hpp)
    VecX xdot_a;
    if (!wrap_) {
      calcPathMap(x_, nullptr, mp_, map_, name_);
      xdot_a = map_.J_ax * stackPoints(xdot_);
    } else {
      mapPositions(getBodyTransformFromState(s, surface_cb_));
      VecX v(12);
      v << stackPoints(xdot_), fromSimTKVec3(getBodyAngularVelocity(V_AB, surface_cb_)),
          fromSimTKVec3(findStationVelocity(s, V_AB, surface_cb_, X_bs_.p()));
      xdot_a = wmap_.J * v;
    }
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& v = V_AB[particle_cb_[a]][1];
      for (int k = 0; k < 3; ++k) pverr[3 * a + k] = v[k] - xdot_a[3 * a + k];
    }
  }

  void calcPositionDotDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                                const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& cqddot,
                                SimTK::Array_<SimTK::Real>& paerr) const override {
    VecX xddot(3 * static_cast<int>(x_.size()));
    for (size_t i = 0; i < x_.size(); ++i) {
      locate(i, moving(i) ? getOneQFromState(s, cm_[i], mq_[i]) : 0.0);
      const SimTK::Vec3 station = toSimTKVec3(x_b_[i]);
      x_[i] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], station));
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
      xdot_[i] = fromSimTKVec3(v);
      xddot.segment<3>(3 * static_cast<int>(i)) = fromSimTKVec3(acc);
    }
    // a_a = J_ax xddot + Jdot_ax xdot [D Eq. 5.5]; Type III: J vdot + b (path_map.hpp)
    VecX a_a;
    if (!wrap_) {
      calcPathMap(x_, &xdot_, mp_, map_, name_);
      a_a = calcMassPointAccelerations(map_, xddot);
    } else {
      WrapSegmentVelocity v;
      v.xdot1 = xdot_[0];
      v.xdot2 = xdot_[1];
      v.omega = fromSimTKVec3(getBodyAngularVelocityFromState(s, surface_cb_));
      v.pdot = fromSimTKVec3(findStationVelocityFromState(s, surface_cb_, X_bs_.p()));
      const SimTK::Transform X_AS = getBodyTransformFromState(s, surface_cb_) * X_bs_;
      calcWrapPathMap(surface_, wrap_opt_, mp_, x_[0], x_[1], toMat3(X_AS.R()), fromSimTKVec3(X_AS.p()), &v, wmap_,
                      name_);
      VecX vdot(12);
      vdot << xddot, fromSimTKVec3(getBodyAngularAcceleration(A_AB, surface_cb_)),
          fromSimTKVec3(findStationAcceleration(s, A_AB, surface_cb_, X_bs_.p()));
      a_a = wmap_.J * vdot + wmap_.bias;
    }
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& acc = A_AB[particle_cb_[a]][1];
      for (int k = 0; k < 3; ++k) paerr[3 * a + k] = acc[k] - a_a[3 * a + k];
    }
  }

  void addInPositionConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& lambda,
                                     SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
                                     SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>& qForces) const override {
    for (size_t i = 0; i < x_.size(); ++i) {
      locate(i, moving(i) ? getOneQFromState(s, cm_[i], mq_[i]) : 0.0);
      x_[i] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], toSimTKVec3(x_b_[i])));
    }
    // G^T lambda with G = (I on the particles, -J_ax on the path points); Type III: -J on
    // (xdot, omega, pdot), the last six a torque and a force at the surface origin
    VecX l(3 * mp_.size());
    for (int r = 0; r < l.size(); ++r) l[r] = lambda[r];
    for (int a = 0; a < mp_.size(); ++a)
      addInStationForce(s, particle_cb_[a], SimTK::Vec3(0), toSimTKVec3(l.segment<3>(3 * a)), bodyForcesInA);
    VecX F;
    if (!wrap_) {
      calcPathMap(x_, nullptr, mp_, map_, name_);
      F = -(map_.J_ax.transpose() * l);
    } else {
      mapPositions(getBodyTransformFromState(s, surface_cb_));
      const VecX G = -(wmap_.J.transpose() * l);
      F = G.head<6>();
      addInBodyTorque(s, surface_cb_, toSimTKVec3(G.segment<3>(6)), bodyForcesInA);
      addInStationForce(s, surface_cb_, X_bs_.p(), toSimTKVec3(G.segment<3>(9)), bodyForcesInA);
    }
    for (size_t i = 0; i < x_.size(); ++i) {
      const SimTK::Vec3 Fi = toSimTKVec3(F.segment<3>(3 * static_cast<int>(i)));
      addInStationForce(s, point_cb_[i], toSimTKVec3(x_b_[i]), Fi, bodyForcesInA);
      // a moving point's column through its coordinate: (R x_b')^T F
      if (moving(i))
        addInOneQForce(s, cm_[i], mq_[i], ~(getBodyRotationFromState(s, point_cb_[i]) * toSimTKVec3(dx_b_[i])) * Fi, qForces);
    }
  }

 private:
  bool moving(size_t i) const { return cm_[i].isValid(); }
  static Mat3 toMat3(const SimTK::Rotation& R) {
    Mat3 out;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) out(r, c) = R[r][c];
    return out;
  }
  // mass point positions from x_ (and, Type III, the surface body's pose X_AB in the ancestor)
  const std::vector<Vec3>& mapPositions(const SimTK::Transform& X_AB_surface) const {
    if (!wrap_) {
      calcPathMap(x_, nullptr, mp_, map_, name_);
      return map_.x_a;
    }
    const SimTK::Transform X_AS = X_AB_surface * X_bs_;
    calcWrapPathMap(surface_, wrap_opt_, mp_, x_[0], x_[1], toMat3(X_AS.R()), fromSimTKVec3(X_AS.p()), nullptr, wmap_,
                    name_);
    return wmap_.x_a;
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

  std::vector<PathPoint> points_;
  MassPoints mp_;
  std::string name_;
  std::vector<SimTK::ConstrainedBodyIndex> point_cb_, particle_cb_;
  std::vector<SimTK::ConstrainedMobilizerIndex> cm_;  // per point; invalid for non-moving points
  std::vector<SimTK::MobilizerQIndex> mq_;
  mutable std::vector<Vec3> x_, xdot_, x_b_, dx_b_, ddx_b_;
  mutable VecX q_;  // scratch core q holding only the coordinate being evaluated
  mutable PathMap map_;
  // Type III: the wrap surface, its pose on its body and the constrained body carrying it
  WrapMassOptions wrap_opt_;
  bool wrap_ = false;
  WrapSurface surface_;
  SimTK::Transform X_bs_;
  SimTK::ConstrainedBodyIndex surface_cb_;
  mutable WrapPathMap wmap_;
};

}  // namespace

ParticleMuscles::ParticleMuscles(SimbodyModel& sm, const Model& model, std::vector<Muscle> muscles)
    : sm_(sm), muscles_(std::move(muscles)) {
  for (const Muscle& mu : muscles_) {
    validateMuscle(model, mu);
    if (mu.mass_points.size() == 0) {
      first_particle_.push_back(-1);
      continue;
    }
    const std::string why = simbodyWrapShapeUnsupportedReason(mu);
    if (!why.empty()) throw SimbodyBuildError(why);
    for (const PathPoint& p : mu.path.points)
      if (p.kind == PathPointKind::Conditional)
        throw SimbodyBuildError("muscle '" + mu.name + "': point '" + p.name +
                                "' is conditional; Simbody particles support fixed and moving path points only");
    for (double m : mu.mass_points.mass)
      if (!(m > 0.0))
        throw SimbodyBuildError("muscle '" + mu.name + "': a mass point without mass cannot be a Simbody particle");

    // particles: point masses translating freely from Ground, placed by placeParticles
    first_particle_.push_back(static_cast<int>(particles_.size()));
    std::vector<SimTK::MobilizedBody> mine;
    for (double m : mu.mass_points.mass) {
      SimTK::Body::Rigid body(SimTK::MassProperties(m, SimTK::Vec3(0), SimTK::Inertia(0)));
      SimTK::MobilizedBody::Translation p(sm.matter.updGround(), SimTK::Transform(), body, SimTK::Transform());
      mine.push_back(p);
      particles_.push_back(p);
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
    // Type III (validateMuscle accepted the supported shape): the surface's body is constrained too
    std::unique_ptr<SimTK::MobilizedBody> surface_body;
    if (pathType(mu.path) == PathType::III) {
      const int b = mu.path.wraps.at(0).body;
      surface_body = std::make_unique<SimTK::MobilizedBody>(b >= 0 ? sm.mobods[b]
                                                                   : SimTK::MobilizedBody(sm.matter.updGround()));
    }
    SimTK::Constraint::Custom(
        new PathConstraint(sm.matter, mu, point_bodies, coord_mobods, coord_in_mobod, mine, surface_body.get()));
  }
  // the topology changed: a new default state, Euler angles on as makeSimbodyModel sets them
  try {
    sm.default_state = sm.system.realizeTopology();
    sm.matter.setUseEulerAngles(sm.default_state, true);
    sm.system.realizeModel(sm.default_state);
  } catch (const std::exception& e) {
    throw SimbodyBuildError(std::string("Simbody could not realize the model with muscle particles: ") + e.what());
  }
}

void ParticleMuscles::placeParticles(SimTK::State& sb) const {
  sm_.system.realize(sb, SimTK::Stage::Velocity);
  std::vector<SimTK::Vec3> x_p(particles_.size()), v_p(particles_.size());
  // the skeleton's q and qdot in core order (Simbody q = core q with Euler angles)
  const SimTK::Vector& q_sb = sm_.matter.getQ(sb);
  const SimTK::Vector& qdot_sb = sm_.matter.getQDot(sb);
  int nr = 0;
  for (const MobilizerMap& mm : sm_.map) nr = std::max(nr, mm.q_index + mm.nq);
  VecX q(nr), qdot(nr);
  for (const MobilizerMap& mm : sm_.map)
    for (int k = 0; k < mm.nq; ++k) {
      q[mm.q_index + k] = q_sb[mm.simbody_q + k];
      qdot[mm.q_index + k] = qdot_sb[mm.simbody_q + k];
    }
  PathMap map;
  WrapPathMap wmap;
  for (size_t m = 0; m < muscles_.size(); ++m) {
    if (first_particle_[m] < 0) continue;
    const Muscle& mu = muscles_[m];
    std::vector<Vec3> x, xdot;
    for (const PathPoint& p : mu.path.points) {
      const SimTK::MobilizedBody& B = p.body >= 0 ? sm_.mobods[p.body] : sm_.matter.getGround();
      Vec3 x_b, dx_b, ddx_b;
      calcPointLocation(p, q, x_b, dx_b, ddx_b);
      x.push_back(fromSimTKVec3(B.findStationLocationInGround(sb, toSimTKVec3(x_b))));
      SimTK::Vec3 v = B.findStationVelocityInGround(sb, toSimTKVec3(x_b));
      // moving point: R x_b' qdot_c
      if (p.kind == PathPointKind::Moving && p.coordinate >= 0)
        v += B.getBodyRotation(sb) * toSimTKVec3(dx_b) * qdot[p.coordinate];
      xdot.push_back(fromSimTKVec3(v));
    }
    VecX xdot_a;
    const std::vector<Vec3>* x_a = &map.x_a;
    if (pathType(mu.path) != PathType::III) {
      calcPathMap(x, &xdot, mu.mass_points, map, mu.name);
      xdot_a = map.J_ax * stackPoints(xdot);
    } else {
      // Type III: the surface frame's pose and motion (path_map.hpp's calcWrapPathMap)
      const PathWrap& w = mu.path.wraps.at(0);
      const SimTK::MobilizedBody& S = w.body >= 0 ? sm_.mobods[w.body] : sm_.matter.getGround();
      const SimTK::Transform X_bs = toTransform(w.E_bs);
      const SimTK::Transform X_GS = S.getBodyTransform(sb) * X_bs;
      Mat3 R;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R(r, c) = X_GS.R()[r][c];
      WrapSegmentVelocity v;
      v.xdot1 = xdot[0];
      v.xdot2 = xdot[1];
      v.omega = fromSimTKVec3(S.getBodyAngularVelocity(sb));
      v.pdot = fromSimTKVec3(S.findStationVelocityInGround(sb, X_bs.p()));
      calcWrapPathMap(w.surface, mu.wrap, mu.mass_points, x[0], x[1], R, fromSimTKVec3(X_GS.p()), &v, wmap, mu.name);
      VecX vv(12);
      vv << xdot[0], xdot[1], v.omega, v.pdot;
      xdot_a = wmap.J * vv;
      x_a = &wmap.x_a;
    }
    for (int a = 0; a < mu.mass_points.size(); ++a) {
      x_p[first_particle_[m] + a] = toSimTKVec3((*x_a)[a]);
      v_p[first_particle_[m] + a] = toSimTKVec3(xdot_a.segment<3>(3 * a));
    }
  }
  // set after every read: writing q invalidates the stage the reads above need
  for (size_t k = 0; k < particles_.size(); ++k) {
    particles_[k].setQToFitTranslation(sb, x_p[k]);
    particles_[k].setUToFitLinearVelocity(sb, v_p[k]);
  }
}

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
