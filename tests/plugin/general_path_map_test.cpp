// The general path map (core/muscles/path_map.hpp, calcGeneralPathMap): a muscle's mass points as
// a function of its active points' world positions and its wrap surface frames' poses, for paths
// with via points and several wraps on different segments (the map the Simbody plugin uses).
//   - J (3N x (3P + 6W)) against central differences of x_a in every input (points moved, each
//     surface frame turned about its origin and moved; step 1e-6): 1e-6 of max |J|;
//   - bias against central differences of J v along a motion with constant input velocities
//     (vdot = 0, so xddot_a = bias; step 1e-5): 1e-6 of max |bias|; and J vdot + bias against the
//     five-point second difference of x_a along a motion with accelerations (step 2e-4): 1e-5 of the
//     peak;
//   - a path with four points, a cylinder on the first segment and a sphere on the last (the middle
//     one straight), and the same with the third point inactive (a conditional point off: three
//     segments become two, the sphere's range then holds no segment);
//   - one wrapped segment (two active points of three) equals calcWrapPathMap (the dissertation's
//     map, which calcGeneralPathMap uses for origin -> surface -> insertion) to 1e-13;
//   - the exact wrap model on the same paths (OpenSim's whole path, differences in v) equals the
//     smooth model's analytic map there (both surfaces outside the blend band).
#include <gtest/gtest.h>

#include <cstdio>

#include "core/muscles/path_map.hpp"
#include "core/muscles/wrap/smooth.hpp"
#include "core/spatial/se3.hpp"
#include "tests/plugin/wrap_test_geometry.hpp"

namespace redmax {
namespace {

using test::surfacePoseAcross;

struct Scene {
  Muscle mu;
  std::vector<Vec3> x;       // all four points (world)
  std::vector<Mat4> E_ws;    // the two surface frames (world)
  std::vector<Vec3> v, acc;  // point velocities and accelerations
  std::vector<Vec3> omega, alpha, pdot, pddot;
};

Scene makeScene() {
  Scene sc;
  sc.x = {Vec3(0.0, 0.5, 0.0), Vec3(0.05, 0.2, 0.02), Vec3(0.0, -0.15, 0.03), Vec3(0.04, -0.5, -0.02)};
  sc.E_ws = {surfacePoseAcross(sc.x[0], sc.x[1], Vec3(0.3, 0.1, 1.0), 0.7),
             surfacePoseAcross(sc.x[2], sc.x[3], Vec3(-0.2, 0.4, 1.0), -1.2)};
  Muscle& mu = sc.mu;
  mu.name = "two_wraps";
  for (int i = 0; i < 4; ++i) mu.path.points.push_back(makeFixedPoint(i % 2, Vec3::Zero()));
  // the frames sit on bodies 0 and 1 at some E_bs (only the wrap choice reads the body poses)
  const Mat4 E_b0s = expSE3((Vec6() << 0.2, -0.1, 0.3, 0.05, 0.1, -0.2).finished());
  PathWrap w0, w1;
  w0.name = "drum";
  w0.surface = WrapSurface::makeCylinder(0.03, 2.0);
  w0.body = 0;
  w0.E_bs = E_b0s;
  w0.range_begin = 1;
  w0.range_end = 2;
  w1.name = "ball";
  w1.surface = WrapSurface::makeSphere(0.03);
  w1.body = 1;
  w1.E_bs = Mat4::Identity();
  w1.range_begin = 3;
  w1.range_end = 4;
  mu.path.wraps = {w0, w1};
  mu.path.num_wraps = 2;
  MassPointOptions opt;
  opt.count = 12;
  opt.region = MassPointOptions::Region::WholePath;
  mu.mass_points = makeMassPoints(1.0, 1.0, 0.0, opt);
  sc.v = {Vec3(0.3, -0.2, 0.1), Vec3(-0.1, 0.4, 0.2), Vec3(0.2, 0.1, -0.3), Vec3(-0.3, 0.2, 0.1)};
  sc.acc = {Vec3(1.0, 0.5, -0.7), Vec3(-0.4, 0.9, 0.3), Vec3(0.6, -0.2, 0.4), Vec3(0.1, 0.3, -0.8)};
  sc.omega = {Vec3(0.7, -1.1, 0.4), Vec3(-0.5, 0.3, 0.9)};
  sc.alpha = {Vec3(-2.0, 0.5, 1.5), Vec3(1.0, -1.2, 0.3)};
  sc.pdot = {Vec3(0.05, 0.1, -0.2), Vec3(-0.1, 0.05, 0.15)};
  sc.pddot = {Vec3(0.2, -0.6, 0.8), Vec3(-0.3, 0.4, 0.1)};
  return sc;
}

// the inputs at time t of the motion x(t) = x + t v + t^2/2 a (points and frame origins),
// R(t) = exp([omega t + alpha t^2/2]) R0; with_acc false: the accelerations are zero
struct Inputs {
  std::vector<Vec3> x, xdot;
  std::vector<SurfaceFrameState> frames;
};

Inputs inputsAt(const Scene& sc, const std::vector<int>& active, double t, bool with_acc) {
  const double a = with_acc ? 0.5 * t * t : 0.0;
  Inputs in;
  for (int i : active) {
    in.x.push_back(sc.x[i] + t * sc.v[i] + a * sc.acc[i]);
    in.xdot.push_back(sc.v[i] + (with_acc ? t : 0.0) * sc.acc[i]);
  }
  for (int w = 0; w < 2; ++w) {
    SurfaceFrameState f;
    const Vec3 th = sc.omega[w] * t + a * sc.alpha[w];
    f.R = expSO3(th) * sc.E_ws[w].topLeftCorner<3, 3>();
    f.p = sc.E_ws[w].topRightCorner<3, 1>() + t * sc.pdot[w] + a * sc.pddot[w];
    // the world angular velocity of exp(th(t)) R0 is Jl(th) thdot (Jl the left Jacobian of SO(3))
    const Vec3 thdot = sc.omega[w] + (with_acc ? t : 0.0) * sc.alpha[w];
    f.omega = leftJacobianSO3(th) * thdot;
    f.pdot = sc.pdot[w] + (with_acc ? t : 0.0) * sc.pddot[w];
    in.frames.push_back(f);
  }
  return in;
}

const std::vector<std::vector<int>> kActiveSets{{0, 1, 2, 3}, {0, 1, 3}};

TEST(GeneralPathMap, JacobianMatchesCentralDifferences) {
  const Scene sc = makeScene();
  for (const std::vector<int>& active : kActiveSets) {
    SCOPED_TRACE("active points " + std::to_string(active.size()));
    const Inputs in = inputsAt(sc, active, 0.0, false);
    GeneralPathMap map;
    calcGeneralPathMap(sc.mu, active, in.x, nullptr, in.frames, map);
    const int P = static_cast<int>(active.size()), n = 3 * P + 12;
    ASSERT_EQ(map.J.rows(), 36);
    ASSERT_EQ(map.J.cols(), n);
    // the wraps land where intended and the first one really bends the path
    ASSERT_EQ(map.seg_wrap.front(), 0);
    if (P == 4) {
      EXPECT_EQ(map.seg_wrap, (std::vector<int>{0, -1, 1}));
    }
    const Mat3 R0 = in.frames[0].R;
    EXPECT_GT(calcWrapPenetration(sc.mu.path.wraps[0].surface, R0.transpose() * (in.x[0] - in.frames[0].p),
                                  R0.transpose() * (in.x[1] - in.frames[0].p)),
              0.0);
    const double h = 1e-6;
    MatX J_fd(36, n);
    for (int col = 0; col < n; ++col) {
      auto eval = [&](double sgn) {
        Inputs d = in;
        Vec3 e = Vec3::Zero();
        e[col % 3] = sgn * h;
        if (col < 3 * P) {
          d.x[col / 3] += e;
        } else {
          const int w = (col - 3 * P) / 6;
          // the first three columns of a frame turn it about its origin (world), the next move it
          if ((col - 3 * P) % 6 < 3) d.frames[w].R = expSO3(e) * d.frames[w].R;
          else d.frames[w].p += e;
        }
        GeneralPathMap m2;
        calcGeneralPathMap(sc.mu, active, d.x, nullptr, d.frames, m2);
        return stackPoints(m2.x_a);
      };
      J_fd.col(col) = (eval(1.0) - eval(-1.0)) / (2.0 * h);
    }
    const double err = (map.J - J_fd).cwiseAbs().maxCoeff(), peak = J_fd.cwiseAbs().maxCoeff();
    std::printf("  [%zu active points] J vs central differences: %.3e of %.3e\n", active.size(), err, peak);
    EXPECT_LT(err, 1e-6 * peak);
    // every surface column block that acts is non-zero (the surfaces move the mass points)
    EXPECT_GT(map.J.middleCols(3 * P, 6).cwiseAbs().maxCoeff(), 1e-2);
    if (P == 4) {
      EXPECT_GT(map.J.middleCols(3 * P + 6, 6).cwiseAbs().maxCoeff(), 1e-2);
    }
  }
}

TEST(GeneralPathMap, BiasMatchesCentralDifferences) {
  const Scene sc = makeScene();
  for (const std::vector<int>& active : kActiveSets) {
    SCOPED_TRACE("active points " + std::to_string(active.size()));
    // vdot = 0: xddot_a = bias = d/dt (J v)
    const Inputs in = inputsAt(sc, active, 0.0, false);
    GeneralPathMap map;
    calcGeneralPathMap(sc.mu, active, in.x, &in.xdot, in.frames, map);
    ASSERT_TRUE(map.velocity);
    const double h = 1e-5;
    auto Jv = [&](double t) {
      const Inputs d = inputsAt(sc, active, t, false);
      GeneralPathMap m2;
      calcGeneralPathMap(sc.mu, active, d.x, nullptr, d.frames, m2);
      return VecX(m2.J * stackGeneralVelocities(d.xdot, d.frames));
    };
    const VecX bias_fd = (Jv(h) - Jv(-h)) / (2.0 * h);
    const double err = (map.bias - bias_fd).cwiseAbs().maxCoeff(), peak = bias_fd.cwiseAbs().maxCoeff();
    std::printf("  [%zu active points] bias vs d/dt (J v): %.3e of %.3e\n", active.size(), err, peak);
    EXPECT_LT(err, 1e-6 * peak);
    EXPECT_GT(peak, 1e-2);

    // with accelerations: J vdot + bias against the second difference of x_a
    const Inputs in2 = inputsAt(sc, active, 0.0, true);
    calcGeneralPathMap(sc.mu, active, in2.x, &in2.xdot, in2.frames, map);
    VecX vdot(3 * static_cast<int>(active.size()) + 12);
    for (size_t i = 0; i < active.size(); ++i) vdot.segment<3>(3 * static_cast<int>(i)) = sc.acc[active[i]];
    for (int w = 0; w < 2; ++w)
      vdot.segment<6>(3 * static_cast<int>(active.size()) + 6 * w) << sc.alpha[w], sc.pddot[w];
    const double h2 = 2e-4;
    auto x = [&](double t) {
      const Inputs d = inputsAt(sc, active, t, true);
      GeneralPathMap m2;
      calcGeneralPathMap(sc.mu, active, d.x, nullptr, d.frames, m2);
      return stackPoints(m2.x_a);
    };
    const VecX xddot_fd =
        (-x(2.0 * h2) + 16.0 * x(h2) - 30.0 * x(0.0) + 16.0 * x(-h2) - x(-2.0 * h2)) / (12.0 * h2 * h2);
    const VecX xddot = map.J * vdot + map.bias;
    const double e2 = (xddot - xddot_fd).cwiseAbs().maxCoeff(), p2 = xddot_fd.cwiseAbs().maxCoeff();
    std::printf("  [%zu active points] J vdot + bias vs second differences: %.3e of %.3e\n", active.size(), e2, p2);
    EXPECT_LT(e2, 1e-5 * p2);
  }
}

TEST(GeneralPathMap, OneWrappedSegmentEqualsCalcWrapPathMap) {
  // three points with the middle one off: the segment construction on one wrapped segment (the
  // two-point path itself goes to calcWrapPathMap directly)
  const Scene sc = makeScene();
  Muscle mu = sc.mu;
  mu.path.points.resize(3);
  mu.path.wraps.resize(1);
  mu.path.wraps[0].range_begin = -1;
  mu.path.wraps[0].range_end = -1;
  mu.path.num_wraps = 1;
  const Inputs in = inputsAt(sc, {0, 1}, 0.0, false);
  GeneralPathMap map;
  calcGeneralPathMap(mu, {0, 2}, in.x, &in.xdot, {in.frames[0]}, map);
  ASSERT_EQ(map.seg_wrap, std::vector<int>{0});
  WrapPathMap ref;
  const WrapSegmentVelocity v{in.xdot[0], in.xdot[1], in.frames[0].omega, in.frames[0].pdot};
  calcWrapPathMap(mu.path.wraps[0].surface, mu.wrap, mu.mass_points, in.x[0], in.x[1], in.frames[0].R, in.frames[0].p,
                  &v, ref, mu.name);
  ASSERT_EQ(map.J.cols(), 12);
  EXPECT_LT((map.J - ref.J).cwiseAbs().maxCoeff(), 1e-13 * ref.J.cwiseAbs().maxCoeff());
  EXPECT_LT((map.bias - ref.bias).cwiseAbs().maxCoeff(), 1e-13 * ref.bias.cwiseAbs().maxCoeff());
  EXPECT_LT((stackPoints(map.x_a) - stackPoints(ref.x_a)).cwiseAbs().maxCoeff(), 1e-15);
}

// the exact wrap model beyond origin -> surface -> insertion: OpenSim's whole path
// (core/muscles/wrap/wrap_path.hpp) on the inputs, J and the bias by differences in v. On this
// scene the surfaces act on different segments, each deep in contact (outside the smooth model's
// blend band), where the smooth model's analytic chain rule gives the same path: an independent
// reference for x_a, J and the bias.
TEST(GeneralPathMap, ExactModelOnLongerPathsEqualsSmoothOutsideTheBand) {
  const Scene sc = makeScene();
  Muscle exact = sc.mu;
  exact.wrap.model = WrapModel::Exact;
  for (const std::vector<int>& active : kActiveSets) {
    SCOPED_TRACE("active points " + std::to_string(active.size()));
    const Inputs in = inputsAt(sc, active, 0.0, false);
    GeneralPathMap ms, me;
    calcGeneralPathMap(sc.mu, active, in.x, &in.xdot, in.frames, ms);
    calcGeneralPathMap(exact, active, in.x, &in.xdot, in.frames, me);
    // outside the band: the smooth model's wrapped segments are the exact library's
    for (size_t i = 0; i < ms.seg_wrap.size(); ++i) {
      const int w = ms.seg_wrap[i];
      if (w < 0) continue;
      const Mat3 Rt = in.frames[w].R.transpose();
      const double d = calcWrapPenetration(sc.mu.path.wraps[w].surface, Rt * (in.x[i] - in.frames[w].p),
                                           Rt * (in.x[i + 1] - in.frames[w].p));
      EXPECT_GT(d, 1.05 * 0.05 * 0.03) << "segment " << i << " is inside the band (0.05 radius)";
    }
    const double ex = (stackPoints(me.x_a) - stackPoints(ms.x_a)).cwiseAbs().maxCoeff();
    const double eJ = (me.J - ms.J).cwiseAbs().maxCoeff(), pJ = ms.J.cwiseAbs().maxCoeff();
    const double eb = (me.bias - ms.bias).cwiseAbs().maxCoeff(), pb = ms.bias.cwiseAbs().maxCoeff();
    std::printf("  [%zu active points] exact vs smooth: x_a %.2e m, J %.2e of %.2e, bias %.2e of %.2e\n",
                active.size(), ex, eJ, pJ, eb, pb);
    EXPECT_LT(ex, 1e-12);
    EXPECT_LT(eJ, 1e-8 * pJ);
    EXPECT_LT(eb, 1e-6 * pb);
    EXPECT_TRUE(me.seg_wrap.empty());
  }
  // sizes that do not fit
  const Inputs in = inputsAt(sc, {0, 1, 2, 3}, 0.0, false);
  GeneralPathMap map;
  EXPECT_THROW(calcGeneralPathMap(exact, {0, 1, 2}, in.x, nullptr, in.frames, map), std::invalid_argument);
}

}  // namespace
}  // namespace redmax
