#include "core/muscles/via_point.hpp"

#include <Eigen/LU>

namespace redmax {

Eigen::Matrix<double, 3, 8> calcJ_az(double beta, const Vec3& F) {
  Eigen::Matrix<double, 3, 8> J;
  J.leftCols<3>() = (1.0 - beta) * Mat3::Identity();
  J.middleCols<3>(3) = beta * Mat3::Identity();
  J.col(6) = -(1.0 - beta) * F;
  J.col(7) = -beta * F;
  return J;
}

Eigen::Matrix<double, 3, 8> calcJdot_az(double beta, double betadot, const Vec3& F, const Vec3& Fdot) {
  Eigen::Matrix<double, 3, 8> J;
  J.leftCols<3>() = -betadot * Mat3::Identity();
  J.middleCols<3>(3) = betadot * Mat3::Identity();
  J.col(6) = betadot * F - (1.0 - beta) * Fdot;
  J.col(7) = -betadot * F - beta * Fdot;
  return J;
}

void checkEulerianSegments(const MuscleKinematics& mk, const std::string& muscle_name) {
  for (int i = 0; i + 1 < static_cast<int>(mk.x_w.size()); ++i) {
    if (mk.l[i] > 1e-12 * (1.0 + mk.length)) continue;
    throw MuscleError("muscle '" + muscle_name + "': path segment " + std::to_string(i) +
                      " (between active points " + std::to_string(mk.active[i]) + " and " +
                      std::to_string(mk.active[i + 1]) +
                      ") has zero length here; mass points need distinct consecutive path points");
  }
}

void calcEulerianCoordinates(MuscleKinematics& mk, const std::string& muscle_name) {
  const int P = static_cast<int>(mk.x_w.size());
  const int n = P - 2;
  const int k = static_cast<int>(mk.J_xr.cols());  // compact columns
  if (n < 1) throw std::logic_error("calcEulerianCoordinates: needs at least one internal path point");
  checkEulerianSegments(mk, muscle_name);

  // equal strain: s_i = arc length to i / length
  mk.s.resize(P);
  mk.s[0] = 0.0;
  for (int i = 1; i < P; ++i) mk.s[i] = mk.s[i - 1] + mk.l[i - 1] / mk.length;
  mk.s[P - 1] = 1.0;
  const VecX ds = mk.s.tail(P - 1) - mk.s.head(P - 1);  // Delta s_i (P-1)

  // L (n x n), DeltaS (n x n+1), DeltaXbar (n+1 x 3P) [D Eq. 5.20-5.22]; row r is internal point r+1
  MatX L = MatX::Zero(n, n), dS = MatX::Zero(n, n + 1), dXbar = MatX::Zero(n + 1, 3 * P);
  for (int r = 0; r < n; ++r) {
    const int i = r + 1;
    L(r, r) = mk.l[i - 1] + mk.l[i];
    if (r > 0) L(r, r - 1) = -mk.l[i];
    if (r < n - 1) L(r, r + 1) = -mk.l[i - 1];
    dS(r, i - 1) = -ds[i];
    dS(r, i) = ds[i - 1];
  }
  for (int i = 0; i <= n; ++i) {
    dXbar.block<1, 3>(i, 3 * i) = -mk.dxbar[i].transpose();
    dXbar.block<1, 3>(i, 3 * (i + 1)) = mk.dxbar[i].transpose();
  }
  // J_sx = -L^-1 DeltaS DeltaXbar [D Eq. 5.23]; L is small and tridiagonal, nonsingular for l_i > 0
  const Eigen::PartialPivLU<MatX> Llu(L);
  mk.J_sx = -Llu.solve(dS * dXbar);
  // J_sr = J_sx J_xr on the internal rows; the ends have sdot = 0
  mk.J_sr.setZero(P, k);
  mk.J_sr.middleRows(1, n).noalias() = mk.J_sx * mk.J_xr;

  if (!mk.velocity) return;
  // stacked point velocities and the Eulerian rates sdot = J_sx xdot
  VecX xdot(3 * P);
  for (int i = 0; i < P; ++i) xdot.segment<3>(3 * i) = mk.xdot_w[i];
  mk.sdot.setZero(P);
  mk.sdot.segment(1, n).noalias() = mk.J_sx * xdot;
  const VecX dsdot = mk.sdot.tail(P - 1) - mk.sdot.head(P - 1);  // [D Eq. 5.26]

  // Ldot, DeltaSdot, DeltaXbardot with ldot [D Eq. 5.27] and dxbardot [D Eq. 5.28]
  MatX Ld = MatX::Zero(n, n), dSd = MatX::Zero(n, n + 1), dXbard = MatX::Zero(n + 1, 3 * P);
  for (int r = 0; r < n; ++r) {
    const int i = r + 1;
    Ld(r, r) = mk.ldot[i - 1] + mk.ldot[i];
    if (r > 0) Ld(r, r - 1) = -mk.ldot[i];
    if (r < n - 1) Ld(r, r + 1) = -mk.ldot[i - 1];
    dSd(r, i - 1) = -dsdot[i];
    dSd(r, i) = dsdot[i - 1];
  }
  for (int i = 0; i <= n; ++i) {
    const Vec3& u = mk.dxbar[i];
    const Vec3 ud = (Mat3::Identity() - u * u.transpose()) * (mk.xdot_w[i + 1] - mk.xdot_w[i]) / mk.l[i];
    dXbard.block<1, 3>(i, 3 * i) = -ud.transpose();
    dXbard.block<1, 3>(i, 3 * (i + 1)) = ud.transpose();
  }
  // Jdot_sx = -L^-1 (Ldot J_sx + DeltaSdot DeltaXbar + DeltaS DeltaXbardot) [D Eq. 5.24]
  mk.Jdot_sx = -Llu.solve(Ld * mk.J_sx + dSd * dXbar + dS * dXbard);
  mk.Jdot_sr.setZero(P, k);
  mk.Jdot_sr.middleRows(1, n).noalias() = mk.Jdot_sx * mk.J_xr + mk.J_sx * mk.Jdot_xr;
}

void calcViaPointMassPoints(const MassPoints& mp, MuscleKinematics& mk) {
  const int P = static_cast<int>(mk.x_w.size());
  const int N = mp.size();
  const int k = static_cast<int>(mk.J_xr.cols());  // compact columns
  mk.x_a.resize(N);
  mk.segment.resize(N);
  mk.beta.resize(N);
  if (mk.J_ar.rows() != 3 * N || mk.J_ar.cols() != k) mk.J_ar.resize(3 * N, k);
  if (mk.velocity && (mk.Jdot_ar.rows() != 3 * N || mk.Jdot_ar.cols() != k)) mk.Jdot_ar.resize(3 * N, k);

  for (int a = 0; a < N; ++a) {
    const double s_a = mp.alpha[a];
    // segment holding s_a: the last i with s_i <= s_a (s_a = 1 falls in the last segment)
    int i = 0;
    while (i < P - 2 && mk.s[i + 1] <= s_a) ++i;
    const double ds = mk.s[i + 1] - mk.s[i];
    const double beta = (s_a - mk.s[i]) / ds;                       // [D Eq. 5.29]
    const Vec3 dx = mk.x_w[i + 1] - mk.x_w[i];
    const Vec3 F = dx / ds;                                          // [D Eq. 5.33]
    mk.segment[a] = i;
    mk.beta[a] = beta;
    mk.x_a[a] = (1.0 - beta) * mk.x_w[i] + beta * mk.x_w[i + 1];    // [D Eq. 5.30]

    // J_ar = J_az J_zr, J_zr rows (J_xr(i); J_xr(i+1); J_sr(i); J_sr(i+1)) [D Eq. 5.15, 5.34,
    // 5.36]; J_az's blocks are multiples of I and of F (calcJ_az), applied here as such
    const auto Jx0 = mk.J_xr.middleRows<3>(3 * i);
    const auto Jx1 = mk.J_xr.middleRows<3>(3 * (i + 1));
    const auto Js0 = mk.J_sr.row(i);
    const auto Js1 = mk.J_sr.row(i + 1);
    auto Ja = mk.J_ar.middleRows<3>(3 * a);
    Ja = (1.0 - beta) * Jx0 + beta * Jx1;
    Ja.noalias() -= F * ((1.0 - beta) * Js0 + beta * Js1);
    if (!mk.velocity) continue;

    // betadot [D Eq. 5.31] and Fdot (sign: see header)
    const double betadot = -((1.0 - beta) * mk.sdot[i] + beta * mk.sdot[i + 1]) / ds;
    const Vec3 Fdot = (mk.xdot_w[i + 1] - mk.xdot_w[i] - F * (mk.sdot[i + 1] - mk.sdot[i])) / ds;
    // Jdot_ar = Jdot_az J_zr + J_az Jdot_zr [D Eq. 5.15], Jdot_az from calcJdot_az:
    //   (-betadot I, betadot I, betadot F - (1 - beta) Fdot, -betadot F - beta Fdot)
    auto Jda = mk.Jdot_ar.middleRows<3>(3 * a);
    Jda = betadot * (Jx1 - Jx0) + (1.0 - beta) * mk.Jdot_xr.middleRows<3>(3 * i) +
          beta * mk.Jdot_xr.middleRows<3>(3 * (i + 1));
    Jda.noalias() += (betadot * F - (1.0 - beta) * Fdot) * Js0;
    Jda.noalias() -= (betadot * F + beta * Fdot) * Js1;
    Jda.noalias() -= F * ((1.0 - beta) * mk.Jdot_sr.row(i) + beta * mk.Jdot_sr.row(i + 1));
  }
}

}  // namespace redmax
