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

// ---------------------------------------------------------------------------------------------
// training [D Sec. 5.3.3.1]

#include "core/muscles/wrap/train.hpp"

namespace redmax {
namespace {

TEST(WrapTraining, ThresholdDiscardsNearContactSamplesOnly) {
  const WrapInputBox box = makeDefaultWrapBox(WrapType::Cylinder);
  const WrapOracle oracle = makeExactWrapOracle(WrapType::Cylinder);
  const double threshold = 0.05;
  const WrapTrainingSet set = makeWrapTrainingSet(box, oracle, 2000, threshold, 3);
  EXPECT_EQ(set.X.cols(), 2000);
  EXPECT_GT(set.near_contact, 0);
  EXPECT_GT(set.invalid, 0);
  EXPECT_GT(set.wrapped, 200);
  EXPECT_EQ(set.drawn, 2000 + set.near_contact + set.invalid);
  for (Eigen::Index j = 0; j < set.X.cols(); ++j) {
    const VecX x = set.X.col(j);
    const WrapSample s = oracle(x);
    ASSERT_TRUE(s.valid);
    EXPECT_TRUE(s.l == 0.0 || s.l >= threshold * s.L) << j;
    EXPECT_EQ(s.x, Vec3(set.Y.col(j)));
    EXPECT_TRUE(((x.array() >= box.lo.array()) && (x.array() <= box.hi.array())).all());
  }
}

TEST(WrapTraining, TinyNetworkLearnsAndIsDeterministic) {
  // CI-sized: 2x16, 1500 samples, 10 epochs of batch 32 (430 Adam steps), learning rate 1e-3
  const WrapInputBox box = makeDefaultWrapBox(WrapType::Cylinder);
  const WrapTrainingSet set = makeWrapTrainingSet(box, makeExactWrapOracle(WrapType::Cylinder), 1500, 0.01, 5);
  TrainOptions opt;
  opt.hidden = parseHidden("2x16");
  opt.epochs = 10;
  opt.batch = 32;
  opt.learning_rate = 1e-3;
  opt.seed = 7;
  int calls = 0;
  opt.on_epoch = [&](const TrainEpoch&) { ++calls; };
  std::vector<TrainEpoch> h;
  const Mlp net = trainWrapNetwork(set, box, opt, &h);
  ASSERT_EQ(h.size(), 10u);
  EXPECT_EQ(calls, 10);
  EXPECT_EQ(h.back().steps, 430);
  // loss falls at least 2x from the first epoch's mean to the last validation value (measured: 0.83 -> 0.28)
  EXPECT_LT(h.back().val_mse, 0.5 * h.front().train_mse);
  EXPECT_LT(h.back().train_mse, 0.5 * h.front().train_mse);
  // the untrained network is much worse than the trained one on fresh samples
  const WrapTrainingSet test = makeWrapTrainingSet(box, makeExactWrapOracle(WrapType::Cylinder), 500, 0.0, 99);
  TrainOptions none = opt;
  none.epochs = 0;
  const Mlp untrained = trainWrapNetwork(set, box, none);
  EXPECT_LT(calcWrapNetworkError(net, test).rms, 0.75 * calcWrapNetworkError(untrained, test).rms);
  // metadata and the box are stored
  EXPECT_EQ(net.meta.at("seed"), "7");
  EXPECT_EQ(net.meta.at("architecture"), "2x16");
  EXPECT_EQ(net.input_min, box.lo);
  EXPECT_EQ(net.input_names[7], "radius");
  // same seed: the same network bit for bit; another seed: a different one
  Mlp again = trainWrapNetwork(set, box, opt);
  again.meta = net.meta;  // the wall time differs
  EXPECT_TRUE(again.identical(net));
  TrainOptions other = opt;
  other.seed = 8;
  EXPECT_FALSE(trainWrapNetwork(set, box, other).identical(net));
}

TEST(WrapTraining, ParallelLabellingKeepsTheSerialSet) {
  const WrapInputBox box = makeDefaultWrapBox(WrapType::Sphere);
  const WrapOracle oracle = makeExactWrapOracle(WrapType::Sphere);
  const WrapTrainingSet a = makeWrapTrainingSet(box, oracle, 3000, 0.05, 11, 1);
  const WrapTrainingSet b = makeWrapTrainingSet(box, oracle, 3000, 0.05, 11, 3);
  EXPECT_EQ(a.X, b.X);
  EXPECT_EQ(a.Y, b.Y);
  EXPECT_EQ(a.drawn, b.drawn);
  EXPECT_EQ(a.invalid, b.invalid);
  EXPECT_EQ(a.near_contact, b.near_contact);
  EXPECT_EQ(a.wrapped, b.wrapped);
}

TEST(WrapTraining, ShardedGradientsAreTheSerialOnesAndThreadCountFree) {
  const WrapInputBox box = makeDefaultWrapBox(WrapType::Cylinder);
  const WrapTrainingSet set = makeWrapTrainingSet(box, makeExactWrapOracle(WrapType::Cylinder), 800, 0.01, 5);
  TrainOptions opt;
  opt.hidden = parseHidden("2x16");
  opt.learning_rate = 1e-3;
  opt.seed = 3;
  // one Adam step over the whole training part: the sharded gradient sums to the serial one, so
  // the weights agree to rounding (Adam's first step is lr * g / (|g| + eps) elementwise)
  opt.epochs = 1;
  opt.batch = 1000;
  opt.threads = 1;
  opt.shards = 1;
  const Mlp serial = trainWrapNetwork(set, box, opt);
  opt.shards = 5;
  const Mlp sharded = trainWrapNetwork(set, box, opt);
  for (int l = 0; l < serial.layers(); ++l) {
    EXPECT_LT((serial.weights(l) - sharded.weights(l)).cwiseAbs().maxCoeff(), 1e-12) << "layer " << l;
    EXPECT_LT((serial.biases(l) - sharded.biases(l)).cwiseAbs().maxCoeff(), 1e-12) << "layer " << l;
  }
  // many steps with 4 shards: 1 and 3 threads give the same network bit for bit
  opt.epochs = 4;
  opt.batch = 32;
  opt.shards = 4;
  opt.threads = 1;
  const Mlp t1 = trainWrapNetwork(set, box, opt);
  opt.threads = 3;
  Mlp t3 = trainWrapNetwork(set, box, opt);
  t3.meta = t1.meta;  // wall time differs
  EXPECT_TRUE(t3.identical(t1));
  EXPECT_NE(t1.meta.at("adam").find("shards 4"), std::string::npos);
}

TEST(WrapTraining, InitContinuesFromANetwork) {
  const WrapInputBox box = makeDefaultWrapBox(WrapType::Cylinder);
  const WrapTrainingSet set = makeWrapTrainingSet(box, makeExactWrapOracle(WrapType::Cylinder), 1500, 0.01, 5);
  TrainOptions opt;
  opt.hidden = parseHidden("2x16");
  opt.epochs = 8;
  opt.batch = 32;
  opt.learning_rate = 1e-3;
  std::vector<TrainEpoch> h1, h2;
  const Mlp first = trainWrapNetwork(set, box, opt, &h1);
  // zero epochs from `first` returns its weights unchanged; more epochs start from its loss
  TrainOptions cont = opt;
  cont.init = &first;
  cont.epochs = 0;
  Mlp zero = trainWrapNetwork(set, box, cont);
  EXPECT_TRUE(zero.weights(0) == first.weights(0));
  zero.meta = first.meta;  // the wall time differs
  EXPECT_TRUE(zero.identical(first));  // every layer, and the normalisation
  // the first run's normalisation is kept on another training set (its own statistics differ)
  const WrapTrainingSet other = makeWrapTrainingSet(box, makeExactWrapOracle(WrapType::Cylinder), 300, 0.01, 6);
  const Mlp moved = trainWrapNetwork(other, box, cont);
  EXPECT_TRUE(moved.input_mean == first.input_mean && moved.input_scale == first.input_scale);
  EXPECT_TRUE(moved.output_mean == first.output_mean && moved.output_scale == first.output_scale);
  TrainOptions fresh = opt;  // without init the statistics are the set's own: the check above can fail
  fresh.epochs = 0;
  EXPECT_FALSE(trainWrapNetwork(other, box, fresh).input_mean == first.input_mean);
  cont.epochs = 4;
  trainWrapNetwork(set, box, cont, &h2);
  EXPECT_LT(h2.front().train_mse, 0.8 * h1.front().train_mse);  // not a fresh start
  EXPECT_LT(h2.back().val_mse, 1.2 * h1.back().val_mse);
  // another architecture is refused
  TrainOptions wrong = cont;
  wrong.hidden = parseHidden("3x16");
  EXPECT_THROW(trainWrapNetwork(set, box, wrong), std::invalid_argument);
}

TEST(WrapTraining, ParseHidden) {
  EXPECT_EQ(parseHidden("6x256"), std::vector<int>(6, 256));
  EXPECT_EQ(parseHidden("64-32"), (std::vector<int>{64, 32}));
  EXPECT_THROW(parseHidden("6x"), std::invalid_argument);
  EXPECT_THROW(parseHidden("0x8"), std::invalid_argument);
  EXPECT_THROW(parseHidden("abc"), std::invalid_argument);
}

}  // namespace
}  // namespace redmax

// ---------------------------------------------------------------------------------------------
// the networks committed under osim_models/networks

#include <filesystem>

namespace redmax {
namespace {

TEST(WrapTraining, CommittedNetworksApproximateTheExactLibrary) {
  const std::filesystem::path dir = std::filesystem::path(REDMAX_SOURCE_DIR) / "osim_models" / "networks";
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".txt") continue;
    const Mlp net = Mlp::load(entry.path().string());
    // the file says how to reproduce it
    ASSERT_TRUE(net.meta.count("command") && net.meta.count("seed") && net.meta.count("surface")) << entry.path();
    EXPECT_EQ(net.meta.at("command").rfind("redmax train-wrap ", 0), 0u);
    const WrapType type = parseWrapType(net.meta.at("surface"));
    ASSERT_EQ(net.inputs(), wrapInputSize(type));
    // fresh samples (all of them, also near the contact change): the network must beat the
    // straight path p1 + alpha (p2 - p1), which is exact for every sample that does not wrap
    // (measured: cylinder straight 0.215, 3x64 0.114, 2x64 0.149; sphere straight 0.122, 3x64 0.103;
    // a 1x32 cylinder network, 0.216, was no better than the straight path and is not kept)
    const WrapInputBox box = makeDefaultWrapBox(type);
    const WrapTrainingSet test = makeWrapTrainingSet(box, makeExactWrapOracle(type), 3000, 0.0, 4242);
    WrapTrainingSet straight = test;
    for (Eigen::Index j = 0; j < test.X.cols(); ++j) {
      const VecX x = test.X.col(j);
      straight.Y.col(j) = x.segment<3>(0) + x[6] * (x.segment<3>(3) - x.segment<3>(0));
    }
    double se = 0.0;
    for (Eigen::Index j = 0; j < test.X.cols(); ++j) se += (straight.Y.col(j) - test.Y.col(j)).squaredNorm();
    const double straight_rms = std::sqrt(se / test.X.cols());
    const double net_rms = calcWrapNetworkError(net, test).rms;
    EXPECT_LT(net_rms, 0.9 * straight_rms) << entry.path() << ": network " << net_rms << ", straight " << straight_rms;
    // and agrees with the error recorded in the file (other fresh samples) within 25%
    EXPECT_NEAR(net_rms, std::stod(net.meta.at("test_rms_m")), 0.25 * net_rms) << entry.path();
    ++checked;
  }
  EXPECT_GE(checked, 2);
}

}  // namespace
}  // namespace redmax
