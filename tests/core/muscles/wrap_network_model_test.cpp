// The trained network as a run-time wrap model (core/muscles/wrap/network_model.hpp, issue 7):
// J, Jdot and the fraction derivatives of the scaled network against central differences, on its
// own and through the chain rule of a surface on a moving body; every fallback reason gives the
// smooth model's result exactly and is counted and reported once per muscle; the wrapping double
// pendulum and a group of varied pendulums on one committed network conserve energy to integrator
// error (tight rk45).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <unistd.h>
#include <random>
#include <string>
#include <vector>

#include "core/muscles/wrap/network_model.hpp"
#include "tools/wrap_training/train.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/spatial/se3.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"
#include "validation/scenes/wrap_pendulums.hpp"

namespace redmax {
namespace {

std::shared_ptr<const Mlp> committedNet(const std::string& file) {
  return loadWrapNetwork(std::string(REDMAX_SOURCE_DIR) + "/osim_models/networks/" + file);
}

// |A - B| <= tol |B| (+ a floor far below any entry that matters)
::testing::AssertionResult closeRel(const MatX& A, const MatX& B, double tol, const std::string& what) {
  const double diff = (A - B).norm(), ref = B.norm();
  if (diff <= tol * ref + 1e-13) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << what << ": |diff| " << diff << " |ref| " << ref << " rel " << diff / ref;
}

// stacked (3 x 6N) Jacobians / (3 x N) vectors of a point set
MatX stackJ(const std::vector<Eigen::Matrix<double, 3, 6>>& J) {
  MatX out(3, 6 * J.size());
  for (size_t k = 0; k < J.size(); ++k) out.middleCols(6 * k, 6) = J[k];
  return out;
}
MatX stackV(const std::vector<Vec3>& x) {
  MatX out(3, x.size());
  for (size_t k = 0; k < x.size(); ++k) out.col(k) = x[k];
  return out;
}

// a random configuration inside the training box (scaled coordinates within +-0.93 of the box,
// end points outside the surface)
Vec3 randomEnd(std::mt19937& rng, const WrapSurface& s, double zmax) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {
    const Vec3 p(2.8 * u(rng), 2.8 * u(rng), zmax * u(rng));
    const double r = s.type == WrapType::Cylinder ? p.head<2>().norm() : p.norm();
    if (r > 1.1) return s.radius * p;
  }
}

void checkModelAgainstFd(const Mlp& net, const WrapSurface& surf, double zmax, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::vector<double> alphas{0.15, 0.35, 0.5, 0.65, 0.85};
  NetworkWrapWorkspace ws;
  int wrapped = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 p1 = randomEnd(rng, surf, zmax), p2 = randomEnd(rng, surf, zmax);
    const Vec3 v1 = surf.radius * test::randomVec(rng, 1.0), v2 = surf.radius * test::randomVec(rng, 1.0);
    std::vector<double> alphadots(alphas.size());
    for (auto& a : alphadots) a = 0.3 * u(rng);
    wrapped += calcWrapPenetration(surf, p1, p2) > 0.0;
    WrapMassPoints mp;
    std::vector<Vec3> xa, xad;
    const NetworkWrapEval ev = calcNetworkWrapModel(&net, surf, p1, p2, v1, v2, alphas, true, mp, ws, {}, alphadots, &xa, &xad);
    ASSERT_TRUE(ev.usedNetwork()) << ev.describe(&net);
    // J = dw/d(p1, p2) and dw/dalpha: central differences, step 1e-5 of the size
    const double h = 1e-5 * surf.radius;
    MatX J_fd(3, 6 * alphas.size());
    for (int i = 0; i < 6; ++i) {
      Vec3 e1 = Vec3::Zero(), e2 = Vec3::Zero();
      (i < 3 ? e1 : e2)[i % 3] = h;
      WrapMassPoints a, b;
      calcNetworkWrapModel(&net, surf, p1 + e1, p2 + e2, v1, v2, alphas, false, a, ws);
      calcNetworkWrapModel(&net, surf, p1 - e1, p2 - e2, v1, v2, alphas, false, b, ws);
      for (size_t k = 0; k < alphas.size(); ++k) J_fd.col(6 * k + i) = (a.x[k] - b.x[k]) / (2 * h);
    }
    EXPECT_TRUE(closeRel(stackJ(mp.J), J_fd, 1e-6, "J"));
    const double ha = 1e-5;
    std::vector<double> ap = alphas, am = alphas;
    for (size_t k = 0; k < alphas.size(); ++k) ap[k] += ha, am[k] -= ha;
    WrapMassPoints a, b;
    calcNetworkWrapModel(&net, surf, p1, p2, v1, v2, ap, false, a, ws);
    calcNetworkWrapModel(&net, surf, p1, p2, v1, v2, am, false, b, ws);
    EXPECT_TRUE(closeRel(stackV(xa), (stackV(a.x) - stackV(b.x)) / (2 * ha), 1e-6, "dw/dalpha"));
    // Jdot and d/dt dw/dalpha: central differences of J along (p1dot, p2dot, alphadot)
    const double tau = 1e-5;
    std::vector<double> atp = alphas, atm = alphas;
    for (size_t k = 0; k < alphas.size(); ++k) atp[k] += tau * alphadots[k], atm[k] -= tau * alphadots[k];
    std::vector<Vec3> xa_p, xa_m;
    calcNetworkWrapModel(&net, surf, p1 + tau * v1, p2 + tau * v2, v1, v2, atp, false, a, ws, {}, {}, &xa_p);
    calcNetworkWrapModel(&net, surf, p1 - tau * v1, p2 - tau * v2, v1, v2, atm, false, b, ws, {}, {}, &xa_m);
    EXPECT_TRUE(closeRel(stackJ(mp.Jdot), (stackJ(a.J) - stackJ(b.J)) / (2 * tau), 1e-6, "Jdot"));
    EXPECT_TRUE(closeRel(stackV(xad), (stackV(xa_p) - stackV(xa_m)) / (2 * tau), 1e-6, "d/dt dw/dalpha"));
    // the dissertation's forward difference [D Eq. 5.58]: first order in its step
    NetworkWrapOptions fd;
    fd.fd_jdot = true;
    WrapMassPoints f;
    calcNetworkWrapModel(&net, surf, p1, p2, v1, v2, alphas, true, f, ws, fd, alphadots);
    EXPECT_TRUE(closeRel(stackJ(f.Jdot), stackJ(mp.Jdot), 1e-4, "forward-difference Jdot"));
    EXPECT_TRUE(closeRel(stackJ(f.J), stackJ(mp.J), 1e-15, "J of the forward-difference call"));
  }
  EXPECT_GE(wrapped, 3);
}

TEST(NetworkWrapModel, JacobiansMatchCentralDifferencesCylinder) {
  const auto net = committedNet("cylinder_3x64.txt");
  // length 4 radii: end points within |z| <= 1.8 radii stay within it
  checkModelAgainstFd(*net, WrapSurface::makeCylinder(0.05, 0.2), 1.8, 3);
}

TEST(NetworkWrapModel, JacobiansMatchCentralDifferencesSphere) {
  const auto net = committedNet("sphere_3x64.txt");
  checkModelAgainstFd(*net, WrapSurface::makeSphere(0.03), 2.8, 5);
}

// ---------------------------------------------------------------------------------------------
// the compact input map and displacement output (meta wrap_map compact C, issue 22)

TEST(NetworkWrapModel, CompactMapRoundTripAndDerivatives) {
  std::mt19937 rng(11);
  for (const double C : {1.0, 4.0, 10.0})
    for (int trial = 0; trial < 20; ++trial) {
      // from near the origin to 1000 radii
      const Vec3 q = std::pow(10.0, 3.0 * std::uniform_real_distribution<double>(-0.5, 1.0)(rng)) *
                     test::randomVec(rng, 1.0).normalized();
      const Vec3 qd = test::randomVec(rng, 1.0);
      Mat3 M, Md;
      const Vec3 u = calcCompactWrapInput(q, C, &M, &qd, &Md);
      EXPECT_LT(u.norm(), C);
      EXPECT_LE((calcCompactWrapInputInverse(u, C) - q).norm(), 1e-12 * (1.0 + q.norm()) * (1.0 + q.norm() / C));
      // du/dq and its time derivative along qdot: central differences
      const double h = 1e-6 * (1.0 + q.norm());
      Mat3 M_fd, Md_fd;
      for (int i = 0; i < 3; ++i) {
        const Vec3 e = h * Vec3::Unit(i);
        M_fd.col(i) = (calcCompactWrapInput(q + e, C) - calcCompactWrapInput(q - e, C)) / (2 * h);
      }
      Mat3 Mp, Mm;
      calcCompactWrapInput(q + h * qd, C, &Mp);
      calcCompactWrapInput(q - h * qd, C, &Mm);
      Md_fd = (Mp - Mm) / (2 * h);
      EXPECT_TRUE(closeRel(M, M_fd, 1e-7, "du/dq")) << "C " << C << " q " << q.transpose();
      EXPECT_TRUE(closeRel(Md, Md_fd, 1e-6, "d/dt du/dq")) << "C " << C << " q " << q.transpose();
    }
  // near end points keep their coordinates to first order
  Mat3 M0;
  EXPECT_EQ(calcCompactWrapInput(Vec3::Zero(), 4.0, &M0), Vec3::Zero());
  EXPECT_EQ(M0, Mat3::Identity());
}

// a random network with the compact map and a box of all of space
Mlp compactNetwork(double C, unsigned seed) {
  Mlp net(8, {12, 9}, 3, seed);
  std::mt19937 rng(seed + 7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int l = 0; l < net.layers(); ++l)
    net.biases(l) = VecX::NullaryExpr(net.biases(l).size(), [&] { return 0.4 * u(rng); });
  net.output_scale = VecX::Constant(3, 0.3);
  net.input_min = VecX::Constant(8, -C);
  net.input_max = VecX::Constant(8, C);
  net.input_min[6] = 0.0;
  net.input_max[6] = 1.0;
  net.meta["surface"] = "cylinder";
  net.meta["wrap_map"] = formatCompactWrapMap(C);
  return net;
}

TEST(NetworkWrapModel, CompactMapJacobiansMatchCentralDifferences) {
  // J, Jdot, dw/dalpha and its rate through the map and the displacement output
  checkModelAgainstFd(compactNetwork(4.0, 21), WrapSurface::makeCylinder(0.05, 0.2), 1.8, 23);
  Mlp sphere = compactNetwork(2.0, 22);
  sphere.meta["surface"] = "sphere";
  checkModelAgainstFd(sphere, WrapSurface::makeSphere(0.03), 2.8, 24);
}

TEST(NetworkWrapModel, CompactMapServesFarEndsAndOutputsTheDisplacement) {
  // zero output: the straight line exactly, however far the ends (no box to leave)
  Mlp net = compactNetwork(4.0, 31);
  net.weights(net.layers() - 1).setZero();
  net.biases(net.layers() - 1).setZero();
  net.output_mean.setZero();
  const WrapSurface s = WrapSurface::makeCylinder(0.02, 100.0);
  const Vec3 p1(-1.5, 0.9, 0.3), p2(2.0, -1.1, -0.2);  // 75-100 radii from the axis
  const Vec3 v1(0.1, 0.2, -0.3), v2(-0.2, 0.1, 0.05);
  const std::vector<double> alphas{0.0, 0.25, 0.5, 1.0}, alphadots{0.1, -0.2, 0.3, 0.0};
  NetworkWrapWorkspace ws;
  WrapMassPoints mp;
  std::vector<Vec3> xa, xad;
  const NetworkWrapEval ev = calcNetworkWrapModel(&net, s, p1, p2, v1, v2, alphas, true, mp, ws, {}, alphadots, &xa, &xad);
  ASSERT_TRUE(ev.usedNetwork()) << ev.describe(&net);
  for (size_t k = 0; k < alphas.size(); ++k) {
    const double a = alphas[k];
    EXPECT_LE((mp.x[k] - (p1 + a * (p2 - p1))).norm(), 1e-15) << k;
    Eigen::Matrix<double, 3, 6> J;
    J << (1 - a) * Mat3::Identity(), a * Mat3::Identity();
    EXPECT_LE((mp.J[k] - J).norm(), 1e-15) << k;
    Eigen::Matrix<double, 3, 6> Jd;
    Jd << -alphadots[k] * Mat3::Identity(), alphadots[k] * Mat3::Identity();
    EXPECT_LE((mp.Jdot[k] - Jd).norm(), 1e-15) << k;
    EXPECT_LE((xa[k] - (p2 - p1)).norm(), 1e-15) << k;
    EXPECT_LE((xad[k] - (v2 - v1)).norm(), 1e-15) << k;
  }
}

TEST(NetworkWrapModel, WrapMapMetaIsCheckedWithItsLine) {
  Mlp net = compactNetwork(4.0, 41);
  EXPECT_EQ(wrapNetworkMap(net).compact, 4.0);
  const auto dir = std::filesystem::temp_directory_path() / ("wrap_map_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  // the file round trip keeps the map bit for bit
  net.save((dir / "good.txt").string());
  const auto back = loadWrapNetwork((dir / "good.txt").string());
  EXPECT_TRUE(back->identical(net));
  EXPECT_EQ(wrapNetworkMap(*back).compact, 4.0);
  // older files (no wrap_map) keep the older map
  net.meta.erase("wrap_map");
  EXPECT_FALSE(wrapNetworkMap(net).isCompact());
  for (const std::string bad : {"compact -1", "compact", "compact 4 extra", "affine 2"}) {
    net.meta["wrap_map"] = bad;
    const std::string f = (dir / "bad.txt").string();
    net.save(f);
    // the meta line's number in the file: after the header lines, meta in key order
    const std::string text = net.toText();
    int line = 0, no = 0;
    for (size_t pos = 0, next; pos < text.size() && line == 0; pos = next + 1) {
      next = text.find('\n', pos);
      ++no;
      if (text.compare(pos, 13, "meta wrap_map") == 0) line = no;
    }
    try {
      loadWrapNetwork(f);
      ADD_FAILURE() << "accepted wrap_map '" << bad << "'";
    } catch (const NetworkFormatError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(f + ":" + std::to_string(line) + ": meta wrap_map", 0), 0u) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

// the network is trained in units of the surface size: a surface of radius R gets R y(p1 / R,
// p2 / R, alpha, 1) (positions back in metres)
TEST(NetworkWrapModel, PositionsAreTheNetworkAtTheSurfaceScale) {
  const WrapSurface s = WrapSurface::makeCylinder(0.08, 8.0);  // metres, like the pendulum's
  Mlp net(8, {10, 10}, 3, 4);
  const WrapInputBox box = makeDefaultWrapBox(WrapType::Cylinder);
  net.input_min = box.lo;
  net.input_max = box.hi;
  const std::vector<double> alphas{0.1, 0.35, 0.6, 0.9};
  const Vec3 p1(-0.15, 0.12, 0.01), p2(0.11, -0.14, 0.05), v1(0.3, -0.2, 0.1), v2(-0.1, 0.4, 0.2);
  NetworkWrapWorkspace ws;
  WrapMassPoints mp;
  const NetworkWrapEval ev = calcNetworkWrapModel(&net, s, p1, p2, v1, v2, alphas, true, mp, ws);
  ASSERT_TRUE(ev.usedNetwork()) << ev.describe(&net);
  MlpWorkspace mws;
  for (size_t k = 0; k < alphas.size(); ++k) {
    VecX u(8);
    u << p1 / 0.08, p2 / 0.08, alphas[k], 1.0;
    MatX y;
    net.calcOutput(u, y, mws);
    EXPECT_LE((mp.x[k] - 0.08 * Vec3(y.col(0))).norm(), 1e-15) << k;
  }
}

TEST(NetworkWrapModel, LoadingAndDefaultNetworks) {
  const std::string src = REDMAX_SOURCE_DIR;
  const std::string cyl = defaultWrapNetworkPath(src, WrapType::Cylinder);
  EXPECT_NE(cyl.find("osim_models/networks/cylinder_3x64.txt"), std::string::npos) << cyl;
  EXPECT_NE(defaultWrapNetworkPath(src, WrapType::Sphere).find("sphere_3x64.txt"), std::string::npos);
  EXPECT_EQ(defaultWrapNetworkPath(src, WrapType::Torus), "");
  EXPECT_EQ(defaultWrapNetworkPath("/nonexistent", WrapType::Cylinder), "");
  const auto net = loadWrapNetwork(cyl);
  EXPECT_EQ(net->meta.at("surface"), "cylinder");
  EXPECT_THROW(loadWrapNetwork(src + "/osim_models/networks/README.md"), std::runtime_error);  // not a network
  EXPECT_THROW(loadWrapNetwork("/nonexistent/net.txt"), std::runtime_error);
}

// ---------------------------------------------------------------------------------------------
// fallback: the smooth model's result exactly, the reason reported

void expectSmooth(const WrapSurface& s, const Vec3& p1, const Vec3& p2, const Vec3& v1, const Vec3& v2,
                  const std::vector<double>& alphas, const WrapMassPoints& mp) {
  for (size_t k = 0; k < alphas.size(); ++k) {
    const SmoothWrapPoint sp = calcSmoothWrapPointDerivatives(s, p1, p2, alphas[k], v1, v2);
    EXPECT_EQ(mp.x[k], sp.x);
    EXPECT_EQ(mp.J[k], sp.J);
    EXPECT_EQ(mp.Jdot[k], sp.Jdot);
  }
  EXPECT_FALSE(mp.used_network);
}

TEST(NetworkWrapModel, FallbacksGiveTheSmoothModelExactly) {
  const auto cyl = committedNet("cylinder_3x64.txt");
  const auto sph = committedNet("sphere_3x64.txt");
  const std::vector<double> alphas{0.2, 0.5, 0.8};
  const Vec3 v1(0.01, -0.02, 0.005), v2(-0.03, 0.01, 0.0);
  NetworkWrapWorkspace ws;
  WrapMassPoints mp;
  const WrapSurface s = WrapSurface::makeCylinder(0.1, 0.4);
  // inside the box: the network (differs from the smooth model)
  const Vec3 p1(-0.15, 0.25, 0.02), p2(0.2, -0.22, -0.05);
  EXPECT_TRUE(calcNetworkWrapModel(cyl.get(), s, p1, p2, v1, v2, alphas, true, mp, ws).usedNetwork());
  EXPECT_TRUE(mp.used_network);
  EXPECT_GT((mp.x[1] - calcSmoothWrapPoint(s, p1, p2, 0.5)).norm(), 1e-6);
  // origin x at 3.5 radii: outside the box [-3, 3] (compact map: its image), named
  const Vec3 far(-0.35, 0.1, 0.0);
  NetworkWrapEval ev = calcNetworkWrapModel(cyl.get(), s, far, p2, v1, v2, alphas, true, mp, ws);
  EXPECT_EQ(ev.fallback, NetworkWrapFallback::OutsideBox);
  EXPECT_EQ(ev.input, 0);
  EXPECT_EQ(ev.point, 0);
  // the value the network sees: the scaled coordinate, through the compact map when the file has one
  const WrapNetworkMap map = wrapNetworkMap(*cyl);
  const double seen = map.isCompact() ? calcCompactWrapInput(far / 0.1, map.compact)[0] : -3.5;
  EXPECT_NEAR(ev.value, seen, 1e-12);
  EXPECT_NE(ev.describe(cyl.get()).find(cyl->input_names[0] + " = " + (map.isCompact() ? "-1.8" : "-3.5")),
            std::string::npos)
      << ev.describe(cyl.get());
  expectSmooth(s, far, p2, v1, v2, alphas, mp);
  // a sphere network on a cylinder
  ev = calcNetworkWrapModel(sph.get(), s, p1, p2, v1, v2, alphas, true, mp, ws);
  EXPECT_EQ(ev.fallback, NetworkWrapFallback::SurfaceType);
  expectSmooth(s, p1, p2, v1, v2, alphas, mp);
  // an end point beyond the cylinder's length (|z| = 0.18 > 0.15) with the tangent points within it
  // (and inside the box, |z| <= 2 radii): the finite cylinder's path is the infinite one's, so the
  // network serves (issue 22)
  const WrapSurface shorter = WrapSurface::makeCylinder(0.1, 0.3);
  const Vec3 high(-0.25, 0.05, 0.18), low(0.25, 0.02, -0.1);
  ASSERT_TRUE(calcWrap(shorter, high, low).wraps());
  ev = calcNetworkWrapModel(cyl.get(), shorter, high, low, v1, v2, alphas, true, mp, ws);
  EXPECT_TRUE(ev.usedNetwork()) << ev.describe(cyl.get());
  // both ends (and so both tangent points) beyond the top end (|z| = 0.18, 0.19 > 0.15): the
  // library gives no wrap although the line passes through the infinite cylinder, so the smooth model
  const Vec3 high2(0.25, 0.02, 0.19);
  ASSERT_FALSE(calcWrap(shorter, high, high2).wraps());
  ASSERT_TRUE(calcWrap(WrapSurface::makeCylinder(0.1, 100.0), high, high2).wraps());
  ev = calcNetworkWrapModel(cyl.get(), shorter, high, high2, v1, v2, alphas, true, mp, ws);
  EXPECT_EQ(ev.fallback, NetworkWrapFallback::FiniteLength);
  expectSmooth(shorter, high, high2, v1, v2, alphas, mp);
  // quadrant -x with both ends on +x: OpenSim forces a wrap round -x
  const WrapSurface q = WrapSurface::makeCylinder(0.1, 0.4, 0, -1);
  const Vec3 a(0.05, 0.25, 0.0), b(0.05, -0.25, 0.0);
  ev = calcNetworkWrapModel(cyl.get(), q, a, b, v1, v2, alphas, true, mp, ws);
  EXPECT_EQ(ev.fallback, NetworkWrapFallback::Quadrant);
  expectSmooth(q, a, b, v1, v2, alphas, mp);
  // ... but with both ends on the active side the quadrant does not change the path: the network
  EXPECT_TRUE(calcNetworkWrapModel(cyl.get(), q, Vec3(-0.05, 0.25, 0), Vec3(-0.05, -0.25, 0), v1, v2, alphas, true, mp, ws)
                  .usedNetwork());
  // a quadrant sphere (+y; smooth since issue 22): both ends on the active side, the library's
  // path is the unconstrained one the sphere network learnt, so it serves; both ends on the
  // inactive side, the library wraps round the active side (the long way): the smooth model
  const WrapSurface qs = WrapSurface::makeSphere(0.1, 1, +1);
  const Vec3 up1(-0.25, 0.06, 0.01), up2(0.25, 0.06, -0.01), down1(-0.25, -0.06, 0.01), down2(0.25, -0.06, -0.01);
  ASSERT_TRUE(calcWrap(qs, up1, up2).wraps());
  ASSERT_TRUE(calcWrap(qs, down1, down2).wraps());
  ev = calcNetworkWrapModel(sph.get(), qs, up1, up2, v1, v2, alphas, true, mp, ws);
  EXPECT_TRUE(ev.usedNetwork()) << ev.describe(sph.get());
  ev = calcNetworkWrapModel(sph.get(), qs, down1, down2, v1, v2, alphas, true, mp, ws);
  EXPECT_EQ(ev.fallback, NetworkWrapFallback::Quadrant);
  expectSmooth(qs, down1, down2, v1, v2, alphas, mp);
  // no network
  ev = calcNetworkWrapModel(nullptr, s, p1, p2, v1, v2, alphas, true, mp, ws);
  EXPECT_EQ(ev.fallback, NetworkWrapFallback::NoNetwork);
  expectSmooth(s, p1, p2, v1, v2, alphas, mp);
  // errors: an end inside, an unsupported surface, a network of the wrong shape
  EXPECT_THROW(calcNetworkWrapModel(cyl.get(), s, Vec3(0.05, 0, 0), p2, v1, v2, alphas, true, mp, ws), std::invalid_argument);
  EXPECT_THROW(calcNetworkWrapModel(cyl.get(), WrapSurface::makeTorus(0.05, 0.3), p1, p2, v1, v2, alphas, true, mp, ws),
               std::invalid_argument);
  const Mlp bad(7, {4}, 3, 1);
  EXPECT_THROW(calcNetworkWrapModel(&bad, s, p1, p2, v1, v2, alphas, true, mp, ws), std::invalid_argument);
  EXPECT_FALSE(neuralWrapUnsupportedReason(&bad, s).empty());
  EXPECT_FALSE(neuralWrapUnsupportedReason(nullptr, s).empty());
  EXPECT_TRUE(neuralWrapUnsupportedReason(cyl.get(), s).empty());
}

TEST(NetworkWrapModel, PathLengthFromThePointPolyline) {
  const auto net = committedNet("cylinder_3x64.txt");
  const WrapSurface s = WrapSurface::makeCylinder(0.1, 0.4);
  const Vec3 p1(-0.15, 0.25, 0.02), p2(0.2, -0.22, -0.05);  // wraps (d > 0), inside the box
  ASSERT_GT(calcWrapPenetration(s, p1, p2), 0.0);
  NetworkWrapWorkspace ws;
  NetworkWrapEval ev;
  // without a network: the polyline through the smooth model's points converges to its length
  const double Ls = calcSmoothWrapLength(s, p1, p2, Vec3::Zero(), Vec3::Zero()).length;
  const double L400 = calcNetworkWrapPathLength(nullptr, s, p1, p2, 400, ws, &ev);
  EXPECT_EQ(ev.fallback, NetworkWrapFallback::NoNetwork);
  EXPECT_NEAR(L400, Ls, 1e-5 * Ls);
  EXPECT_LT(L400, Ls);  // a chord polyline is shorter than the arc
  // with the network: converged in the segment count, longer than the straight line
  const double N200 = calcNetworkWrapPathLength(net.get(), s, p1, p2, 200, ws, &ev);
  EXPECT_TRUE(ev.usedNetwork());
  const double N400 = calcNetworkWrapPathLength(net.get(), s, p1, p2, 400, ws);
  EXPECT_NEAR(N200, N400, 1e-5 * N400);
  EXPECT_GT(N400, (p2 - p1).norm());
  std::printf("wrapped length: smooth %.6f m, network polyline %.6f m (straight %.6f m)\n", Ls, N400, (p2 - p1).norm());
  EXPECT_THROW(calcNetworkWrapPathLength(net.get(), s, p1, p2, 0, ws), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// through the muscle: chain rule with the surface on a moving body, counting, warning once

WrapMassOptions neural(std::shared_ptr<const Mlp> net) {
  WrapMassOptions o;
  o.model = WrapModel::Neural;
  o.network = std::move(net);
  return o;
}

// the muscle's kinematics at s, its workspace's fallback counts added to `monitor`
MuscleKinematics evalCounted(const Model& m, const Muscle& mu, const State& s, WrapFallbackMonitor& monitor) {
  MuscleKinematics mk = test::evalMuscle(m, mu, s);
  monitor.add(mu, mk.wrap_counts);
  return mk;
}

// (the finite differences' own evaluations are not counted)
void checkMuscleAgainstFd(const Model& m, const Muscle& mu, const State& s, double tol, WrapFallbackMonitor& monitor) {
  const double h = 1e-6;
  const MuscleKinematics mk = evalCounted(m, mu, s, monitor);
  const MatX J_fd = test::calcJarFd(m, mu, s, h);
  EXPECT_TRUE(closeRel(mk.J_ar, J_fd, tol, "J_ar"));
  EXPECT_TRUE(closeRel(mk.Jdot_ar, test::calcJdotArFd(m, mu, s, h), tol, "Jdot_ar"));
}

TEST(NetworkWrapModel, MuscleJacobiansOnAMovingSurfaceMatchCentralDifferences) {
  const auto net = committedNet("cylinder_3x64.txt");
  auto monitor = std::make_shared<WrapFallbackMonitor>();
  const Model m = scenes::doublePendulum();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double tilt : {0.0, 0.25}) {
    scenes::WrapPendulumSpec spec;
    spec.tilt = tilt;  // the surface's axis turned off the joint axis: a 3-D wrap
    const Muscle mu = scenes::makeWrapPendulumMuscle(spec, neural(net));
    validateMuscle(m, mu);
    for (int trial = 0; trial < 12; ++trial) {
      State s;
      s.q = Vec2(u(rng), 0.2 + 0.3 * u(rng));
      s.qdot = Vec2(2 * u(rng), 2 * u(rng));
      checkMuscleAgainstFd(m, mu, s, 1e-6, *monitor);
    }
  }
  EXPECT_GT(monitor->evaluations("wrap_muscle"), 0);
  EXPECT_EQ(monitor->fallbacks("wrap_muscle"), 0) << monitor->summary();
}

// a path with a via point before the wrapped segment: mass points over the whole path slide onto and
// along the wrapped segment, so the network's alpha derivative enters J and Jdot
TEST(NetworkWrapModel, SlidingPointsOnAViaPointPathMatchCentralDifferences) {
  const auto net = committedNet("cylinder_3x64.txt");
  auto monitor = std::make_shared<WrapFallbackMonitor>();
  const Model m = scenes::doublePendulum();
  Muscle mu = scenes::makeWrapPendulumMuscle(scenes::WrapPendulumSpec{}, neural(net));
  mu.path.points = {makeFixedPoint(0, Vec3(-0.1, -0.5, 0), "origin"), makeFixedPoint(0, Vec3(-0.1, -0.8, 0), "via"),
                    makeFixedPoint(1, Vec3(-0.1, -0.2, 0), "insertion")};
  mu.path.wraps[0].range_begin = 2;  // via -> insertion
  mu.path.wraps[0].range_end = 3;
  MassPointOptions mpo;
  mpo.region = MassPointOptions::Region::WholePath;
  mu.mass_points = makeMassPoints(1.0, 0.5, 0.3, mpo);
  validateMuscle(m, mu);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int wrapped = 0;
  for (int trial = 0; trial < 10; ++trial) {
    State s;
    s.q = Vec2(u(rng), 0.25 + 0.2 * u(rng));
    s.qdot = Vec2(2 * u(rng), 2 * u(rng));
    // does the via -> insertion segment touch the cylinder here?
    const MuscleKinematics mk = test::evalMuscle(m, mu, s);  // not counted: only the check's evaluations
    SkeletonWorkspace sk(m);
    calcKinematics(m, s, sk);
    const Mat4 E_sw = inverseE(Mat4(sk.E_wi[0] * mu.path.wraps[0].E_bs));
    wrapped += calcWrapPenetration(mu.path.wraps[0].surface, transformPoint(E_sw, mk.x_w[1]),
                                   transformPoint(E_sw, mk.x_w[2])) > 0.0;
    checkMuscleAgainstFd(m, mu, s, 1e-6, *monitor);
  }
  EXPECT_GE(wrapped, 3);
  EXPECT_GT(monitor->evaluations("wrap_muscle"), 0);
  EXPECT_EQ(monitor->fallbacks("wrap_muscle"), 0) << monitor->summary();
}

TEST(NetworkWrapModel, OutOfBoxMuscleFallsBackCountsAndWarnsOnce) {
  const auto net = committedNet("cylinder_3x64.txt");
  std::vector<std::string> messages;
  auto monitor = std::make_shared<WrapFallbackMonitor>([&](const std::string& msg) { messages.push_back(msg); });
  const Model m = scenes::doublePendulum();
  // osim_models/double_pendulum_wrap.osim's geometry: end points 0.4 m = 5 radii from the axis
  scenes::WrapPendulumSpec osim;
  osim.origin = Vec3(-0.1, -0.6, 0);
  osim.insertion = Vec3(-0.1, -0.4, 0);
  const Muscle mu = scenes::makeWrapPendulumMuscle(osim, neural(net));
  WrapMassOptions sm;
  sm.model = WrapModel::Smooth;
  const Muscle mu_s = scenes::makeWrapPendulumMuscle(osim, sm);
  std::mt19937 rng(2);
  for (int trial = 0; trial < 3; ++trial) {
    const State s = test::randomState(2, rng, 0.3);
    const MuscleKinematics a = evalCounted(m, mu, s, *monitor), b = test::evalMuscle(m, mu_s, s);
    for (int k = 0; k < mu.mass_points.size(); ++k) EXPECT_EQ(a.x_a[k], b.x_a[k]);
    EXPECT_EQ(a.J_ar, b.J_ar);
    EXPECT_EQ(a.Jdot_ar, b.Jdot_ar);
  }
  const long n = monitor->evaluations("wrap_muscle");
  EXPECT_GE(n, 3);
  EXPECT_EQ(monitor->fallbacks("wrap_muscle"), n);
  EXPECT_EQ(monitor->totalFallbacks(), n);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("wrap_muscle"), std::string::npos) << messages[0];
  EXPECT_NE(messages[0].find("outside the training box"), std::string::npos) << messages[0];
  const std::string all = std::to_string(n) + " of " + std::to_string(n) + " evaluations";
  EXPECT_NE(monitor->summary().find(all), std::string::npos) << monitor->summary();
  long by_reason = 0;
  const auto counts = monitor->counts();
  for (const auto& [why, count] : counts.at("wrap_muscle").by_reason) {
    EXPECT_NE(why, NetworkWrapFallback::None);
    by_reason += count;
  }
  EXPECT_EQ(by_reason, n);
  // a second muscle on the same monitor warns once for itself
  Muscle other = mu;
  other.name = "other";
  evalCounted(m, other, test::randomState(2, rng, 0.3), *monitor);
  EXPECT_EQ(messages.size(), 2u);
  EXPECT_GE(monitor->fallbacks("other"), 1);
  // validation: Neural without a network is refused with the reason
  Muscle none = mu;
  none.wrap.network.reset();
  try {
    validateMuscle(m, none);
    ADD_FAILURE() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("no wrap network"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// energy: gravity only, rk45 rtol = atol = 1e-12

TEST(NetworkWrapModel, PendulumEnergyConservedToIntegratorError) {
  const auto net = committedNet("cylinder_3x64.txt");
  const scenes::WrapPendulumSpec spec;  // end points 2.5 radii from the axis: inside the box
  const scenes::WrapPendulumRun r = scenes::runWrapPendulum(spec, neural(net), 3.0);
  WrapMassOptions fd = neural(net);
  fd.network_fd_jdot = true;
  const scenes::WrapPendulumRun f = scenes::runWrapPendulum(spec, fd, 3.0);
  std::printf("wrapping pendulum on cylinder_3x64, 3 s rk45 1e-12: E0 %.4f J\n%s"
              "  exact Jdot: drift %.3e J, largest 10 ms change %.3e J, %d contact changes, %ld steps, %.2f s wall\n"
              "  Eq. 5.58 forward-difference Jdot (eps 1e-6 s): drift %.3e J, %ld steps, %.2f s wall\n",
              r.E0, scenes::formatWrapPendulumTable({r}).c_str(), r.max_drift, r.max_step_change, r.contact_changes,
              r.steps, r.wall_s, f.max_drift, f.steps, f.wall_s);
  ::testing::Test::RecordProperty("neural_drift_J", std::to_string(r.max_drift));
  EXPECT_EQ(r.fallbacks, 0) << r.first_fallback;
  EXPECT_GT(r.evaluations, 1000);
  EXPECT_GE(r.contact_changes, 2);
  // integrator error only: no jump at contact changes (the network is C-infinity)
  EXPECT_LE(r.max_drift, 1e-8);
}

TEST(NetworkWrapModel, GroupOfPendulumsOnOneNetwork) {
  const auto net = committedNet("cylinder_3x64.txt");
  const auto specs = scenes::makeWrapPendulumGroup(8, 1);
  std::vector<scenes::WrapPendulumRun> runs;
  for (const auto& s : specs) runs.push_back(scenes::runWrapPendulum(s, neural(net), 2.0));
  std::printf("8 wrapping pendulums (seed 1) on cylinder_3x64, 2 s rk45 1e-12:\n%s",
              scenes::formatWrapPendulumTable(runs).c_str());
  // pendulums that stay in the training box: integrator error only; one that leaves it switches to
  // the smooth model, which differs from this small network by its fitting error (0.1 radius RMS),
  // so the energy jumps there: counted, and visible
  int in_box = 0, changes = 0;
  for (const auto& r : runs) {
    EXPECT_GT(r.evaluations, 1000);
    if (r.fallbacks == 0) {
      ++in_box;
      changes += r.contact_changes;
      EXPECT_LE(r.max_drift, 1e-8);
    } else {
      EXPECT_GE(r.max_drift, 1e-6) << "a switch to the smooth model moves the points";
      EXPECT_NE(r.first_fallback.find("outside the training box"), std::string::npos) << r.first_fallback;
    }
  }
  EXPECT_GE(in_box, 6);
  EXPECT_GE(changes, 4);
}

}  // namespace
}  // namespace redmax
