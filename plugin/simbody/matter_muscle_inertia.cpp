#include "plugin/simbody/matter_muscle_inertia.hpp"

#include <stdexcept>

#include "core/muscles/path_kinematics.hpp"
#include "plugin/simbody/simtk_convert.hpp"

namespace redmax::simbody {

namespace {

bool isMoving(const PathPoint& pt) { return pt.kind == PathPointKind::Moving && pt.coordinate >= 0; }

}  // namespace

std::string simbodyWrapShapeUnsupportedReason(const Muscle& mu) {
  if (mu.mass_points.size() == 0) return "";
  // the Simbody side moves points at fixed arc fractions only (core/muscles/fibre_placement.hpp)
  if (mu.fibre.enabled())
    return "muscle '" + mu.name + "': fibre-following mass placement is computed by the core only (--engine core, "
           "or --mass-placement uniform)";
  if (hasNodePoints(mu.path))
    return "muscle '" + mu.name + "': a path through deformable nodes is the core's only (Simbody has no such nodes)";
  return "";
}

MatterMuscleInertia::MatterMuscleInertia(const SimTK::SimbodyMatterSubsystem& matter, MatterMap map,
                                         const Model& model, std::vector<Muscle> muscles, const Vec3& gravity)
    : matter_(matter), map_(std::move(map)), muscles_(std::move(muscles)), gravity_(gravity) {
  if (static_cast<int>(map_.mobod_of_body.size()) != model.nb() ||
      static_cast<int>(map_.q_of_coordinate.size()) != model.nr())
    throw std::invalid_argument("MatterMuscleInertia: the map has " + std::to_string(map_.mobod_of_body.size()) +
                                " bodies and " + std::to_string(map_.q_of_coordinate.size()) +
                                " coordinates, the model " + std::to_string(model.nb()) + " and " +
                                std::to_string(model.nr()));
  for (int m = 0; m < static_cast<int>(muscles_.size()); ++m) {
    const Muscle& mu = muscles_[m];
    validateMuscle(model, mu);
    if (mu.mass_points.size() == 0) continue;
    const std::string why = simbodyWrapShapeUnsupportedReason(mu);
    if (!why.empty()) throw ModelError(why);
    // every body and coordinate the path depends on must be in the foreign system
    for (const PathPoint& pt : mu.path.points) {
      if (pt.body >= 0 && !map_.mobod_of_body[pt.body].isValid())
        throw std::invalid_argument("muscle '" + mu.name + "': body '" + model.bodies()[pt.body].name +
                                    "' has no mobilized body in the Simbody system");
      if (pt.coordinate >= 0 && map_.q_of_coordinate[pt.coordinate] < 0)
        throw std::invalid_argument("muscle '" + mu.name + "': coordinate '" + model.coordinates()[pt.coordinate].name +
                                    "' has no q in the Simbody system");
    }
    Entry e;
    e.muscle = m;
    // Type III: every wrap surface frame is a frame on its body (X_GS = X_GB X_bs)
    for (const PathWrap& w : mu.path.wraps) {
      if (w.body >= 0 && !map_.mobod_of_body[w.body].isValid())
        throw std::invalid_argument("muscle '" + mu.name + "': the body of wrap object '" + w.name +
                                    "' has no mobilized body in the Simbody system");
      e.surface_body.push_back(w.body);
      e.X_bs.push_back(toTransform(w.E_bs));
    }
    e.frames.resize(e.X_bs.size());
    entries_.push_back(std::move(e));
  }
  q_core_.setZero(model.nr());
}

const SimTK::MobilizedBody& MatterMuscleInertia::mobod(int body) const {
  return body >= 0 ? matter_.getMobilizedBody(map_.mobod_of_body[body]) : matter_.getGround();
}

double MatterMuscleInertia::totalMass() const {
  double m = 0.0;
  for (const Muscle& mu : muscles_) m += mu.mass_points.totalMass();
  return m;
}

std::vector<Vec3> MatterMuscleInertia::massPointPositions() const {
  std::vector<Vec3> out;
  for (const Entry& e : entries_) {
    out.insert(out.end(), e.gmap.x_a.begin(), e.gmap.x_a.end());
  }
  return out;
}

const std::vector<Vec3>& MatterMuscleInertia::massPointPositions(int e) const {
  return entries_.at(e).gmap.x_a;
}

void MatterMuscleInertia::evaluate(const SimTK::State& state, bool velocity) {
  const SimTK::Vector& q = matter_.getQ(state);
  for (int c = 0; c < q_core_.size(); ++c)
    q_core_[c] = map_.q_of_coordinate[c] >= 0 ? q[map_.q_of_coordinate[c]] : 0.0;
  const SimTK::Vector* qdot = velocity ? &matter_.getQDot(state) : nullptr;

  for (Entry& e : entries_) {
    const Muscle& mu = muscles_[e.muscle];
    const auto& points = mu.path.points;
    // active set: conditional points by OpenSim's rule, on the state's q
    activePathPoints(mu.path, q_core_, e.active);
    const int P = static_cast<int>(e.active.size());
    e.x.resize(P);
    e.x_b.resize(P);
    e.dx_b.resize(P);
    e.ddx_b.resize(P);
    if (velocity) e.xdot.resize(P);
    for (int i = 0; i < P; ++i) {
      const PathPoint& pt = points[e.active[i]];
      calcPointLocation(pt, q_core_, e.x_b[i], e.dx_b[i], e.ddx_b[i]);
      const SimTK::MobilizedBody& B = mobod(pt.body);
      const SimTK::Vec3 station = toSimTKVec3(e.x_b[i]);
      e.x[i] = fromSimTKVec3(B.findStationLocationInGround(state, station));
      if (!velocity) continue;
      SimTK::Vec3 v = B.findStationVelocityInGround(state, station);
      // moving point: the location's own rate through its coordinate, R x_b' qdot_c
      if (isMoving(pt)) v += B.getBodyRotation(state) * toSimTKVec3(e.dx_b[i]) * (*qdot)[map_.q_of_coordinate[pt.coordinate]];
      e.xdot[i] = fromSimTKVec3(v);
    }
    // the surface frames (Type III): pose, angular velocity and origin velocity (Ground)
    for (size_t w = 0; w < e.frames.size(); ++w) {
      const SimTK::MobilizedBody& S = mobod(e.surface_body[w]);
      const SimTK::Transform X_GS = S.getBodyTransform(state) * e.X_bs[w];
      SurfaceFrameState& f = e.frames[w];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) f.R(r, c) = X_GS.R()[r][c];
      f.p = fromSimTKVec3(X_GS.p());
      if (!velocity) continue;
      f.omega = fromSimTKVec3(S.getBodyAngularVelocity(state));
      f.pdot = fromSimTKVec3(S.findStationVelocityInGround(state, e.X_bs[w].p()));
    }
    calcGeneralPathMap(mu, e.active, e.x, velocity ? &e.xdot : nullptr, e.frames, e.gmap);
  }
}

void MatterMuscleInertia::calcGeneralizedForces(const SimTK::State& state, const SimTK::Vector& udot,
                                                SimTK::Vector& f_u) {
  const int nu = matter_.getNumMobilities();
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
      bodies_.push_back(mobod(pt.body).getMobilizedBodyIndex());
      stations_.push_back(toSimTKVec3(e.x_b[i]));
      any_moving = any_moving || isMoving(pt);
    }
  }
  matter_.multiplyByStationJacobian(state, bodies_, stations_, udot, JSudot_);
  matter_.calcBiasForStationJacobian(state, bodies_, stations_, bias_);
  forces_.resize(static_cast<int>(bodies_.size()));
  // Type III surfaces: one frame per wrap object, spatial acceleration JF udot + JFdot u
  frame_bodies_.clear();
  frame_origins_.clear();
  for (const Entry& e : entries_)
    for (size_t w = 0; w < e.X_bs.size(); ++w) {
      frame_bodies_.push_back(mobod(e.surface_body[w]).getMobilizedBodyIndex());
      frame_origins_.push_back(e.X_bs[w].p());
    }
  if (!frame_bodies_.empty()) {
    matter_.multiplyByFrameJacobian(state, frame_bodies_, frame_origins_, udot, JFudot_);
    matter_.calcBiasForFrameJacobian(state, frame_bodies_, frame_origins_, frame_bias_);
    frame_forces_.resize(static_cast<int>(frame_bodies_.size()));
  }
  int frame = 0;  // the first frame of the current entry
  SimTK::Vector qddot, f_q;
  if (any_moving) {
    matter_.calcQDotDot(state, udot, qddot);
    f_q.resize(matter_.getQ(state).size());
    f_q = 0.0;
  }
  const SimTK::Vector& qdot = matter_.getQDot(state);

  int row = 0;  // first station of the current muscle in the batch
  for (Entry& e : entries_) {
    const Muscle& mu = muscles_[e.muscle];
    const int P = static_cast<int>(e.active.size());
    VecX xddot(3 * P);
    for (int i = 0; i < P; ++i) {
      SimTK::Vec3 a = JSudot_[row + i] + bias_[row + i];
      const PathPoint& pt = mu.path.points[e.active[i]];
      if (isMoving(pt)) {
        // 2 w x (R x_b' qdot_c) + R (x_b'' qdot_c^2 + x_b' qddot_c)
        const SimTK::MobilizedBody& B = mobod(pt.body);
        const SimTK::Rotation& R = B.getBodyRotation(state);
        const int sq = map_.q_of_coordinate[pt.coordinate];
        const double qd = qdot[sq], qdd = qddot[sq];
        const SimTK::Vec3 v_rel = R * toSimTKVec3(e.dx_b[i]) * qd;
        a += 2.0 * SimTK::cross(B.getBodyAngularVelocity(state), v_rel) +
             R * toSimTKVec3(e.ddx_b[i] * qd * qd + e.dx_b[i] * qdd);
      }
      xddot.segment<3>(3 * i) = fromSimTKVec3(a);
    }
    // a_a = J vdot + bias (path_map.hpp), vdot = (xddot, (alpha_w, pddot_w) per wrap)
    const int W = static_cast<int>(e.X_bs.size());
    VecX vdot(3 * P + 6 * W);
    vdot.head(3 * P) = xddot;
    for (int w = 0; w < W; ++w) {
      const SimTK::SpatialVec A = JFudot_[frame + w] + frame_bias_[frame + w];
      vdot.segment<6>(3 * P + 6 * w) << fromSimTKVec3(A[0]), fromSimTKVec3(A[1]);
    }
    const VecX a_a = e.gmap.J * vdot + e.gmap.bias;
    // f_a = m_a (a_a - g) [D Eq. 5.6-5.7], pulled back to the path points
    VecX f_a(a_a.size());
    for (int a = 0; a < mu.mass_points.size(); ++a)
      f_a.segment<3>(3 * a) = mu.mass_points.mass[a] * (a_a.segment<3>(3 * a) - gravity_);
    const VecX F_v = e.gmap.J.transpose() * f_a;
    // each wrap's (omega, pdot) columns: a torque and a force at its surface origin
    for (int w = 0; w < W; ++w, ++frame) {
      const int c = 3 * P + 6 * w;
      frame_forces_[frame] = SimTK::SpatialVec(toSimTKVec3(F_v.segment<3>(c)), toSimTKVec3(F_v.segment<3>(c + 3)));
    }
    for (int i = 0; i < P; ++i) {
      const Vec3 F = F_v.segment<3>(3 * i);
      forces_[row + i] = toSimTKVec3(F);
      const PathPoint& pt = mu.path.points[e.active[i]];
      if (isMoving(pt)) {
        // the point's column through q_c: (R x_b')^T F, conjugate to qdot_c
        const SimTK::MobilizedBody& B = mobod(pt.body);
        f_q[map_.q_of_coordinate[pt.coordinate]] += ~(B.getBodyRotation(state) * toSimTKVec3(e.dx_b[i])) * toSimTKVec3(F);
      }
    }
    row += P;
  }
  // station forces to u space: JS^T F; the q-space part through qdot = N u: N^T f_q
  matter_.multiplyByStationJacobianTranspose(state, bodies_, stations_, forces_, f_u);
  if (!frame_bodies_.empty()) {
    SimTK::Vector f_frames;
    matter_.multiplyByFrameJacobianTranspose(state, frame_bodies_, frame_origins_, frame_forces_, f_frames);
    f_u += f_frames;
  }
  if (any_moving) {
    SimTK::Vector f_extra;
    matter_.multiplyByN(state, true, f_q, f_extra);
    f_u += f_extra;
  }
}

void MatterMuscleInertia::calcMassPointMotion(const SimTK::State& state, std::vector<Vec3>& x,
                                              std::vector<Vec3>& xdot) {
  evaluate(state, true);
  x.clear();
  xdot.clear();
  for (const Entry& e : entries_) {
    const VecX xdot_a = e.gmap.J * stackGeneralVelocities(e.xdot, e.frames);
    x.insert(x.end(), e.gmap.x_a.begin(), e.gmap.x_a.end());
    for (int a = 0; a < static_cast<int>(e.gmap.x_a.size()); ++a) xdot.push_back(xdot_a.segment<3>(3 * a));
  }
}

double MatterMuscleInertia::kineticEnergy(const SimTK::State& state) {
  std::vector<Vec3> x, xdot;
  calcMassPointMotion(state, x, xdot);
  double T = 0.0;
  size_t k = 0;
  for (const Entry& e : entries_)
    for (double m : muscles_[e.muscle].mass_points.mass) T += 0.5 * m * xdot[k++].squaredNorm();
  return T;
}

double MatterMuscleInertia::potentialEnergy(const SimTK::State& state) {
  evaluate(state, false);
  double V = 0.0;
  for (const Entry& e : entries_) {
    const MassPoints& mp = muscles_[e.muscle].mass_points;
    for (int a = 0; a < mp.size(); ++a) V -= mp.mass[a] * gravity_.dot(e.gmap.x_a[a]);
  }
  return V;
}

}  // namespace redmax::simbody
