// The discrete adjoint (core/adjoint/adjoint.hpp, docs/gradients.md): a closed form for a linear
// spring-mass, and central differences of whole simulations for a double pendulum with springs
// and dampers and for a constrained four-bar, with every fixed-step integrator that has an adjoint.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/adjoint/adjoint.hpp"
#include "core/dynamics/constraints/point_constraint.hpp"
#include "../dynamics/constraint_scenes.hpp"
#include "tests/core/adjoint/adjoint_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using adjoint::ForceParameter;
using adjoint::Objective;
using adjoint::Problem;

// a body of mass m on a slider along x with a joint spring k and damper d, no gravity
Model springMass(double m, double k, double d) {
  ModelBuilder b("spring_mass");
  b.setGravity(Vec3::Zero());
  const int body = b.addBody("block", m, Vec3::Zero(), Mat3::Identity() * 0.01, -1, "slider", Prismatic{});
  b.coordinate(body, 0).stiffness = k;
  b.coordinate(body, 0).damping = d;
  return b.finalize();
}

using test::problemFor;

// Closed form of the discrete run: both steps are linear in y = (x, v) and F for a linear
// spring-mass, y+ = A y + b F, so the sensitivities S = dy/d(F, x0, v0) follow S+ = A S + (b 0 0).
struct Discrete {
  double x = 0.0, v = 0.0;
  Eigen::Matrix<double, 2, 3> S = Eigen::Matrix<double, 2, 3>::Zero();
};
Discrete closedForm(const std::string& integrator, double m, double k, double d, double h, int N, double F,
                    double x0, double v0) {
  Eigen::Matrix2d A;
  Eigen::Vector2d b;
  if (integrator == "euler") {
    // v+ = v + h (F - k x - d v) / m,  x+ = x + h v+   [D Eq. 4.20]
    A << 0.0, 0.0, -h * k / m, 1.0 - h * d / m;
    b << 0.0, h / m;
  } else {
    // (m + h d + h^2 k) v+ = m v + h (F - k x)   [D Eq. 4.80]
    const double c = m + h * d + h * h * k;
    A << 0.0, 0.0, -h * k / c, m / c;
    b << 0.0, h / c;
  }
  // x+ = x + h v+
  A.row(0) = Eigen::RowVector2d(1.0, 0.0) + h * A.row(1);
  b[0] = h * b[1];
  Discrete r;
  Eigen::Vector2d y(x0, v0);
  r.S(0, 1) = 1.0;
  r.S(1, 2) = 1.0;
  for (int i = 0; i < N; ++i) {
    y = A * y + b * F;
    r.S = (A * r.S).eval();
    r.S.col(0) += b;
  }
  r.x = y[0];
  r.v = y[1];
  return r;
}

class SpringMass : public ::testing::TestWithParam<std::string> {};

// both routes of the step Jacobians (docs/gradients.md §2): central differences of the step, and
// the analytic ones (§2.1), which meet the closed form to round-off
TEST_P(SpringMass, GradientEqualsTheClosedFormOfTheDiscreteRun) {
  const double m = 2.0, k = 50.0, d = 0.4, T = 0.5, h = 1e-3;
  const double F = 3.0, x0 = -0.05, v0 = 0.2;
  const auto sys = std::make_shared<System>(springMass(m, k, d));
  Problem pr = problemFor(sys, GetParam(), T, h);
  pr.forces = {{0, 0, 1}};
  pr.initial_q = {0};
  pr.initial_qdot = {0};
  Objective obj;
  obj.points.push_back({0, Vec3::Zero(), Vec3(0.3, 0.0, 0.0), 1.0});
  obj.speed_weight = 0.5;
  obj.effort_weight = 0.01;
  VecX p(3);
  p << F, x0, v0;
  const Discrete c = closedForm(GetParam(), m, k, d, h, 500, F, x0, v0);
  Eigen::RowVector3d g = (c.x - 0.3) * c.S.row(0) + 0.5 * c.v * c.S.row(1);
  g[0] += 2.0 * 0.01 * T * F;
  for (const char* route : {"differences", "analytic"}) {
    pr.step_jacobians = route;
    const adjoint::Result r = adjoint::evaluate(pr, obj, p, true);
    EXPECT_EQ(r.analytic_jacobians, std::string(route) == "analytic");
    EXPECT_NEAR(r.final.q[0], c.x, 1e-13);
    const double J = 0.5 * (c.x - 0.3) * (c.x - 0.3) + 0.25 * c.v * c.v + 0.01 * T * F * F;
    EXPECT_NEAR(r.objective, J, 1e-13);
    const double err = adjoint::worstRelativeError(r.gradient, g.transpose());
    std::printf("[ measured ] %s, %s step Jacobians: closed form %.2e relative\n", GetParam().c_str(), route, err);
    // measured: differences 1.9e-10 (euler), 1.2e-10 (bdf1); analytic 1.3e-14, 4.6e-15 (500 steps of round-off)
    EXPECT_LE(err, std::string(route) == "analytic" ? 1e-12 : 1e-9)
        << route << "\nadjoint " << r.gradient.transpose() << "\nclosed form " << g;
  }
}

TEST_P(SpringMass, TendsToTheContinuousClosedForm) {
  // undamped: x(T) = F/k (1 - cos wT) + x0 cos wT + v0/w sin wT, so dx(T)/dF = (1 - cos wT)/k;
  // the discrete run's derivative differs by O(h)
  const double m = 2.0, k = 50.0, T = 0.5, w = std::sqrt(k / m);
  for (double h : {1e-3, 1e-4}) {
    const auto sys = std::make_shared<System>(springMass(m, k, 0.0));
    Problem pr = problemFor(sys, GetParam(), T, h);
    pr.forces = {{0, 0, 1}};
    Objective obj;
    obj.points.push_back({0, Vec3::Zero(), Vec3(-10.0, 0.0, 0.0), 1.0});  // dJ/dF = (x - target) dx/dF
    VecX p(1);
    p << 1.0;
    const adjoint::Result r = adjoint::evaluate(pr, obj, p, true);
    const double dxdF = r.gradient[0] / (r.final.q[0] + 10.0);
    const double exact = (1.0 - std::cos(w * T)) / k;
    // measured: euler 8.3e-4 (h = 1e-3), 8.3e-5 (h = 1e-4); bdf1 (more dissipative) 2.78e-3,
    // 2.78e-4 relative: first order in h
    const double factor = GetParam() == "euler" ? 1.0 : 3.0;
    EXPECT_LE(std::abs(dxdF - exact) / exact, factor * h) << "h = " << h;
  }
}

INSTANTIATE_TEST_SUITE_P(Integrators, SpringMass, ::testing::Values("euler", "bdf1"));

class AgainstCentralDifferences : public ::testing::TestWithParam<std::string> {};

TEST_P(AgainstCentralDifferences, DoublePendulumWithSpringsAndDampers) {
  ModelBuilder b(scenes::doublePendulum(1.0, 1.0));
  for (int c = 0; c < 2; ++c) {
    b.coordinateAt(c).stiffness = 3.0 + c;
    b.coordinateAt(c).rest_value = 0.2;
    b.coordinateAt(c).damping = 0.2;
  }
  const auto sys = std::make_shared<System>(b.finalize());
  Problem pr = problemFor(sys, GetParam(), 0.3, 0.01);
  pr.initial.q << 0.4, -0.3;
  pr.forces = {{0, 0, 3}, {0, 1, 3}, {0, 2, 3}, {1, 0, 1}};
  pr.initial_q = {1};
  pr.initial_qdot = {0};
  Objective obj;
  obj.points.push_back({1, Vec3(0, -1, 0), Vec3(1.0, -1.2, 0.1), 1.0});
  obj.speed_weight = 0.1;
  obj.effort_weight = 0.01;
  std::mt19937 rng(19);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 3; ++trial) {
    VecX p(6);
    for (int i = 0; i < 6; ++i) p[i] = u(rng);
    const VecX fd = adjoint::finiteDifferenceGradient(pr, obj, p);
    for (const char* route : {"differences", "analytic"}) {
      pr.step_jacobians = route;
      const adjoint::Result r = adjoint::evaluate(pr, obj, p, true);
      const double err = adjoint::worstRelativeError(r.gradient, fd);
      std::printf("[ measured ] %s, %s step Jacobians: %.2e\n", GetParam().c_str(), route, err);
      // measured over euler, bdf1, sdirk2: differences 5.2e-11 .. 4.1e-10, analytic 9.2e-12 .. 4.8e-10
      // (the largest in the reference, whose error it shares with the differenced route); the issue asks 1e-6
      EXPECT_LE(err, 3e-9) << route << "\nadjoint " << r.gradient.transpose() << "\ndifferences " << fd.transpose();
    }
  }
}

TEST_P(AgainstCentralDifferences, FourBarWithAClosedLoop) {
  const redmax::testing::FourBar fb;
  auto sys = std::make_shared<System>(fb.model);
  sys->addConstraint(std::make_shared<HingePointConstraint>(fb.model, fb.rocker_body, fb.tip_rocker(), -1,
                                                            fb.pivot_world(), -1, Vec3::UnitZ()));
  Problem pr = problemFor(sys, GetParam(), 0.2, 0.01);
  pr.initial.q = fb.closedQ(0.7);
  pr.initial.qdot = fb.closedQdot(pr.initial.q, 0.5);
  pr.forces = {{0, 0, 2}, {0, 1, 2}, {2, 0, 1}};
  Objective obj;
  obj.points.push_back({fb.coupler_body, Vec3(1.0, 0, 0), Vec3(1.0, 1.5, 0.0), 1.0});
  obj.speed_weight = 0.05;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  VecX p(3);
  for (int i = 0; i < 3; ++i) p[i] = u(rng);
  const adjoint::Result r = adjoint::evaluate(pr, obj, p, true);
  const VecX fd = adjoint::finiteDifferenceGradient(pr, obj, p);
  // measured: 5.2e-10 (euler, bdf1: no springs, the same step), 8.5e-10 (sdirk2) relative (the
  // issue asks 1e-6)
  EXPECT_LE(adjoint::worstRelativeError(r.gradient, fd), 5e-9)
      << "adjoint " << r.gradient.transpose() << "\ndifferences " << fd.transpose();
}

INSTANTIATE_TEST_SUITE_P(Integrators, AgainstCentralDifferences, ::testing::Values("euler", "bdf1", "sdirk2"));

TEST(Adjoint, CostDoesNotGrowWithTheNumberOfForceParameters) {
  const auto sys = std::make_shared<System>(scenes::doublePendulum(1.0, 1.0));
  Problem pr = problemFor(sys, "euler", 0.2, 0.01);
  Objective obj;
  obj.points.push_back({1, Vec3(0, -1, 0), Vec3(1.0, -1.2, 0.0), 1.0});
  for (const char* route : {"differences", "analytic"}) {
    pr.step_jacobians = route;
    long evaluations[2] = {0, 0};
    for (int pieces : {2, 20}) {
      pr.forces.clear();
      for (int c = 0; c < 2; ++c)
        for (int k = 0; k < pieces; ++k) pr.forces.push_back({c, k, pieces});
      const adjoint::Result r = adjoint::evaluate(pr, obj, VecX::Constant(2 * pieces, 0.5), true);
      evaluations[pieces == 20] = r.step_evaluations;
    }
    // differences: forward N, and per step 2 per driven coordinate and 2 per state entry: 20 (1 +
    // 4 + 8); analytic: the forward run's N alone (no step is evaluated again)
    EXPECT_EQ(evaluations[0], std::string(route) == "analytic" ? 20 : 20 * 13) << route;
    EXPECT_EQ(evaluations[1], evaluations[0]) << route;
  }
}

TEST(Adjoint, RefusesWhatItCannotDifferentiate) {
  const auto sys = std::make_shared<System>(scenes::doublePendulum(1.0, 1.0));
  Problem pr = problemFor(sys, "rk45", 0.1, 0.01);
  pr.forces = {{0, 0, 1}};
  EXPECT_THROW(adjoint::evaluate(pr, Objective{}, VecX::Zero(1), true), adjoint::AdjointError);
  pr.integrator = "euler";
  EXPECT_THROW(adjoint::evaluate(pr, Objective{}, VecX::Zero(2), true), adjoint::AdjointError);
  pr.forces = {{5, 0, 1}};
  EXPECT_THROW(adjoint::evaluate(pr, Objective{}, VecX::Zero(1), true), adjoint::AdjointError);
  // hard unilateral constraints (a joint limit) are refused, not silently dropped
  auto limited = std::make_shared<System>(*sys);
  limited->setUnilateral(std::make_shared<UnilateralConstraints>(
      limited->model(), std::vector<CollisionGeometry>{}, std::vector<CollisionPair>{},
      std::vector<JointLimit>{{"q0", 0, -1.0, 1.0, 0.0}}));
  Problem pl = problemFor(limited, "bdf1", 0.1, 0.01);
  pl.forces = {{0, 0, 1}};
  EXPECT_THROW(adjoint::evaluate(pl, Objective{}, VecX::Zero(1), true), adjoint::AdjointError);
}

// ---- excitation parameters (docs/gradients.md §2): a linear first-order "activation" a with
// one control u, adot = (u - a) / tau, pushing the slider mass with F = Fmax a. The run is linear,
// y+ = A y + b u_k with y = (x, v, a), so the gradient with respect to the excitation nodes is a
// matrix product through the hat-function weights (zero where the clamp holds u at a bound).

class ActivationPush final : public ForceTerm {
 public:
  ActivationPush(double tau, double fmax) : tau_(tau), fmax_(fmax) {}
  std::string name() const override { return "activation_push"; }
  void addForce(const Model&, const State& s, const TermContext& ctx, VecX& f) const override {
    f[0] += fmax_ * s.z[ctx.z_offset];
  }
  int numStates() const override { return 1; }
  std::vector<std::string> stateNames() const override { return {"a"}; }
  void calcStateDerivatives(const Model&, const State& s, const TermContext& ctx, Eigen::Ref<VecX> zdot) const override {
    zdot[0] = (ctx.control(0) - s.z[ctx.z_offset]) / tau_;
  }
  int numControls() const override { return 1; }
  std::vector<std::string> controlNames() const override { return {"u"}; }

 private:
  double tau_, fmax_;
};

TEST(AdjointExcitations, NodesAgainstTheClosedFormOfTheDiscreteRunWithTheClamp) {
  const double m = 2.0, tau = 0.04, fmax = 30.0, T = 0.3, h = 1e-3, lo = 0.01, hi = 1.0;
  const int N = 300, K = 4;
  auto sys = std::make_shared<System>(springMass(m, 0.0, 0.0));
  sys->addTerm(std::make_shared<ActivationPush>(tau, fmax));
  Problem pr = problemFor(sys, "euler", T, h);
  pr.initial.z = VecX::Constant(1, 0.05);
  for (int i = 0; i < K; ++i) pr.excitations.push_back({0, i, K, lo, hi});
  Objective obj;
  obj.points.push_back({0, Vec3::Zero(), Vec3(0.4, 0.0, 0.0), 1.0});
  obj.speed_weight = 0.3;
  obj.excitation_weight = 0.02;
  // euler, with the activation's rate at the step's start: v+ = v + h Fmax a / m, x+ = x + h v+,
  // a+ = a + h (u - a) / tau
  Eigen::Matrix3d A;
  A << 1.0, h, h * h * fmax / m,  //
      0.0, 1.0, h * fmax / m,     //
      0.0, 0.0, 1.0 - h / tau;
  const Eigen::Vector3d b(0.0, 0.0, h / tau);
  for (const VecX& p : {VecX((VecX(K) << 0.2, 0.9, 0.5, 0.3).finished()),
                        VecX((VecX(K) << 0.6, 1.8, 0.4, -0.3).finished())}) {  // the second one clamps
    Eigen::Vector3d y(0.0, 0.0, 0.05);
    Eigen::Matrix<double, 3, K> S = Eigen::Matrix<double, 3, K>::Zero();
    Eigen::Matrix<double, 1, K> g_effort = Eigen::Matrix<double, 1, K>::Zero();
    double effort = 0.0;
    for (int k = 0; k < N; ++k) {
      const double s = static_cast<double>(k) * (K - 1) / N;
      const int i0 = static_cast<int>(s);
      Eigen::Matrix<double, 1, K> w = Eigen::Matrix<double, 1, K>::Zero();
      w[i0] = 1.0 - (s - i0);
      w[i0 + 1] = s - i0;
      const double raw = w.dot(p.transpose());
      const double u = std::clamp(raw, lo, hi);
      if (raw < lo || raw > hi) w.setZero();
      y = A * y + b * u;
      S = (A * S).eval() + b * w;
      effort += h * u * u;
      g_effort += 2.0 * h * u * w;
    }
    const adjoint::Result r = adjoint::evaluate(pr, obj, p, true);
    // a term with states of its own other than Hill-type muscles has no derivatives: differenced
    EXPECT_FALSE(r.analytic_jacobians);
    EXPECT_EQ(r.jacobian_note, "auxiliary states of a term other than Hill-type muscles");
    EXPECT_NEAR(r.final.q[0], y[0], 1e-13);
    EXPECT_NEAR(r.final.z[0], y[2], 1e-13);
    const double J = 0.5 * (y[0] - 0.4) * (y[0] - 0.4) + 0.15 * y[1] * y[1] + 0.02 * effort;
    EXPECT_NEAR(r.objective, J, 1e-13);
    const Eigen::Matrix<double, 1, K> g = (y[0] - 0.4) * S.row(0) + 0.3 * y[1] * S.row(1) + 0.02 * g_effort;
    // measured 4.6e-10 and 2.2e-10 relative (the step Jacobians are central differences)
    EXPECT_LE(adjoint::worstRelativeError(r.gradient, g.transpose()), 1e-9)
        << "adjoint " << r.gradient.transpose() << "\nclosed form " << g;
  }
}

TEST(ForceBasis, PiecesHatsAndCubicBSplinesPartitionUnityAndTheSplineIsSmooth) {
  // every shape's basis sums to 1 at every step (a constant force is reproduced exactly); the
  // cubic B-spline starts and ends at its first and last control points, and a force built on it
  // has second differences of order h^2 (C2), where the hats' have kinks of order h
  const int N = 200;
  using Shape = ForceParameter::Shape;
  for (auto [shape, m] : {std::pair{Shape::Pieces, 5}, std::pair{Shape::Linear, 5}, std::pair{Shape::Cubic, 6}}) {
    double worst = 0.0;
    for (int k = 0; k < N; ++k) {
      double sum = 0.0;
      for (int i = 0; i < m; ++i) {
        const double b = adjoint::forceBasis({0, i, m, shape}, k, N);
        EXPECT_GE(b, -1e-15);
        sum += b;
      }
      worst = std::max(worst, std::abs(sum - 1.0));
    }
    EXPECT_LE(worst, 1e-15) << static_cast<int>(shape);
  }
  EXPECT_DOUBLE_EQ(adjoint::forceBasis({0, 0, 6, Shape::Cubic}, 0, N), 1.0);
  // smoothness: the force with control points c_i = i^2, its largest second difference at N and
  // 2N steps: a C2 force's falls as h^2 (ratio 4), a kinked one's as h (ratio 2)
  auto d2 = [&](Shape shape, int m, int n) {
    auto f = [&](int k) {
      double v = 0.0;
      for (int i = 0; i < m; ++i) v += i * i * adjoint::forceBasis({0, i, m, shape}, k, n);
      return v;
    };
    double worst = 0.0;
    for (int k = 1; k + 1 < n; ++k) worst = std::max(worst, std::abs(f(k + 1) - 2 * f(k) + f(k - 1)));
    return worst;
  };
  const double rc = d2(Shape::Cubic, 6, N) / d2(Shape::Cubic, 6, 2 * N);
  const double rl = d2(Shape::Linear, 6, N) / d2(Shape::Linear, 6, 2 * N);
  std::printf("[ measured ] second differences halving the step: cubic B-spline falls %.3f x, piecewise linear %.3f x\n",
              rc, rl);
  EXPECT_NEAR(rc, 4.0, 0.1);
  EXPECT_NEAR(rl, 2.0, 0.1);
}

}  // namespace
}  // namespace redmax
