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
  const Mat4 E = expTwist(xi, theta);
  const Mat6 A = AdInv(E);
  const double thetadot = grad.dot(qdot);
  // the previous S, carried into the new child frame, is needed by both updates
  const Mat6X AS = A * out.S;
  out.Sdot = A * out.Sdot - ad(xi * thetadot) * AS + xi * graddot.transpose();
  out.S = AS + xi * grad.transpose();
  out.Q = out.Q * E;
}

}  // namespace redmax::detail
