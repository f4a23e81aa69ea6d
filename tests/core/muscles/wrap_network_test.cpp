// The wrap network's evaluation [D Sec. 5.3.3]: input Jacobians [D Eq. 5.44] and their exact time
// derivatives against central differences, the dissertation's forward-difference Jdot [D Eq. 5.58],
// batched against per-point evaluation, and the file format (bit-exact round trip, errors with
// line numbers).
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "core/muscles/wrap/network.hpp"

namespace redmax {
namespace {

bool nearRel(const MatX& a, const MatX& b, double tol) { return (a - b).norm() <= tol * (1.0 + b.norm()); }

// a random network with non-trivial normalisation, so the scaling of J is exercised too
Mlp randomNetwork(unsigned seed) {
  Mlp net(8, {11, 7, 9}, 3, seed);
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int l = 0; l < net.layers(); ++l) net.biases(l) = VecX::NullaryExpr(net.biases(l).size(), [&] { return 0.5 * u(rng); });
  net.input_mean = VecX::NullaryExpr(8, [&] { return u(rng); });
  net.input_scale = VecX::NullaryExpr(8, [&] { return 0.5 + std::abs(u(rng)); });
  net.output_mean = VecX::NullaryExpr(3, [&] { return u(rng); });
  net.output_scale = VecX::NullaryExpr(3, [&] { return 0.2 + std::abs(u(rng)); });
  net.meta["seed"] = std::to_string(seed);
  net.meta["command"] = "redmax train-wrap --surface cylinder --hidden 3x8";
  return net;
}

MatX randomInputs(int n_in, int N, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  return MatX::NullaryExpr(n_in, N, [&] { return u(rng); });
}

TEST(WrapNetwork, JacobianMatchesCentralDifferences) {
  const Mlp net = randomNetwork(3);
  const int N = 13;
  const MatX X = randomInputs(8, N, 4);
  MlpWorkspace ws;
  MatX Y, J;
  net.calcJacobian(X, Y, J, ws);
  ASSERT_EQ(J.rows(), 3);
  ASSERT_EQ(J.cols(), 8 * N);
  const double h = 1e-5;
  for (int i = 0; i < 8; ++i) {
    MatX Xp = X, Xm = X, Yp, Ym;
    Xp.row(i).array() += h;
    Xm.row(i).array() -= h;
    net.calcOutput(Xp, Yp, ws);
    net.calcOutput(Xm, Ym, ws);
    const MatX fd = (Yp - Ym) / (2 * h);
    for (int p = 0; p < N; ++p) {
      const MatX col = J.col(p * 8 + i);
      EXPECT_TRUE(nearRel(col, fd.col(p), 1e-7)) << "input " << i << " point " << p << "\n" << col.transpose()
                                                 << "\n" << fd.col(p).transpose();
    }
  }
}

TEST(WrapNetwork, ExactJacobianDotMatchesCentralDifferencesOfJacobian) {
  const Mlp net = randomNetwork(5);
  const int N = 9;
  const MatX X = randomInputs(8, N, 6);
  const MatX Xdot = randomInputs(8, N, 7);
  MlpWorkspace ws;
  MatX Y, J, Jdot, Y0, J0;
  net.calcJacobianDot(X, Xdot, Y, J, Jdot, ws);
  // the velocity pass must not change positions or Jacobians
  net.calcJacobian(X, Y0, J0, ws);
  EXPECT_TRUE(nearRel(Y, Y0, 1e-15));
  EXPECT_TRUE(nearRel(J, J0, 1e-15));
  const double h = 1e-5;
  MatX Yp, Jp, Ym, Jm;
  net.calcJacobian(X + h * Xdot, Yp, Jp, ws);
  net.calcJacobian(X - h * Xdot, Ym, Jm, ws);
  const MatX fd = (Jp - Jm) / (2 * h);
  for (int p = 0; p < N; ++p)
    EXPECT_TRUE(nearRel(Jdot.middleCols(p * 8, 8), fd.middleCols(p * 8, 8), 1e-7)) << "point " << p;
}

TEST(WrapNetwork, DissertationForwardDifferenceJdotAgreesToFirstOrder) {
  // [D Eq. 5.58] is a forward difference: its error is O(eps), so it halves with eps
  const Mlp net = randomNetwork(8);
  const MatX X = randomInputs(8, 5, 9), Xdot = randomInputs(8, 5, 10);
  MlpWorkspace ws;
  MatX Y, J, Jdot, Yf, Jf, Jdot_fd;
  net.calcJacobianDot(X, Xdot, Y, J, Jdot, ws);
  net.calcJacobianDotFd(X, Xdot, 1e-4, Yf, Jf, Jdot_fd, ws);
  const double e1 = (Jdot_fd - Jdot).norm();
  net.calcJacobianDotFd(X, Xdot, 0.5e-4, Yf, Jf, Jdot_fd, ws);
  const double e2 = (Jdot_fd - Jdot).norm();
  EXPECT_LT(e1, 1e-3 * (1 + Jdot.norm()));
  EXPECT_NEAR(e1 / e2, 2.0, 0.1);  // first order
  EXPECT_TRUE(nearRel(Jf, J, 1e-15));
}

TEST(WrapNetwork, BatchedEqualsPerPoint) {
  const Mlp net = randomNetwork(11);
  const int N = 17;
  const MatX X = randomInputs(8, N, 12), Xdot = randomInputs(8, N, 13);
  MlpWorkspace ws;
  MatX Y, J, Jdot;
  net.calcJacobianDot(X, Xdot, Y, J, Jdot, ws);
  MlpWorkspace ws1;  // separate workspace: a batch of one reuses nothing from the batch of N
  for (int p = 0; p < N; ++p) {
    MatX y, j, jd;
    net.calcJacobianDot(X.col(p), Xdot.col(p), y, j, jd, ws1);
    // matrix-matrix and matrix-vector kernels may sum in different orders: round-off only
    EXPECT_TRUE(nearRel(y, Y.col(p), 1e-14)) << p;
    EXPECT_TRUE(nearRel(j, J.middleCols(p * 8, 8), 1e-14)) << p;
    EXPECT_TRUE(nearRel(jd, Jdot.middleCols(p * 8, 8), 1e-14)) << p;
  }
}

TEST(WrapNetwork, SerialisationRoundTripIsBitExact) {
  const Mlp net = randomNetwork(21);
  const Mlp back = Mlp::fromText(net.toText());
  EXPECT_TRUE(back.identical(net));
  EXPECT_EQ(back.meta.at("command"), "redmax train-wrap --surface cylinder --hidden 3x8");
  // and through a file
  const auto path = (std::filesystem::temp_directory_path() / "redmax_wrap_network_test.txt").string();
  net.save(path);
  const Mlp from_file = Mlp::load(path);
  std::filesystem::remove(path);
  EXPECT_TRUE(from_file.identical(net));
  // identical outputs, bit for bit
  const MatX X = randomInputs(8, 4, 22);
  MlpWorkspace ws;
  MatX Y1, Y2;
  net.calcOutput(X, Y1, ws);
  from_file.calcOutput(X, Y2, ws);
  EXPECT_TRUE((Y1.array() == Y2.array()).all());
  // a changed weight is detected
  Mlp changed = back;
  changed.weights(1)(0, 0) = std::nextafter(changed.weights(1)(0, 0), 10.0);
  EXPECT_FALSE(changed.identical(net));
}

TEST(WrapNetwork, MalformedFilesNameTheLine) {
  const std::string good = randomNetwork(1).toText();
  auto expectError = [](const std::string& text, const std::string& needle) {
    try {
      Mlp::fromText(text, "net.txt");
      ADD_FAILURE() << "accepted: " << needle;
    } catch (const NetworkFormatError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("net.txt:", 0), 0u) << e.what();
    }
  };
  expectError("", "expected 'redmax-mlp'");
  expectError("redmax-mlp 2\n", "net.txt:1: unsupported format version");
  std::string bad = good;
  bad.replace(bad.find("hidden 3 11"), 11, "hidden 3 12");
  expectError(bad, "the architecture needs");
  bad = good;
  bad.replace(bad.find("input_scale "), 12, "input_scale 1 ");
  expectError(bad, "has 9 values, expected 8");
  expectError(good.substr(0, good.rfind('\n', good.size() / 2) + 1), "unexpected end of file");
  bad = good;
  const auto pos = bad.find("layer 1");
  bad.replace(bad.find('\n', pos) + 1, 3, "abc");
  expectError(bad, "is not a finite number");
}

TEST(WrapNetwork, BoxCheck) {
  Mlp net(2, {3}, 1, 1);
  net.input_min = Vec2(0, -1);
  net.input_max = Vec2(1, 1);
  EXPECT_TRUE(net.insideBox(Vec2(0.5, 0)));
  EXPECT_FALSE(net.insideBox(Vec2(1.5, 0)));
  EXPECT_FALSE(net.insideBox(Vec2(0.5, std::nan(""))));
}

}  // namespace
}  // namespace redmax
