#include "converter/id/core_id_engine.hpp"

#include <algorithm>
#include <sstream>
#include <type_traits>
#include <variant>

#include <Eigen/Dense>

#include "core/dynamics/muscle_term.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::osim {

namespace {

// T = blockdiag(R, R) S (rows = 6) or R S_w (rows = 3), and Tdot along qdot (file comment)
void mapFromKinematics(const JointKinematics& jk, int rows, const VecJ& qdot, MatJ& T, MatJ* Tdot) {
  const Mat3 R = jk.Q.topLeftCorner<3, 3>();
  const int nq = static_cast<int>(jk.S.cols());
  T.resize(rows, nq);
  T.topRows(3) = R * jk.S.topRows(3);
  if (rows == 6) T.bottomRows(3) = R * jk.S.bottomRows(3);
  if (!Tdot) return;
  // d/dt R = R [w], w the angular velocity of M in F expressed in M
  const Vec3 w = jk.S.topRows(3) * qdot;
  const Mat3 Rw = R * skew(w);
  Tdot->resize(rows, nq);
  Tdot->topRows(3) = Rw * jk.S.topRows(3) + R * jk.Sdot.topRows(3);
  if (rows == 6) Tdot->bottomRows(3) = Rw * jk.S.bottomRows(3) + R * jk.Sdot.bottomRows(3);
}

template <class J>
void mapOf(const J& j, const VecJ& q, const VecJ& qdot, MatJ& T, MatJ* Tdot, int rows) {
  JointKinematics jk;
  jk.resize(j.nq());
  j.calc(q, qdot, jk);
  mapFromKinematics(jk, rows, qdot, T, Tdot);
}

// returns false when the joint has no OpenSim speed map; computes it when T is given
bool speedMap(const Joint& joint, const VecJ& q, const VecJ& qdot, MatJ* T, MatJ* Tdot) {
  return std::visit(
      [&](const auto& j) -> bool {
        using J = std::decay_t<decltype(j)>;
        if constexpr (std::is_same_v<J, SphericalEuler> || std::is_same_v<J, Ellipsoid>) {
          // Ball / Ellipsoid mobilizer: u = w_FM expressed in F
          if (T) mapOf(j, q, qdot, *T, Tdot, 3);
          return true;
        } else if constexpr (std::is_same_v<J, Free3D>) {
          // Free mobilizer: u = [w_FM; v_FM], both in F, rotation first as q is
          if (j.layout != FreeLayout::RotationFirst) return false;
          if (T) mapOf(j, q, qdot, *T, Tdot, 6);
          return true;
        } else if constexpr (std::is_same_v<J, Reversed>) {
          // u keeps its meaning under Direction::Reverse: the inner joint's map
          return j.inner && speedMap(*j.inner, q, qdot, T, Tdot);
        } else if constexpr (std::is_same_v<J, Composite>) {
          // Scapulothoracic: an Ellipsoid followed by parts whose speeds are their q rates
          if (j.parts.empty()) return false;
          const int n0 = j.parts.front().nq(), n = j.nq();
          MatJ T0, Tdot0;
          if (!speedMap(j.parts.front(), q.head(n0), qdot.head(n0), T ? &T0 : nullptr,
                        Tdot ? &Tdot0 : nullptr))
            return false;
          if (T) {
            T->setIdentity(n, n);
            T->topLeftCorner(n0, n0) = T0;
          }
          if (Tdot) {
            Tdot->setZero(n, n);
            Tdot->topLeftCorner(n0, n0) = Tdot0;
          }
          return true;
        } else {
          return false;
        }
      },
      joint.v);
}

}  // namespace

void calcOpenSimSpeedMap(const Joint& joint, const VecJ& q, const VecJ& qdot, MatJ& T, MatJ* Tdot) {
  if (!speedMap(joint, q, qdot, &T, Tdot))
    throw IdEngineError("a " + joint.typeName() +
                        " joint has no OpenSim speed map (only ball, free and ellipsoid joints put "
                        "Euler-angle rates into Simbody's u)");
}

bool hasOpenSimSpeedMap(const Joint& joint) {
  const VecJ z = VecJ::Zero(joint.nq());
  return speedMap(joint, z, z, nullptr, nullptr);
}

CoreIdEngine::CoreIdEngine(Model model, IdEngineOptions options)
    : system_(std::move(model)),
      loads_(std::make_shared<BodyLoads>()),
      ws_(system_.model()),
      options_(std::move(options)) {
  const Model& m = system_.model();
  if (!options_.rates_as_u.empty() && static_cast<int>(options_.rates_as_u.size()) != m.nb())
    throw IdEngineError("engine options name " + std::to_string(options_.rates_as_u.size()) +
                        " joints; the model has " + std::to_string(m.nb()));
  for (int j = 0; j < m.nb(); ++j) {
    if (!options_.marked(j)) continue;
    if (!hasOpenSimSpeedMap(m.joints()[j].joint))
      throw IdEngineError("joint '" + m.joints()[j].name + "' (" + m.joints()[j].joint.typeName() +
                          ") cannot take OpenSim's Euler-rate speeds");
    marked_.push_back(j);
  }
  T_.resize(marked_.size());
  system_.addTerm(loads_);
  E_wi_.resize(m.nb());
}

CoreIdEngine::CoreIdEngine(Model model, std::vector<Muscle> muscles, IdEngineOptions options)
    : CoreIdEngine(std::move(model), std::move(options)) {
  const bool any_mass = std::any_of(muscles.begin(), muscles.end(),
                                    [](const Muscle& m) { return m.mass_points.size() > 0; });
  if (!any_mass) return;
  auto term = std::make_shared<MuscleTerm>(system_.model(), std::move(muscles));
  muscle_mass_ = term->totalMass();
  system_.addTerm(std::move(term));
}

void CoreIdEngine::calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                                         const std::vector<IdLoadSample>& loads, VecX& tau) {
  const Model& m = system_.model();
  const int nr = m.nr();
  if (q.size() != nr || v.size() != nr || vdot.size() != nr)
    throw IdEngineError("inverse dynamics needs " + std::to_string(nr) + " coordinates, speeds and "
                        "accelerations");
  state_.t = t;
  state_.q = q;
  state_.qdot = v;
  qddot_ = vdot;

  // OpenSim's u -> the core's qdot for marked joints: qdot = T^-1 u, qddot = T^-1 (udot - Tdot qdot)
  for (size_t k = 0; k < marked_.size(); ++k) {
    const JointSlot& slot = m.joints()[marked_[k]];
    const int i0 = slot.q_index, n = slot.nq;
    const VecJ qj = q.segment(i0, n);
    MatJ T, Tdot;
    calcOpenSimSpeedMap(slot.joint, qj, VecJ::Zero(n), T, nullptr);
    Eigen::JacobiSVD<MatJ> svd(T);
    const auto& sv = svd.singularValues();
    if (!(sv(n - 1) > 1e-12 * sv(0))) {
      std::ostringstream os;
      os << "joint '" << slot.name << "' at t = " << t
         << ": the map from Euler-angle rates to angular velocity is singular (gimbal lock)";
      throw IdEngineError(os.str());
    }
    const Eigen::PartialPivLU<MatJ> lu(T);
    const VecJ qdot_j = lu.solve(VecJ(v.segment(i0, n)));
    calcOpenSimSpeedMap(slot.joint, qj, qdot_j, T, &Tdot);
    state_.qdot.segment(i0, n) = qdot_j;
    qddot_.segment(i0, n) = lu.solve(VecJ(vdot.segment(i0, n) - Tdot * qdot_j));
    T_[k] = T;
  }

  // external loads at the current poses, then tau = M qddot - f [D Eq. 4.18]
  calcBodyPoses(m, q, E_wi_);
  resolveLoads(loads, E_wi_, loads_->point_forces, loads_->wrenches);
  tau = system_.inverseDynamics(state_, qddot_, ws_);

  // back to OpenSim's u: tau_u = T^-T tau_qdot
  for (size_t k = 0; k < marked_.size(); ++k) {
    const JointSlot& slot = m.joints()[marked_[k]];
    const MatJ Tt = T_[k].transpose();
    tau.segment(slot.q_index, slot.nq) =
        Eigen::PartialPivLU<MatJ>(Tt).solve(VecJ(tau.segment(slot.q_index, slot.nq)));
  }
}

}  // namespace redmax::osim
