#pragma once
// Fixed-size Eigen aliases used across redmax. Twists are (omega; nu) and wrenches (tau; f),
// both in body coordinates unless a suffix says otherwise [D Eq. 3.5, 3.12].
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace redmax {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat3 = Eigen::Matrix3d;
using Mat4 = Eigen::Matrix4d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat3x6 = Eigen::Matrix<double, 3, 6>;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

/// 6 x n matrix with at most 6 columns, stored inline (no heap): joint Jacobians S and Sdot.
using Mat6X = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;
/// vector of at most 6 entries, stored inline: one joint's q or qdot.
using VecJ = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

}  // namespace redmax
