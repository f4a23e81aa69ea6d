// Networks for a model (tools/wrap_training/model_networks.hpp, issue 22): the training set of one
// wrap object holds compact inputs and the displacement of the exact library's point from the
// straight line, does not depend on the thread count, and a network trained on it serves its
// inputs (no fallback) close to the exact library.
#include <gtest/gtest.h>

#include <random>

#include "core/geometry/wrap_surface.hpp"
#include "tools/wrap_training/model_networks.hpp"

namespace redmax {
namespace {

// end points 3-12 radii from a cylinder's axis, on both sides, as a muscle over a joint would have
WrapObjectInputs cylinderInputs(int n, unsigned seed) {
  WrapObjectInputs in;
  in.name = "test_cylinder";
  in.surface = WrapSurface::makeCylinder(0.02, 0.2);  // length 10 radii
  in.muscles = {"m"};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ang(0.0, 3.14159), rad(3.0, 12.0), z(-4.0, 4.0);
  for (int k = 0; k < n; ++k) {
    const double a = ang(rng), r1 = rad(rng), r2 = rad(rng);
    in.q1.emplace_back(r1 * std::cos(a), r1 * std::sin(a), z(rng));
    in.q2.emplace_back(-r2 * std::cos(a + 0.4), -r2 * std::sin(a + 0.4), z(rng));
  }
  return in;
}

TEST(ModelNetworks, TrainingSetHoldsCompactInputsAndDisplacements) {
  const WrapObjectInputs in = cylinderInputs(40, 3);
  const double C = 4.0;
  const WrapTrainingSet set = makeWrapObjectTrainingSet(in, 2000, 0.01, C, 0.05, 7, 1);
  ASSERT_EQ(set.X.cols(), 2000);
  EXPECT_GT(set.wrapped, 100);  // the set exercises wrapping (measured 149)
  const WrapOracle oracle = makeExactWrapOracle(WrapType::Cylinder);
  int straight = 0;
  for (Eigen::Index j = 0; j < set.X.cols(); ++j) {
    const Vec3 u1 = set.X.col(j).segment<3>(0), u2 = set.X.col(j).segment<3>(3);
    ASSERT_LT(u1.norm(), C);
    ASSERT_EQ(set.X(7, j), 1.0);
    const Vec3 q1 = calcCompactWrapInputInverse(u1, C), q2 = calcCompactWrapInputInverse(u2, C);
    const double alpha = set.X(6, j);
    VecX x(8);
    x << q1, q2, alpha, 1.0;
    const WrapSample s = oracle(x);
    ASSERT_TRUE(s.valid);
    // the label is the exact point less the straight one (the inverse map costs ~1e-15 relative)
    EXPECT_LE((set.Y.col(j) - (s.x - (q1 + alpha * (q2 - q1)))).norm(), 1e-9) << j;
    if (!s.wraps) {
      ++straight;
      EXPECT_LE(set.Y.col(j).norm(), 1e-9) << j;  // a straight path has no displacement
    }
  }
  EXPECT_GT(straight, 100);
  // the same set on three threads
  const WrapTrainingSet par = makeWrapObjectTrainingSet(in, 2000, 0.01, C, 0.05, 7, 3);
  EXPECT_EQ(par.X, set.X);
  EXPECT_EQ(par.Y, set.Y);
  // the box covers the inputs, within the ball's bounds
  const WrapInputBox box = makeCompactWrapBox(set, C, 0.1);
  for (int i = 0; i < 6; ++i) {
    EXPECT_LE(box.lo[i], set.X.row(i).minCoeff());
    EXPECT_GE(box.hi[i], set.X.row(i).maxCoeff());
    EXPECT_GE(box.lo[i], -C);
    EXPECT_LE(box.hi[i], C);
  }
}

TEST(ModelNetworks, TrainedNetworkServesItsInputsCloseToTheLibrary) {
  const WrapObjectInputs in = cylinderInputs(60, 5);
  ModelWrapTrainOptions o;
  o.train.hidden = {32, 32, 32};
  o.train.epochs = 40;
  o.train.batch = 64;
  o.train.learning_rate = 3e-3;
  o.samples = 6000;
  WrapErrorStats err;
  const Mlp net = trainWrapObjectNetwork(in, o, &err);
  EXPECT_EQ(net.meta.at("wrap_map"), formatCompactWrapMap(4.0));
  EXPECT_EQ(net.meta.at("wrap_object"), "test_cylinder");
  const std::vector<WrapNetworkCheck> c =
      checkWrapNetworks({in}, [&](const std::string&, WrapType) { return &net; }, {0.1, 0.3, 0.5, 0.7, 0.9});
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].evaluations, 60);
  // the inputs themselves: inside the box, no tangent point beyond the 10-radius length
  EXPECT_EQ(c[0].fallbacks, 0);
  std::printf("[ measured ] fresh-sample RMS %.4g radii (max %.3g); on the inputs RMS %.4g, max %.3g radii\n", err.rms,
              err.max, c[0].rms, c[0].max);
  // measured 0.0135 / 0.092 radii on the inputs (3x32, 40 epochs)
  EXPECT_LT(c[0].rms, 0.03);
  // and without a network every evaluation falls back, by reason
  const auto none = checkWrapNetworks({in}, [](const std::string&, WrapType) { return nullptr; }, {0.5});
  EXPECT_EQ(none[0].fallbacks, 60);
  EXPECT_EQ(none[0].by_reason.at(NetworkWrapFallback::NoNetwork), 60);
}

}  // namespace
}  // namespace redmax
