#pragma once
// Element kernels of the deformable bodies [D Sec. 4.6.3] in node space (world positions x):
//   - the axial spring of a mass-spring strand [D Eq. 4.88-4.89];
//   - the tetrahedron of co-rotated linear elasticity (Sifakis and Barbic 2012, docs/references.md
//     [79] of [D]): F = Ds Dm^-1, F = R S (polar, R a rotation),
//       Psi(F) = mu |F - R|^2 + lambda/2 tr(R^T F - I)^2,
//       P = dPsi/dF = 2 mu (F - R) + lambda tr(R^T F - I) R,
//     energy V Psi, forces -V P Dm^-T on nodes 1..3 (node 0 the negative sum). Its stiffness is the
//     exact Hessian, with the derivative of the polar rotation (docs/deformable.md §2):
//       R^T dR = [w],  (tr(S) I - S) w = vee(R^T dF - dF^T R),
//       dP = 2 mu dF + lambda tr(R^T dF) R + (lambda tr(S - I) - 2 mu) dR.
// Stiffness here means K = -df/dx (the ForceTerm convention).
#include <array>

#include "core/spatial/types.hpp"

namespace redmax {

/// Axial spring between nodes 0 and 1 with rest length L and stiffness k (J):
/// V = k/2 eps^2, eps = (l - L)/L [D Eq. 4.88]. Returns V; f0 (force on node 0, f1 = -f0)
/// [D Eq. 4.89]; H = -df0/dx0 (the 6x6 stiffness is [H -H; -H H]). l must be positive.
double springEnergyForce(const Vec3& x0, const Vec3& x1, double L, double k, Vec3* f0, Mat3* H);

/// Rotation R (det +1) and symmetric S = R^T F of the polar decomposition of F (through the SVD;
/// an inverted F gets the rotation nearest to it and an S with one negative eigenvalue).
void polarRotation(const Mat3& F, Mat3& R, Mat3& S);

/// Co-rotated energy density Psi(F) and first Piola-Kirchhoff stress P (mu, lambda: Lame).
double corotatedEnergyStress(const Mat3& F, double mu, double lambda, Mat3* P, Mat3* R = nullptr, Mat3* S = nullptr);

/// dP along dF at F with polar factors R, S (exact, including dR).
Mat3 corotatedStressDifferential(const Mat3& R, const Mat3& S, const Mat3& dF, double mu, double lambda);

/// One tetrahedron's nodes x (4), inverse rest shape Dm_inv and rest volume V0: returns the
/// energy V0 Psi; f (12: node forces, 3 per node) and K (12x12, -df/dx) when asked.
double tetEnergyForce(const std::array<Vec3, 4>& x, const Mat3& Dm_inv, double V0, double mu, double lambda,
                      Eigen::Matrix<double, 12, 1>* f, Eigen::Matrix<double, 12, 12>* K);

/// Lame parameters of Young's modulus E (Pa) and Poisson's ratio nu.
double lameMu(double E, double nu);
double lameLambda(double E, double nu);

}  // namespace redmax
