#include "core/joints/product_of_exponentials.hpp"

namespace redmax::detail {

Mat4 expTwist(const Vec6& xi, double theta) {
  const Vec3 w = xi.head<3>();
  const Vec3 v = xi.tail<3>();
  if (w.isZero(0.0)) return makeTranslation(v * theta);
  if (v.isZero(0.0)) return makeE(expSO3(w * theta), Vec3::Zero());
  return expSE3(xi * theta);
}

void appendFactor(const Vec6& xi, double theta, const VecJ& grad, const VecJ& graddot,
                  const VecJ& qdot, JointKinematics& out) {
  const Vec3 w = xi.head<3>();
  const Vec3 v = xi.tail<3>();
  const double thetadot = grad.dot(qdot);
  const int n = static_cast<int>(out.S.cols());
  auto St = out.S.topRows<3>(), Sb = out.S.bottomRows<3>();
  auto Sdt = out.Sdot.topRows<3>(), Sdb = out.Sdot.bottomRows<3>();
  // the two factor kinds of OpenSim's joints by their block structure (the general product below
  // does the same arithmetic on full 6 x 6 matrices, four times the work)
  if (w.isZero(0.0)) {
    // translation by p = v theta: Ad(E^-1) = [I 0; -[p] I], ad(xi thetadot) = [0 0; [v thetadot] 0]
    const Vec3 p = v * theta, vd = v * thetadot;
    for (int c = 0; c < n; ++c) {
      const Vec3 st = St.col(c), sdt = Sdt.col(c);
      Sdb.col(c) += v * graddot[c] - vd.cross(st) - p.cross(sdt);
      Sb.col(c) += v * grad[c] - p.cross(st);
    }
    out.Q.topRightCorner<3, 1>() += out.Q.topLeftCorner<3, 3>() * p;
    return;
  }
  if (v.isZero(0.0)) {
    // rotation R about w: Ad(E^-1) = blockdiag(R^T, R^T), ad(xi thetadot) = blockdiag([wd], [wd])
    const Mat3 R = expSO3(w * theta), Rt = R.transpose();
    const Vec3 wd = w * thetadot;
    for (int c = 0; c < n; ++c) {
      const Vec3 at = Rt * St.col(c), ab = Rt * Sb.col(c);
      Sdt.col(c) = Rt * Sdt.col(c) - wd.cross(at) + w * graddot[c];
      Sdb.col(c) = Rt * Sdb.col(c) - wd.cross(ab);
      St.col(c) = at + w * grad[c];
      Sb.col(c) = ab;
    }
    out.Q.topLeftCorner<3, 3>() = out.Q.topLeftCorner<3, 3>() * R;
    return;
  }
  const Mat4 E = expTwist(xi, theta);
  const Mat6 A = AdInv(E);
  // the previous S, carried into the new child frame, is needed by both updates
  const Mat6X AS = A * out.S;
  out.Sdot = A * out.Sdot - ad(xi * thetadot) * AS + xi * graddot.transpose();
  out.S = AS + xi * grad.transpose();
  out.Q = out.Q * E;
}

}  // namespace redmax::detail
