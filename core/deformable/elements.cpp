#include "core/deformable/elements.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace redmax {

double springEnergyForce(const Vec3& x0, const Vec3& x1, double L, double k, Vec3* f0, Mat3* H) {
  const Vec3 dx = x1 - x0;
  const double l = dx.norm();
  const double eps = (l - L) / L;
  const Vec3 d = dx / l;
  // f0 = k eps / L d [D Eq. 4.89]; df0/d(dx) = k/L (d d^T / L + eps (I - d d^T) / l)
  if (f0) *f0 = (k * eps / L) * d;
  if (H) {
    const Mat3 dd = d * d.transpose();
    *H = (k / L) * (dd / L + (eps / l) * (Mat3::Identity() - dd));
  }
  return 0.5 * k * eps * eps;
}

void polarRotation(const Mat3& F, Mat3& R, Mat3& S) {
  Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 U = svd.matrixU(), V = svd.matrixV();
  Vec3 sigma = svd.singularValues();
  // a rotation, not a reflection: flip the smallest singular direction (sigma sorted descending)
  if (U.determinant() < 0) {
    U.col(2) *= -1;
    sigma[2] *= -1;
  }
  if (V.determinant() < 0) {
    V.col(2) *= -1;
    sigma[2] *= -1;
  }
  R = U * V.transpose();
  S = V * sigma.asDiagonal() * V.transpose();
}

double corotatedEnergyStress(const Mat3& F, double mu, double lambda, Mat3* P, Mat3* Rout, Mat3* Sout) {
  Mat3 R, S;
  polarRotation(F, R, S);
  const double tr = S.trace() - 3.0;
  if (P) *P = 2.0 * mu * (F - R) + lambda * tr * R;
  if (Rout) *Rout = R;
  if (Sout) *Sout = S;
  return mu * (S - Mat3::Identity()).squaredNorm() + 0.5 * lambda * tr * tr;
}

Mat3 corotatedStressDifferential(const Mat3& R, const Mat3& S, const Mat3& dF, double mu, double lambda) {
  // R^T dF = W S + dS with W = R^T dR skew and dS symmetric, so
  // R^T dF - (R^T dF)^T = W S + S W = [(tr(S) I - S) w]
  const Mat3 A = R.transpose() * dF;
  const Mat3 B = A - A.transpose();
  const Vec3 b(B(2, 1), B(0, 2), B(1, 0));
  const Mat3 G = S.trace() * Mat3::Identity() - S;
  const Vec3 w = G.partialPivLu().solve(b);
  Mat3 W;
  W << 0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0;
  const Mat3 dR = R * W;
  // tr(dR^T F) = tr(W^T S) = 0, so d tr(R^T F) = tr(R^T dF)
  return 2.0 * mu * dF + lambda * A.trace() * R + (lambda * (S.trace() - 3.0) - 2.0 * mu) * dR;
}

double tetEnergyForce(const std::array<Vec3, 4>& x, const Mat3& Dm_inv, double V0, double mu, double lambda,
                      Eigen::Matrix<double, 12, 1>* f, Eigen::Matrix<double, 12, 12>* K) {
  Mat3 Ds;
  Ds << x[1] - x[0], x[2] - x[0], x[3] - x[0];
  const Mat3 F = Ds * Dm_inv;
  Mat3 P, R, S;
  const double psi = corotatedEnergyStress(F, mu, lambda, &P, &R, &S);
  // node forces: columns of H = -V0 P Dm^-T on nodes 1..3, node 0 their negative sum
  const Mat3 DmT = Dm_inv.transpose();
  if (f) {
    const Mat3 H = -V0 * P * DmT;
    for (int a = 0; a < 3; ++a) f->segment<3>(3 * (a + 1)) = H.col(a);
    f->segment<3>(0) = -(H.col(0) + H.col(1) + H.col(2));
  }
  if (K) {
    // column j of -df/dx: the force differential of a unit motion of coordinate j
    for (int n = 0; n < 4; ++n) {
      for (int c = 0; c < 3; ++c) {
        Mat3 dDs = Mat3::Zero();
        if (n == 0) dDs.row(c).setConstant(-1.0);
        else dDs(c, n - 1) = 1.0;
        const Mat3 dP = corotatedStressDifferential(R, S, dDs * Dm_inv, mu, lambda);
        const Mat3 dH = V0 * dP * DmT;  // -dH
        for (int a = 0; a < 3; ++a) K->block<3, 1>(3 * (a + 1), 3 * n + c) = dH.col(a);
        K->block<3, 1>(0, 3 * n + c) = -(dH.col(0) + dH.col(1) + dH.col(2));
      }
    }
  }
  return V0 * psi;
}

double lameMu(double E, double nu) { return E / (2.0 * (1.0 + nu)); }
double lameLambda(double E, double nu) { return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)); }

}  // namespace redmax
