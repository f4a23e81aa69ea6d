#include "core/dynamics/speed_map.hpp"

#include <type_traits>
#include <variant>

#include "core/dynamics/id_engine.hpp"
#include "core/joints/joint_kinematics.hpp"

namespace redmax {

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

}  // namespace redmax
