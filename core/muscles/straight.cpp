#include "core/muscles/straight.hpp"

namespace redmax {

Eigen::Matrix<double, 3, 6> calcJ_ax(double alpha) {
  Eigen::Matrix<double, 3, 6> J;
  J << (1.0 - alpha) * Mat3::Identity(), alpha * Mat3::Identity();
  return J;
}

void calcStraightMassPoints(const MassPoints& mp, MuscleKinematics& mk) {
  if (mk.x_w.size() != 2) throw std::logic_error("calcStraightMassPoints: needs exactly two active path points");
  const int N = mp.size();
  const int k = static_cast<int>(mk.J_xr.cols());  // compact columns
  mk.x_a.resize(N);
  mk.segment.assign(N, 0);
  mk.beta.resize(N);
  if (mk.J_ar.rows() != 3 * N || mk.J_ar.cols() != k) mk.J_ar.resize(3 * N, k);
  if (mk.velocity && (mk.Jdot_ar.rows() != 3 * N || mk.Jdot_ar.cols() != k)) mk.Jdot_ar.resize(3 * N, k);
  for (int a = 0; a < N; ++a) {
    const double alpha = mp.alpha[a];
    mk.beta[a] = alpha;
    mk.x_a[a] = (1.0 - alpha) * mk.x_w[0] + alpha * mk.x_w[1];
    // J_ar = J_ax J_xr with J_ax = ((1 - alpha) I, alpha I) [D Eq. 5.10], applied as weights
    mk.J_ar.middleRows<3>(3 * a) = (1.0 - alpha) * mk.J_xr.topRows<3>() + alpha * mk.J_xr.bottomRows<3>();
    if (mk.velocity)
      mk.Jdot_ar.middleRows<3>(3 * a) = (1.0 - alpha) * mk.Jdot_xr.topRows<3>() + alpha * mk.Jdot_xr.bottomRows<3>();
  }
}

}  // namespace redmax
