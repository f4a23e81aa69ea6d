#include "plugin/simbody/particle_muscles.hpp"

#include <map>

#include <Eigen/LU>

#include "core/muscles/path_map.hpp"

namespace redmax::simbody {

namespace {

SimTK::Vec3 toSimTKVec3(const Vec3& v) { return SimTK::Vec3(v.x(), v.y(), v.z()); }
Vec3 fromSimTKVec3(const SimTK::Vec3& v) { return Vec3(v[0], v[1], v[2]); }

// one muscle's 3N holonomic equations x_p - x_a(x) = 0 (header)
class PathConstraint : public SimTK::Constraint::Custom::Implementation {
 public:
  PathConstraint(SimTK::SimbodyMatterSubsystem& matter, const Muscle& mu,
                 const std::vector<SimTK::MobilizedBody>& point_bodies,
                 const std::vector<SimTK::MobilizedBody>& particles)
      : Implementation(matter, 3 * mu.mass_points.size(), 0, 0), mp_(mu.mass_points), name_(mu.name) {
    // a body carrying several points is one constrained body
    std::map<int, SimTK::ConstrainedBodyIndex> cb_of;
    for (size_t i = 0; i < point_bodies.size(); ++i) {
      const int b = point_bodies[i].getMobilizedBodyIndex();
      auto it = cb_of.find(b);
      if (it == cb_of.end()) it = cb_of.emplace(b, addConstrainedBody(point_bodies[i])).first;
      point_cb_.push_back(it->second);
      station_.push_back(toSimTKVec3(mu.path.points[i].location));
    }
    for (const SimTK::MobilizedBody& p : particles) particle_cb_.push_back(addConstrainedBody(p));
    x_.resize(point_cb_.size());
    xdot_.resize(point_cb_.size());
  }

  Implementation* clone() const override { return new PathConstraint(*this); }

  void calcPositionErrors(const SimTK::State&, const SimTK::Array_<SimTK::Transform, SimTK::ConstrainedBodyIndex>& X_AB,
                          const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                          SimTK::Array_<SimTK::Real>& perr) const override {
    for (size_t i = 0; i < x_.size(); ++i) x_[i] = fromSimTKVec3(findStationLocation(X_AB, point_cb_[i], station_[i]));
    calcPathMap(x_, nullptr, mp_, map_, name_);
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& p = X_AB[particle_cb_[a]].p();
      for (int k = 0; k < 3; ++k) perr[3 * a + k] = p[k] - map_.x_a[a][k];
    }
  }

  void calcPositionDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& V_AB,
                             const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                             SimTK::Array_<SimTK::Real>& pverr) const override {
    for (size_t i = 0; i < x_.size(); ++i) {
      x_[i] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], station_[i]));
      xdot_[i] = fromSimTKVec3(findStationVelocity(s, V_AB, point_cb_[i], station_[i]));
    }
    calcPathMap(x_, nullptr, mp_, map_, name_);
    // xdot_a = J_ax xdot [D Eq. 5.4]
    const VecX xdot_a = map_.J_ax * stackPoints(xdot_);
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& v = V_AB[particle_cb_[a]][1];
      for (int k = 0; k < 3; ++k) pverr[3 * a + k] = v[k] - xdot_a[3 * a + k];
    }
  }

  void calcPositionDotDotErrors(const SimTK::State& s, const SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& A_AB,
                                const SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&,
                                SimTK::Array_<SimTK::Real>& paerr) const override {
    VecX xddot(3 * static_cast<int>(x_.size()));
    for (size_t i = 0; i < x_.size(); ++i) {
      x_[i] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], station_[i]));
      xdot_[i] = fromSimTKVec3(findStationVelocityFromState(s, point_cb_[i], station_[i]));
      xddot.segment<3>(3 * static_cast<int>(i)) = fromSimTKVec3(findStationAcceleration(s, A_AB, point_cb_[i], station_[i]));
    }
    calcPathMap(x_, &xdot_, mp_, map_, name_);
    // a_a = J_ax xddot + Jdot_ax xdot [D Eq. 5.5]
    const VecX a_a = calcMassPointAccelerations(map_, xddot);
    for (int a = 0; a < mp_.size(); ++a) {
      const SimTK::Vec3& acc = A_AB[particle_cb_[a]][1];
      for (int k = 0; k < 3; ++k) paerr[3 * a + k] = acc[k] - a_a[3 * a + k];
    }
  }

  void addInPositionConstraintForces(const SimTK::State& s, const SimTK::Array_<SimTK::Real>& lambda,
                                     SimTK::Array_<SimTK::SpatialVec, SimTK::ConstrainedBodyIndex>& bodyForcesInA,
                                     SimTK::Array_<SimTK::Real, SimTK::ConstrainedQIndex>&) const override {
    for (size_t i = 0; i < x_.size(); ++i) x_[i] = fromSimTKVec3(findStationLocationFromState(s, point_cb_[i], station_[i]));
    calcPathMap(x_, nullptr, mp_, map_, name_);
    // G^T lambda with G = (I on the particles, -J_ax on the path points)
    VecX l(3 * mp_.size());
    for (int r = 0; r < l.size(); ++r) l[r] = lambda[r];
    for (int a = 0; a < mp_.size(); ++a)
      addInStationForce(s, particle_cb_[a], SimTK::Vec3(0), toSimTKVec3(l.segment<3>(3 * a)), bodyForcesInA);
    const VecX F = -(map_.J_ax.transpose() * l);
    for (size_t i = 0; i < x_.size(); ++i)
      addInStationForce(s, point_cb_[i], station_[i], toSimTKVec3(F.segment<3>(3 * static_cast<int>(i))), bodyForcesInA);
  }

 private:
  MassPoints mp_;
  std::string name_;
  std::vector<SimTK::ConstrainedBodyIndex> point_cb_, particle_cb_;
  std::vector<SimTK::Vec3> station_;
  mutable std::vector<Vec3> x_, xdot_;
  mutable PathMap map_;
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
    for (const PathPoint& p : mu.path.points)
      if (p.kind != PathPointKind::Fixed)
        throw SimbodyBuildError("muscle '" + mu.name + "': point '" + p.name +
                                "' is conditional or moving; Simbody particles support fixed path points only");
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
    for (const PathPoint& p : mu.path.points)
      point_bodies.push_back(p.body >= 0 ? sm.mobods[p.body] : SimTK::MobilizedBody(sm.matter.updGround()));
    SimTK::Constraint::Custom(new PathConstraint(sm.matter, mu, point_bodies, mine));
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
  PathMap map;
  for (size_t m = 0; m < muscles_.size(); ++m) {
    if (first_particle_[m] < 0) continue;
    const Muscle& mu = muscles_[m];
    std::vector<Vec3> x, xdot;
    for (const PathPoint& p : mu.path.points) {
      const SimTK::MobilizedBody& B = p.body >= 0 ? sm_.mobods[p.body] : sm_.matter.getGround();
      x.push_back(fromSimTKVec3(B.findStationLocationInGround(sb, toSimTKVec3(p.location))));
      xdot.push_back(fromSimTKVec3(B.findStationVelocityInGround(sb, toSimTKVec3(p.location))));
    }
    calcPathMap(x, &xdot, mu.mass_points, map, mu.name);
    const VecX xdot_a = map.J_ax * stackPoints(xdot);
    for (int a = 0; a < mu.mass_points.size(); ++a) {
      x_p[first_particle_[m] + a] = toSimTKVec3(map.x_a[a]);
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
