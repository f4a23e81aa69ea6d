#pragma once
// World-frame kinematics of points and frames fixed in a body, shared by the maximal-coordinate
// constraints (point, hinge point, weld). A point x_i in body i moves with
//   xdot_w = R_i Gamma(x_i) phi_i = R_i Gamma(x_i) J_i qdot_r                     [D Eq. 3.13, 4.96]
//   xddot_w = R_i Gamma(x_i) J_i qddot_r + R_i [omega_i] Gamma(x_i) phi_i + R_i Gamma(x_i) Jdot_i qdot_r
// where J_i, Jdot_i are body i's six rows of J_mr, Jdot_mr; the last two terms are the bias
// (velocity-product) acceleration that goes to the right-hand side [D Eq. 4.100-4.101].
#include <string>

#include "core/skeleton/model.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax::detail {

using Mat3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;

/// A point fixed in a body (or in the world when body < 0), everything in world coordinates.
struct PointKinematics {
  Vec3 p = Vec3::Zero();        // position
  Vec3 v = Vec3::Zero();        // velocity
  Vec3 a_bias = Vec3::Zero();   // acceleration at qddot_r = 0
  Mat3X J;                      // dp/dq_r = dv/dqdot_r                  (3 x nr)
};

/// Angular velocity of a body (zero for the world), world coordinates.
struct RotationKinematics {
  Mat3 R = Mat3::Identity();    // body orientation R_wi
  Vec3 omega = Vec3::Zero();    // angular velocity
  Vec3 alpha_bias = Vec3::Zero();  // angular acceleration at qddot_r = 0
  Mat3X J;                      // d omega / d qdot_r                    (3 x nr)
};

/// needs Stage::Velocity; qdot_r is the state's qdot (nr)
void calcPointKinematics(const Model& model, const SkeletonWorkspace& ws, const VecX& qdot_r, int body,
                         const Vec3& x_i, PointKinematics& out);
void calcRotationKinematics(const Model& model, const SkeletonWorkspace& ws, const VecX& qdot_r,
                            int body, RotationKinematics& out);

/// throws ModelError unless -1 <= body < nb (what: the constraint's name, for the message)
void checkBodyIndex(const Model& model, int body, const std::string& what);
/// throws ModelError if the model does not have the size the constraint was built for
void checkModelSize(const Model& model, int nb, int nr, const std::string& what);

}  // namespace redmax::detail
