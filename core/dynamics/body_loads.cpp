#include "core/dynamics/body_loads.hpp"

namespace redmax {

void addBodyWrench(const Model& model, const SkeletonWorkspace& ws, int body, const Vec6& w_i, VecX& f) {
  if (body < 0) return;
  for (int a : model.ancestors(body)) {
    const JointSlot& sa = model.joints()[a];
    if (sa.nq == 0) continue;
    f.segment(sa.q_index, sa.nq).noalias() += ws.J_mr.block(6 * body, sa.q_index, 6, sa.nq).transpose() * w_i;
  }
}

void addPointForce(const Model& model, const SkeletonWorkspace& ws, int body, const Vec3& point_i,
                   const Vec3& force_w, VecX& f) {
  if (body < 0) return;  // force on the world does nothing
  const Mat3 R = ws.E_wi[body].topLeftCorner<3, 3>();
  addBodyWrench(model, ws, body, Gamma(point_i).transpose() * (R.transpose() * force_w), f);
}

void addBodyTorque(const Model& model, const SkeletonWorkspace& ws, int body, const Vec3& torque_w, VecX& f) {
  if (body < 0) return;
  const Mat3 R = ws.E_wi[body].topLeftCorner<3, 3>();
  Vec6 w;
  w << R.transpose() * torque_w, Vec3::Zero();
  addBodyWrench(model, ws, body, w, f);
}

void addExternalLoads(const Model& model, const SkeletonWorkspace& ws, const ExternalLoads& loads, VecX& f) {
  for (const PointForce& p : loads.point_forces) addPointForce(model, ws, p.body, p.point_i, p.force_w, f);
  for (const BodyWrench& b : loads.wrenches) {
    if (b.body < 0) continue;
    const Mat3 R = ws.E_wi[b.body].topLeftCorner<3, 3>();
    Vec6 w;
    w << R.transpose() * b.torque_w, R.transpose() * b.force_w;
    addBodyWrench(model, ws, b.body, w, f);
  }
}

double externalLoadsPotential(const SkeletonWorkspace& ws, const ExternalLoads& loads) {
  double V = 0.0;
  for (const PointForce& p : loads.point_forces)
    if (p.body >= 0) V -= p.force_w.dot(transformPoint(ws.E_wi[p.body], p.point_i));
  return V;
}

void BodyLoads::addForce(const Model& model, const State&, const TermContext& ctx, VecX& f) const {
  addExternalLoads(model, ctx.sk, *this, f);
}

double BodyLoads::potentialEnergy(const Model&, const State&, const TermContext& ctx) const {
  return externalLoadsPotential(ctx.sk, *this);
}

}  // namespace redmax
