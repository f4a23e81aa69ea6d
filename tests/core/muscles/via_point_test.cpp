// The Eulerian-on-Lagrangian pieces of Type II paths, checked in raw point space (no skeleton):
//   J_sx  against central differences of the equal-strain Eulerian coordinates s(x)  [D Eq. 5.23]
//   Jdot_sx against differences of J_sx along xdot                                   [D Eq. 5.24]
//   J_az, Jdot_az against their definitions x_a = (1 - beta) x_0 + beta x_1,
//     beta = (s_a - s_0) / (s_1 - s_0)                                               [D Eq. 5.29-5.34]
//   J_ax of Type I                                                                   [D Eq. 5.10]
// h = 1e-6, relative error <= 1e-6.
#include "core/muscles/via_point.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/muscles/muscle_kinematics.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

constexpr double kH = 1e-6;

// a path workspace for free points x (P) with velocities v: J_xr = identity (nr = 3P), so
// J_sr holds J_sx in its internal rows
MuscleKinematics rawPath(const std::vector<Vec3>& x, const std::vector<Vec3>& v) {
  const int P = static_cast<int>(x.size());
  MuscleKinematics mk;
  mk.active.resize(P);
  for (int i = 0; i < P; ++i) mk.active[i] = i;
  mk.x_w = x;
  mk.xdot_w = v;
  mk.J_xr = MatX::Identity(3 * P, 3 * P);
  mk.Jdot_xr = MatX::Zero(3 * P, 3 * P);
  mk.l.resize(P - 1);
  mk.ldot.resize(P - 1);
  mk.dxbar.resize(P - 1);
  mk.length = 0.0;
  for (int i = 0; i + 1 < P; ++i) {
    const Vec3 d = x[i + 1] - x[i];
    mk.l[i] = d.norm();
    mk.dxbar[i] = d / mk.l[i];
    mk.ldot[i] = mk.dxbar[i].dot(v[i + 1] - v[i]);
    mk.length += mk.l[i];
  }
  mk.velocity = true;
  calcEulerianCoordinates(mk, "raw");
  return mk;
}

// equal-strain Eulerian coordinates of the internal points, written independently
VecX equalStrainS(const std::vector<Vec3>& x) {
  const int P = static_cast<int>(x.size());
  VecX c(P);
  c[0] = 0.0;
  for (int i = 1; i < P; ++i) c[i] = c[i - 1] + (x[i] - x[i - 1]).norm();
  return c.segment(1, P - 2) / c[P - 1];
}

std::vector<Vec3> shifted(const std::vector<Vec3>& x, const std::vector<Vec3>& d, double t) {
  std::vector<Vec3> r = x;
  for (size_t i = 0; i < r.size(); ++i) r[i] += t * d[i];
  return r;
}

class EolRandom : public ::testing::TestWithParam<int> {};

TEST_P(EolRandom, J_sxMatchesEqualStrainDifferences) {
  const int n = GetParam();  // internal points
  std::mt19937 rng(40 + n);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<Vec3> x(n + 2), v(n + 2);
    for (int i = 0; i < n + 2; ++i) {
      x[i] = Vec3(0.3 * i, 0, 0) + test::randomVec(rng, 0.1);
      v[i] = test::randomVec(rng, 1.0);
    }
    const MuscleKinematics mk = rawPath(x, v);
    // the stored s are the equal-strain ones
    EXPECT_TRUE(nearRel(VecX(mk.s.segment(1, n)), equalStrainS(x), 1e-14));
    EXPECT_EQ(mk.s[0], 0.0);
    EXPECT_EQ(mk.s[n + 1], 1.0);
    // J_sx along v, and along every single coordinate direction
    const VecX fd = (equalStrainS(shifted(x, v, kH)) - equalStrainS(shifted(x, v, -kH))) / (2 * kH);
    EXPECT_TRUE(nearRel(VecX(mk.sdot.segment(1, n)), fd, 1e-6));
    MatX J_fd(n, 3 * (n + 2));
    for (int c = 0; c < 3 * (n + 2); ++c) {
      std::vector<Vec3> e(n + 2, Vec3::Zero());
      e[c / 3][c % 3] = 1.0;
      J_fd.col(c) = (equalStrainS(shifted(x, e, kH)) - equalStrainS(shifted(x, e, -kH))) / (2 * kH);
    }
    EXPECT_TRUE(nearRel(mk.J_sx, J_fd, 1e-6)) << (mk.J_sx - J_fd).norm();
    // Jdot_sx: J_sx depends on x only, so d/dt J_sx = difference along v
    const MatX Jd_fd = (rawPath(shifted(x, v, kH), v).J_sx - rawPath(shifted(x, v, -kH), v).J_sx) / (2 * kH);
    EXPECT_TRUE(nearRel(mk.Jdot_sx, Jd_fd, 1e-6)) << (mk.Jdot_sx - Jd_fd).norm();
    // the ends carry no Eulerian velocity
    EXPECT_EQ(mk.J_sr.row(0).norm(), 0.0);
    EXPECT_EQ(mk.J_sr.row(n + 1).norm(), 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(InternalPoints, EolRandom, ::testing::Range(1, 6),
                         [](const ::testing::TestParamInfo<int>& i) { return std::to_string(i.param) + "_via_points"; });

// x_a(z) of one segment, z = (x0, x1, s0, s1), for a fixed material coordinate s_a
Vec3 massPointOfZ(const Eigen::Matrix<double, 8, 1>& z, double s_a) {
  const double beta = (s_a - z[6]) / (z[7] - z[6]);
  return (1.0 - beta) * z.head<3>() + beta * z.segment<3>(3);
}

TEST(EolSegment, J_azAndJdot_azMatchTheirDefinitions) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix<double, 8, 1> z, zd;
    z << test::randomVec(rng, 1.0), test::randomVec(rng, 1.0), 0.2 + 0.1 * u(rng), 0.6 + 0.1 * u(rng);
    zd = Eigen::Matrix<double, 8, 1>::NullaryExpr([&] { return u(rng); });
    const double s_a = 0.4;
    auto quantities = [&](const Eigen::Matrix<double, 8, 1>& zz, double& beta, Vec3& F) {
      const double ds = zz[7] - zz[6];
      beta = (s_a - zz[6]) / ds;
      F = (zz.segment<3>(3) - zz.head<3>()) / ds;
    };
    double beta;
    Vec3 F;
    quantities(z, beta, F);
    // J_az zdot = d/dt x_a [D Eq. 5.32, 5.34]
    const Vec3 xd_fd = (massPointOfZ(z + kH * zd, s_a) - massPointOfZ(z - kH * zd, s_a)) / (2 * kH);
    EXPECT_TRUE(nearRel(Vec3(calcJ_az(beta, F) * zd), xd_fd, 1e-6));
    // Jdot_az = d/dt J_az with betadot [D Eq. 5.31] and Fdot = (Delta xdot - F Delta sdot) / Delta s
    const double ds = z[7] - z[6];
    const double betadot = -((1.0 - beta) * zd[6] + beta * zd[7]) / ds;
    const Vec3 dxd = zd.segment<3>(3) - zd.head<3>();
    const Vec3 Fdot = (dxd - F * (zd[7] - zd[6])) / ds;
    double bp, bm;
    Vec3 Fp, Fm;
    quantities(z + kH * zd, bp, Fp);
    quantities(z - kH * zd, bm, Fm);
    const Eigen::Matrix<double, 3, 8> Jd_fd = (calcJ_az(bp, Fp) - calcJ_az(bm, Fm)) / (2 * kH);
    EXPECT_TRUE(nearRel(calcJdot_az(beta, betadot, F, Fdot), Jd_fd, 1e-6));
    EXPECT_NEAR(betadot, (bp - bm) / (2 * kH), 1e-6 * (1 + std::abs(betadot)));
    // the dissertation's printed Eq. 5.35, -(Delta xdot + F Delta sdot) / Delta s, is not d/dt F
    const Vec3 Fdot_printed = -(dxd + F * (zd[7] - zd[6])) / ds;
    EXPECT_FALSE(nearRel(Fdot_printed, Vec3((Fp - Fm) / (2 * kH)), 1e-3));
  }
}

TEST(EolSegment, MassPointJacobianIsJ_azTimesJ_zr) {
  // the library applies J_az's block structure directly; check it against the explicit product
  // J_ar = J_az J_zr and Jdot_ar = Jdot_az J_zr + J_az Jdot_zr [D Eq. 5.15], with J_xr = I
  std::mt19937 rng(12);
  for (int n = 1; n <= 4; ++n) {
    std::vector<Vec3> x(n + 2), v(n + 2);
    for (int i = 0; i < n + 2; ++i) {
      x[i] = Vec3(0.3 * i, 0, 0) + test::randomVec(rng, 0.1);
      v[i] = test::randomVec(rng, 1.0);
    }
    MuscleKinematics mk = rawPath(x, v);
    MassPointOptions opt;
    opt.count = 7;
    opt.region = MassPointOptions::Region::WholePath;
    const MassPoints mp = makeMassPoints(1.0, 0.1, 0.1, opt);
    calcViaPointMassPoints(mp, mk);
    for (int a = 0; a < mp.size(); ++a) {
      const int i = mk.segment[a];
      const double beta = mk.beta[a], ds = mk.s[i + 1] - mk.s[i];
      const Vec3 F = (x[i + 1] - x[i]) / ds;
      const double betadot = -((1.0 - beta) * mk.sdot[i] + beta * mk.sdot[i + 1]) / ds;
      const Vec3 Fdot = (v[i + 1] - v[i] - F * (mk.sdot[i + 1] - mk.sdot[i])) / ds;
      MatX J_zr(8, mk.J_xr.cols()), Jdot_zr(8, mk.J_xr.cols());
      J_zr << mk.J_xr.middleRows<6>(3 * i), mk.J_sr.row(i), mk.J_sr.row(i + 1);
      Jdot_zr << mk.Jdot_xr.middleRows<6>(3 * i), mk.Jdot_sr.row(i), mk.Jdot_sr.row(i + 1);
      EXPECT_TRUE(nearRel(MatX(mk.J_ar.middleRows<3>(3 * a)), MatX(calcJ_az(beta, F) * J_zr), 1e-14));
      EXPECT_TRUE(nearRel(MatX(mk.Jdot_ar.middleRows<3>(3 * a)),
                          MatX(calcJdot_az(beta, betadot, F, Fdot) * J_zr + calcJ_az(beta, F) * Jdot_zr), 1e-14));
    }
  }
}

TEST(StraightPath, J_axIsTheWeightedAverage) {
  const Eigen::Matrix<double, 3, 6> J = calcJ_ax(0.3);
  const Vec3 v0(1, 2, 3), v1(-1, 0.5, 2);
  Eigen::Matrix<double, 6, 1> v;
  v << v0, v1;
  EXPECT_TRUE(nearRel(Vec3(J * v), Vec3(0.7 * v0 + 0.3 * v1), 1e-15));
}

TEST(ViaPointPath, AllConditionalPointsInactiveReducesToTypeI) {
  // the EOL construction with no active internal point is the straight muscle
  const Model m = scenes::doublePendulum();
  Muscle straight;
  straight.name = "straight";
  straight.path.points = {makeFixedPoint(-1, Vec3(0.3, 0.1, 0.05)), makeFixedPoint(1, Vec3(0.1, -0.7, 0))};
  straight.mass_points = makeMassPoints(0.5, 0.2, 0.1, {});
  Muscle cond = straight;
  cond.name = "conditional";
  cond.path.points.insert(cond.path.points.begin() + 1,
                          makeConditionalPoint(0, Vec3(0.2, -0.5, 0), 1, 2.0, 3.0));
  State s;
  s.q = Vec2(0.4, -0.7);
  s.qdot = Vec2(1.3, -0.4);
  const MuscleKinematics a = test::evalMuscle(m, straight, s), b = test::evalMuscle(m, cond, s);
  ASSERT_EQ(b.active.size(), 2u);
  EXPECT_EQ(a.J_ar, b.J_ar);
  EXPECT_EQ(a.Jdot_ar, b.Jdot_ar);
  // active again: now a genuine Type II path through the point
  s.q[1] = 2.5;
  EXPECT_EQ(test::evalMuscle(m, cond, s).active.size(), 3u);
}

TEST(ViaPointPath, ZeroLengthSegmentUnderMassIsAClearError) {
  const Model m = scenes::doublePendulum();
  Muscle mu;
  mu.name = "degenerate";
  mu.path.points = {makeFixedPoint(-1, Vec3(0.3, 0.1, 0)), makeFixedPoint(-1, Vec3(0.3, 0.1, 0)),
                    makeFixedPoint(1, Vec3(0.1, -0.7, 0))};
  mu.mass_points = makeMassPoints({0.5}, {0.1});
  State s;
  s.q = Vec2(0.1, 0.2);
  s.qdot = Vec2::Zero();
  try {
    test::evalMuscle(m, mu, s);
    ADD_FAILURE() << "expected MuscleError";
  } catch (const MuscleError& e) {
    EXPECT_NE(std::string(e.what()).find("'degenerate'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("zero length"), std::string::npos) << e.what();
  }
  // without mass the same path only has a length
  mu.mass_points = MassPoints{};
  EXPECT_NO_THROW(test::evalMuscle(m, mu, s));
}

}  // namespace
}  // namespace redmax
