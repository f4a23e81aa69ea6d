// OpenSim's MuscleAnalysis and Actuation (docs/analyze.md): muscle states after equilibrium per
// frame, and the tables OpenSim prints from them.
#include "converter/analyze/muscle_analysis.hpp"

#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/QR>

#include "core/dynamics/muscle_force_term.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::osim {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

hill::MuscleOutput nanOutput() {
  hill::MuscleOutput o;
  o.tendon_force = o.activation = o.fiber_length = o.fiber_velocity = o.pennation_angle = kNaN;
  o.tendon_length = o.active_fiber_force = o.passive_fiber_force = kNaN;
  o.normalized_fiber_length = o.normalized_fiber_velocity = kNaN;
  return o;
}
}  // namespace

double pennationAngularVelocity(const hill::MuscleOutput& o) {
  // MuscleFixedWidthPennationModel::calcPennationAngularVelocity: 0 for an unpennated muscle
  if (!(std::abs(o.pennation_angle) > 0.0)) return std::isnan(o.pennation_angle) ? kNaN : 0.0;
  return -(o.fiber_velocity / o.fiber_length) * std::tan(o.pennation_angle);
}

double tendonVelocity(const hill::MuscleOutput& o, double path_speed) {
  const double c = std::cos(o.pennation_angle), s = std::sin(o.pennation_angle);
  return path_speed - o.fiber_velocity * c + o.fiber_length * s * pennationAngularVelocity(o);
}

MatX constraintCoupling(const Model& skeleton, const std::vector<std::shared_ptr<const Constraint>>& constraints,
                        const VecX& q, const std::vector<int>& coordinates) {
  const int nr = skeleton.nr();
  MatX C = MatX::Identity(nr, nr);
  int rows = 0;
  for (const auto& c : constraints) rows += c->rows();
  if (rows == 0) return C;
  State st;
  st.q = q;
  st.qdot = VecX::Zero(nr);
  SkeletonWorkspace sk(skeleton);
  calcKinematics(skeleton, st, sk);
  MatX G(rows, nr);
  VecX rhs(rows);
  int r = 0;
  for (const auto& c : constraints) {
    c->calcAcceleration(skeleton, st, sk, G.middleRows(r, c->rows()), rhs.segment(r, c->rows()));
    r += c->rows();
  }
  // projection onto the null space of G: e - G^+ G e (G^+ also for redundant rows)
  const MatX Gp = Eigen::CompleteOrthogonalDecomposition<MatX>(G).pseudoInverse();
  for (int k : coordinates) {
    VecX u = VecX::Unit(nr, k) - Gp * G.col(k);
    C.col(k) = u / u[k];  // OpenSim divides by the coordinate's own speed after the projection
  }
  return C;
}

double fiberActivePower(const hill::MuscleOutput& o) {
  const double damping = o.passive_fiber_force - o.passive_fiber_elastic_force;
  return -(o.active_fiber_force + damping) * o.fiber_velocity;
}

double fiberPassivePower(const hill::MuscleOutput& o) { return -o.passive_fiber_elastic_force * o.fiber_velocity; }

struct MuscleFrameEvaluator::Impl {
  std::unique_ptr<MuscleForceTerm> term;  // muscles with a force model, as forward applies them
  std::vector<int> actuated;              // per muscle: its index in term, or -1
};

MuscleFrameEvaluator::MuscleFrameEvaluator(const Model& skeleton, const MusculoskeletalModel& geometry)
    : skeleton_(skeleton), geometry_(geometry), impl_(new Impl) {
  impl_->term = std::make_unique<MuscleForceTerm>(skeleton, geometry.muscles(), geometry.muscleModels());
  int k = 0;
  for (const auto& m : geometry.muscleModels()) impl_->actuated.push_back(m ? k++ : -1);
}

MuscleFrameEvaluator::~MuscleFrameEvaluator() { delete impl_; }

MuscleFrame MuscleFrameEvaluator::evaluate(const MuscleFrameInput& in, bool equilibrate) const {
  const Model& skel = skeleton_;
  const auto& muscles = geometry_.muscles();
  const auto& models = geometry_.muscleModels();
  const int nm = static_cast<int>(muscles.size()), nr = skel.nr();
  MuscleFrame f;
  f.time = in.time;
  f.q = in.q;
  f.u = in.u;
  f.controls = in.controls;
  f.length.resize(nm);
  f.speed.resize(nm);
  f.dl_dq = MatX::Zero(nm, nr);
  f.out.assign(static_cast<size_t>(nm), nanOutput());
  f.z.resize(static_cast<size_t>(nm));

  State st;
  st.t = in.time;
  st.q = in.q;
  st.qdot = in.u;
  SkeletonWorkspace sk(skel);
  calcKinematics(skel, st, sk);
  std::vector<Mat4> E;
  calcBodyPoses(skel, in.q, E);
  VecX row, qh;
  constexpr double h = 1e-6;  // central differences for paths without a force model (rad or m)
  for (int m = 0; m < nm; ++m) {
    const int k = impl_->actuated[static_cast<size_t>(m)];
    if (k >= 0) {
      double len = 0.0, spd = 0.0;
      impl_->term->calcPath(skel, st, sk, k, len, spd, row);
      f.length[m] = len;
      f.speed[m] = spd;
      f.dl_dq.row(m) = row.transpose();
    } else {
      f.length[m] = calcPathLength(skel, muscles[m].path, in.q, E);
      std::vector<Mat4> Eh;
      for (int j = 0; j < nr; ++j) {
        qh = in.q;
        qh[j] += h;
        calcBodyPoses(skel, qh, Eh);
        const double lp = calcPathLength(skel, muscles[m].path, qh, Eh);
        qh[j] = in.q[j] - h;
        calcBodyPoses(skel, qh, Eh);
        f.dl_dq(m, j) = (lp - calcPathLength(skel, muscles[m].path, qh, Eh)) / (2 * h);
      }
      f.speed[m] = f.dl_dq.row(m).dot(in.u);
      continue;
    }
    const hill::MuscleModel& model = *models[static_cast<size_t>(m)];
    std::vector<double>& z = f.z[static_cast<size_t>(m)];
    z.assign(static_cast<size_t>(model.numStates()), 0.0);
    if (!z.empty()) model.defaultState(z.data());
    if (static_cast<int>(in.z_given.size()) > m)
      for (size_t j = 0; j < z.size() && j < in.z_given[static_cast<size_t>(m)].size(); ++j)
        if (!std::isnan(in.z_given[static_cast<size_t>(m)][j])) z[j] = in.z_given[static_cast<size_t>(m)][j];
    // the control: the setup's controllers when it has any; without, a muscle without an
    // activation state sees control 0 and one with it its activation (the excitation then only
    // moves zdot, which no output reads)
    double excitation = 0.0;
    const auto& names = model.stateNames();
    for (size_t j = 0; j < names.size(); ++j)
      if (names[j] == "activation") excitation = z[j];
    if (in.excitation.size() == nm) excitation = in.excitation[m];  // the setup's controllers
    const hill::MusculotendonInput mi{f.length[m], f.speed[m], excitation};
    if (equilibrate) {
      try {
        model.equilibrate(mi, z.data());
      } catch (const std::exception& e) {
        f.failures.push_back(muscles[m].name + ": " + e.what());
      }
    }
    std::vector<double> zdot(z.size());
    try {
      model.calc(z.data(), mi, f.out[static_cast<size_t>(m)], zdot.data());
    } catch (const std::exception& e) {
      f.out[static_cast<size_t>(m)] = nanOutput();
      f.failures.push_back(muscles[m].name + ": " + e.what());
    }
  }
  return f;
}

std::string muscleAnalysisDescription() {
  return "\nThis analysis gathers basic information about muscles during a simulation (e.g., forces, tendon "
         "lengths, moment arms, etc).\nUnits are S.I. units (second, meters, Newtons, ...)\nIf the header above "
         "contains a line with 'inDegrees', this indicates whether rotational values are in degrees (yes) or "
         "radians (no).\n\n";
}

std::string actuationDescription() {
  return "\nThis file contains either the forces, speeds, or powers developed\nby the actuators of a model during a "
         "simulation.\n\nAn actuator force is a generalized force, meaning that it can be either a force (N) or a "
         "torque (Nm).\n\nAn actuator speed is the rate at which an actuator shortens. Depending on the actuator,\na "
         "speed can be either a translational speed (m/s) or an angular speed (deg/s or rad/s).\n\nAn actuator power "
         "(Watts) is the rate at which an actuator does work.  Positive power means\nthat the actuator is delivering "
         "energy to the model; negative power means that the actuator\nis absorbing energy from the model.\n\nUnits "
         "are S.I. units (second, meters, Newtons, ...)\nIf the header above contains a line with 'inDegrees', this "
         "indicates whether rotational values are in degrees (yes) or radians (no).\n\n";
}

namespace {

// MuscleAnalysis's moment arm of muscle m about core coordinate q (MomentArmSolver)
double momentArm(const MuscleFrame& f, size_t m, int q) {
  const auto row = f.dl_dq.row(static_cast<Eigen::Index>(m));
  if (f.coupling.size() == 0) return -row[q];
  return -row.dot(f.coupling.col(q));
}

template <class F>
Storage table(const std::string& name, const std::vector<std::string>& labels,
              const std::vector<const MuscleFrame*>& frames, F value) {
  Storage s;
  s.name = name;
  s.version = 1;
  s.labels = labels;
  s.data.resize(static_cast<Eigen::Index>(frames.size()), static_cast<Eigen::Index>(labels.size()));
  for (size_t r = 0; r < frames.size(); ++r) {
    s.time.push_back(frames[r]->time);
    for (size_t c = 0; c < labels.size(); ++c)
      s.data(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = value(*frames[r], c);
  }
  return s;
}

}  // namespace

std::vector<Storage> muscleAnalysisTables(const MuscleAnalysisSettings& settings, const MuscleAnalysisColumns& cols,
                                          const std::vector<const MuscleFrame*>& frames) {
  std::vector<Storage> out;
  const auto& L = cols.muscles;
  auto m = [&](size_t c) { return static_cast<size_t>(cols.muscle_index[c]); };
  auto o = [&](const MuscleFrame& f, size_t c) -> const hill::MuscleOutput& { return f.out[m(c)]; };
  // OpenSim's reporting gaps (docs/analyze.md): the deprecated classes fill only part of
  // MuscleDynamicsInfo and FiberVelocityInfo, RigidTendonMuscle no pennation angular velocity
  auto cls = [&](size_t c) -> const std::string& { return cols.classes[c]; };
  auto deprecated = [&](size_t c) {
    const std::string& k = cls(c);
    return k.size() > 11 && k.compare(k.size() - 11, 11, "_Deprecated") == 0;
  };
  auto rigid = [&](size_t c) { return cls(c) == "RigidTendonMuscle"; };
  if (settings.compute_moments) {
    for (size_t k = 0; k < cols.coordinates.size(); ++k) {
      const int q = cols.coordinate_index[k];
      out.push_back(table("MomentArm_" + cols.coordinates[k], L, frames,
                          [&](const MuscleFrame& f, size_t c) { return momentArm(f, m(c), q); }));
    }
    for (size_t k = 0; k < cols.coordinates.size(); ++k) {
      const int q = cols.coordinate_index[k];
      out.push_back(table("Moment_" + cols.coordinates[k], L, frames, [&](const MuscleFrame& f, size_t c) {
        return momentArm(f, m(c), q) * o(f, c).tendon_force;
      }));
    }
  }
  out.push_back(table("PennationAngle", L, frames, [&](const MuscleFrame& f, size_t c) { return o(f, c).pennation_angle; }));
  out.push_back(table("Length", L, frames, [&](const MuscleFrame& f, size_t c) { return f.length[static_cast<Eigen::Index>(m(c))]; }));
  out.push_back(table("FiberLength", L, frames, [&](const MuscleFrame& f, size_t c) { return o(f, c).fiber_length; }));
  out.push_back(table("NormalizedFiberLength", L, frames,
                      [&](const MuscleFrame& f, size_t c) { return o(f, c).normalized_fiber_length; }));
  out.push_back(table("TendonLength", L, frames, [&](const MuscleFrame& f, size_t c) { return o(f, c).tendon_length; }));
  out.push_back(table("FiberVelocity", L, frames, [&](const MuscleFrame& f, size_t c) { return o(f, c).fiber_velocity; }));
  out.push_back(table("NormFiberVelocity", L, frames,
                      [&](const MuscleFrame& f, size_t c) { return o(f, c).normalized_fiber_velocity; }));
  out.push_back(table("PennationAngularVelocity", L, frames,
                      [&](const MuscleFrame& f, size_t c) {
                        return deprecated(c) || rigid(c) ? kNaN : pennationAngularVelocity(o(f, c));
                      }));
  out.push_back(table("TendonForce", L, frames, [&](const MuscleFrame& f, size_t c) { return o(f, c).tendon_force; }));
  out.push_back(table("FiberForce", L, frames, [&](const MuscleFrame& f, size_t c) {
    return deprecated(c) ? kNaN : o(f, c).active_fiber_force + o(f, c).passive_fiber_force;
  }));
  out.push_back(table("ActiveFiberForce", L, frames, [&](const MuscleFrame& f, size_t c) { return o(f, c).active_fiber_force; }));
  out.push_back(table("PassiveFiberForce", L, frames, [&](const MuscleFrame& f, size_t c) { return o(f, c).passive_fiber_force; }));
  out.push_back(table("ActiveFiberForceAlongTendon", L, frames, [&](const MuscleFrame& f, size_t c) {
    return o(f, c).active_fiber_force * std::cos(o(f, c).pennation_angle);
  }));
  out.push_back(table("PassiveFiberForceAlongTendon", L, frames, [&](const MuscleFrame& f, size_t c) {
    return o(f, c).passive_fiber_force * std::cos(o(f, c).pennation_angle);
  }));
  out.push_back(table("FiberActivePower", L, frames, [&](const MuscleFrame& f, size_t c) { return fiberActivePower(o(f, c)); }));
  out.push_back(table("FiberPassivePower", L, frames, [&](const MuscleFrame& f, size_t c) { return fiberPassivePower(o(f, c)); }));
  out.push_back(table("TendonPower", L, frames, [&](const MuscleFrame& f, size_t c) {
    if (deprecated(c)) return kNaN;
    if (rigid(c)) return 0.0;
    return -o(f, c).tendon_force * tendonVelocity(o(f, c), f.speed[static_cast<Eigen::Index>(m(c))]);
  }));
  out.push_back(table("MuscleActuatorPower", L, frames, [&](const MuscleFrame& f, size_t c) {
    return deprecated(c) ? kNaN : -o(f, c).tendon_force * f.speed[static_cast<Eigen::Index>(m(c))];
  }));
  return out;
}

VecX actuatorSpeeds(const std::vector<ActuationColumn>& columns, const SkeletonWorkspace& sk) {
  VecX v = VecX::Constant(static_cast<Eigen::Index>(columns.size()), kNaN);
  // a body's angular velocity and a station's velocity in ground (twists are in body coordinates)
  auto omega = [&](int b) -> Vec3 {
    if (b < 0) return Vec3::Zero();
    return sk.E_wi[static_cast<size_t>(b)].topLeftCorner<3, 3>() * sk.phi[static_cast<size_t>(b)].head<3>();
  };
  for (size_t c = 0; c < columns.size(); ++c) {
    const ActuationColumn& a = columns[c];
    if (a.rigid == ActuationColumn::Rigid::Point) {
      if (a.body_a < 0) {
        v[static_cast<Eigen::Index>(c)] = 0.0;
        continue;
      }
      const Vec6& phi = sk.phi[static_cast<size_t>(a.body_a)];
      const Vec3 vel_i = phi.tail<3>() + phi.head<3>().cross(a.vector);
      v[static_cast<Eigen::Index>(c)] = vel_i.norm();  // |R v| = |v|
    } else if (a.rigid == ActuationColumn::Rigid::Torque) {
      v[static_cast<Eigen::Index>(c)] = (omega(a.body_a) - omega(a.body_b)).dot(a.vector);
    }
  }
  return v;
}

std::vector<Storage> actuationTables(const std::vector<ActuationColumn>& columns,
                                     const std::vector<const MuscleFrame*>& frames) {
  std::vector<std::string> labels;
  for (const auto& c : columns) labels.push_back(c.name);
  auto force = [&](const MuscleFrame& f, size_t c) {
    const ActuationColumn& a = columns[c];
    if (a.muscle) return f.out[static_cast<size_t>(a.path)].tendon_force;
    return a.control >= 0 && a.control < f.controls.size() ? f.controls[a.control] * a.optimal_force : 0.0;
  };
  auto speed = [&](const MuscleFrame& f, size_t c) {
    const ActuationColumn& a = columns[c];
    if (a.path >= 0) return f.speed[a.path];
    if (a.coordinate >= 0) return f.u[a.coordinate];
    if (a.rigid != ActuationColumn::Rigid::None && static_cast<Eigen::Index>(c) < f.actuator_speed.size())
      return f.actuator_speed[static_cast<Eigen::Index>(c)];
    return kNaN;
  };
  std::vector<Storage> out;
  out.push_back(table("ActuatorForces", labels, frames, force));
  out.push_back(table("ActuatorSpeeds", labels, frames, speed));
  // PathActuator::getPower = -F ldot; ScalarActuator::getPower = F speed (0 at control 0, whatever the speed)
  out.push_back(table("ActuatorPowers", labels, frames, [&](const MuscleFrame& f, size_t c) {
    const double F = force(f, c);
    if (F == 0.0) return 0.0;
    return columns[c].path >= 0 ? -F * speed(f, c) : F * speed(f, c);
  }));
  return out;
}

}  // namespace redmax::osim
