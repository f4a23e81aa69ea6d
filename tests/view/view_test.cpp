// view/view.hpp: the shapes drawn for bodies without a mesh.
#include "view/view.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace redmax::view {
namespace {

// closed form: a solid ellipsoid of mass m and semi-axes (a, b, c) has I_x = m (b^2 + c^2) / 5, ...
TEST(InertiaEllipsoid, RecoversTheSemiAxesOfASolidEllipsoid) {
  const double m = 3.2;
  const Vec3 abc(0.05, 0.21, 0.08);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 I(m * (abc[1] * abc[1] + abc[2] * abc[2]) / 5, m * (abc[0] * abc[0] + abc[2] * abc[2]) / 5,
               m * (abc[0] * abc[0] + abc[1] * abc[1]) / 5);
  Vec3 radii;
  Mat3 axes;
  inertiaEllipsoid(m, R * I.asDiagonal() * R.transpose(), radii, axes);
  EXPECT_NEAR((axes.transpose() * axes - Mat3::Identity()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(axes.determinant(), 1.0, 1e-12);
  // each semi-axis along its own direction: the body-frame ellipsoid matrix is rebuilt exactly
  const Mat3 shape = axes * radii.cwiseAbs2().asDiagonal() * axes.transpose();
  const Mat3 expected = R * abc.cwiseAbs2().asDiagonal() * R.transpose();
  EXPECT_NEAR((shape - expected).norm(), 0.0, 1e-12 * expected.norm());
}

TEST(InertiaEllipsoid, RodsKeepAVisibleThicknessAndMasslessBodiesNone) {
  // a thin rod along x (I_x = 0): the flat directions get 2% of the length
  const double m = 1.0, L = 1.0;
  Vec3 radii;
  Mat3 axes;
  inertiaEllipsoid(m, Vec3(0, m * L * L / 12, m * L * L / 12).asDiagonal(), radii, axes);
  const double half = std::sqrt(5.0 * (2 * m * L * L / 12) / (2 * m));  // 0.6455 of the length
  EXPECT_NEAR(radii.maxCoeff(), half, 1e-12);
  EXPECT_NEAR(radii.minCoeff(), 0.02 * half, 1e-12);
  inertiaEllipsoid(0.0, Mat3::Identity(), radii, axes);
  EXPECT_EQ(radii, Vec3::Zero());
}

}  // namespace
}  // namespace redmax::view
