#include "core/dynamics/constraints/body_point.hpp"

#include "core/spatial/se3.hpp"

namespace redmax::detail {

void calcPointKinematics(const Model& model, const SkeletonWorkspace& ws, const VecX& qdot_r, int body,
                         const Vec3& x_i, PointKinematics& out) {
  const int nr = model.nr();
  out.J.setZero(3, nr);
  if (body < 0) {
    // a world point: fixed, no Jacobian
    out.p = x_i;
    out.v.setZero();
    out.a_bias.setZero();
    return;
  }
  const Mat3 R = ws.E_wi[body].topLeftCorner<3, 3>();
  const Mat3x6 RG = R * Gamma(x_i);
  const auto J_i = ws.J_mr.middleRows<6>(6 * body);
  const auto Jdot_i = ws.Jdot_mr.middleRows<6>(6 * body);
  const Vec6& phi = ws.phi[body];
  out.p = transformPoint(ws.E_wi[body], x_i);
  out.J.noalias() = RG * J_i;
  out.v = RG * phi;
  // Rdot = R [omega] [D Eq. 3.9]; phidot = J qddot + Jdot qdot
  out.a_bias = R * (phi.head<3>().cross(Gamma(x_i) * phi)) + RG * (Jdot_i * qdot_r);
}

void calcRotationKinematics(const Model& model, const SkeletonWorkspace& ws, const VecX& qdot_r,
                            int body, RotationKinematics& out) {
  const int nr = model.nr();
  out.J.setZero(3, nr);
  if (body < 0) {
    out.R.setIdentity();
    out.omega.setZero();
    out.alpha_bias.setZero();
    return;
  }
  out.R = ws.E_wi[body].topLeftCorner<3, 3>();
  out.J.noalias() = out.R * ws.J_mr.block(6 * body, 0, 3, nr);
  out.omega = out.R * ws.phi[body].head<3>();
  // d/dt (R omega_i) = R (omega_i x omega_i) + R omegadot_i = R omegadot_i
  out.alpha_bias = out.R * (ws.Jdot_mr.block(6 * body, 0, 3, nr) * qdot_r);
}

void checkBodyIndex(const Model& model, int body, const std::string& what) {
  if (body < -1 || body >= model.nb())
    throw ModelError(what + ": body index " + std::to_string(body) + " out of range (model has " +
                     std::to_string(model.nb()) + " bodies; -1 is the world)");
}

void checkModelSize(const Model& model, int nb, int nr, const std::string& what) {
  if (model.nb() != nb || model.nr() != nr)
    throw ModelError(what + ": built for a model with " + std::to_string(nb) + " bodies and " +
                     std::to_string(nr) + " coordinates, used with one of " + std::to_string(model.nb()) +
                     " and " + std::to_string(model.nr()));
}

}  // namespace redmax::detail
