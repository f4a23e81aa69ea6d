// converter/build/inertia_fallback: our validity test equals Simbody's own
// (SimTK::Inertia::isValidInertiaMatrix) on random tensors around the boundary, and the fallback
// is OpenSim's isotropic tensor, which Simbody accepts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "converter/build/inertia_fallback.hpp"
#include "core/spatial/se3.hpp"
#include "plugin/simbody/simbody_include.hpp"

namespace redmax::osim {
namespace {

bool simbodyAccepts(const Mat3& I) {
  SimTK::SymMat33 m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c <= r; ++c) m(r, c) = I(r, c);
  return SimTK::Inertia::isValidInertiaMatrix(m);
}

TEST(InertiaFallback, ValidityEqualsSimbodysOwnTest) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0), p(-0.6, 0.6);
  int valid = 0, invalid = 0;
  for (int k = 0; k < 20000; ++k) {
    Mat3 I = Mat3::Zero();
    I(0, 0) = u(rng);
    I(1, 1) = u(rng);
    // a third of the cases sit exactly on the triangle-inequality boundary, perturbed by ~1e-16
    I(2, 2) = k % 3 == 0 ? I(0, 0) + I(1, 1) + (u(rng) - 0.5) * 1e-13 : u(rng) * 2.0;
    if (k % 5 == 0) I(k % 15 == 0 ? 0 : 1, k % 15 == 0 ? 0 : 1) *= -1e-3;  // a negative moment
    const double a = p(rng) * I(0, 0), b = p(rng) * I(1, 1), c = p(rng) * I(2, 2);
    I(0, 1) = I(1, 0) = a;
    I(0, 2) = I(2, 0) = b;
    I(1, 2) = I(2, 1) = c;
    const bool ours = isValidInertia(I);
    ASSERT_EQ(ours, simbodyAccepts(I)) << "case " << k << "\n" << I;
    (ours ? valid : invalid)++;
  }
  // both outcomes are exercised, so the comparison can fail either way
  EXPECT_GT(valid, 1000);
  EXPECT_GT(invalid, 1000);
}

TEST(InertiaFallback, ReplacesOnlyInvalidBodiesWithOpenSimsIsotropicTensor) {
  ModelBuilder b("two");
  Mat3 bad = Vec3(0.001, 0.001, 0.0025).asDiagonal();  // Izz > Ixx + Iyy (like gait2392's toes)
  Mat3 good = Vec3(0.01, 0.02, 0.025).asDiagonal();
  b.addBody("bad", 1.0, Vec3(0.1, 0, 0), bad, -1, "j0", Joint{Revolute{Vec3::UnitZ()}});
  b.addBody("good", 2.0, Vec3(0.1, 0, 0), good, 0, "j1", Joint{Revolute{Vec3::UnitZ()}});
  Model m = b.finalize();
  EXPECT_FALSE(isValidInertia(bad));
  EXPECT_TRUE(isValidInertia(good));
  const auto changed = applyOpenSimInertiaFallback(m);
  ASSERT_EQ(changed.size(), 1u);
  EXPECT_EQ(changed[0], "bad");
  const double diag = std::sqrt(0.001 * 0.001 + 0.001 * 0.001 + 0.0025 * 0.0025) / std::sqrt(3.0);
  EXPECT_NEAR((m.bodies()[0].inertia_com - diag * Mat3::Identity()).norm(), 0.0, 1e-18);
  EXPECT_NEAR((m.bodies()[0].M - spatialInertia(1.0, Vec3(0.1, 0, 0), diag * Mat3::Identity())).norm(), 0.0, 1e-15);
  EXPECT_EQ(m.bodies()[1].inertia_com, good);
  EXPECT_TRUE(simbodyAccepts(m.bodies()[0].inertia_com));
}

}  // namespace
}  // namespace redmax::osim
