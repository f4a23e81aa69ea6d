// Derivatives of inverse dynamics with respect to q and qdot (core/dynamics/id_derivatives.hpp)
// against fourth-order central differences of the ID itself, on random trees with every joint
// type, random states and accelerations; and what they hold: dM/dq qddot, df/dq, df/dqdot and
// dJ_mr/dq, each against central differences of M, f and J_mr.
//
// References are fourth-order central differences at 1e-3 (truncation ~1e-12 |tau^(5)|, round-off
// ~eps |tau| / 1e-3 ~ 1e-13 of |tau|; at 1e-4 the round-off made them ten times worse). Measured
// worst errors relative to max(1, |column|_inf), printed by each test: 1.9e-13 (revolute) to
// 2.1e-11 (random trees of every joint type); bound 2e-10, far below an error in any term (a
// missing term is of order 1). The system with limit forces differences at 1e-5 (their transitions
// bend on 0.5 rad): measured 5.0e-10, bound 5e-9.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "core/dynamics/coordinate_actuator_term.hpp"
#include "core/dynamics/id_derivatives.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/muscles/muscle_id_tangent.hpp"
#include "tests/core/dynamics/random_muscle.hpp"
#include "core/dynamics/passive_force_terms.hpp"
#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/dynamics/system.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

constexpr double kBound = 2e-10;

// fourth-order central difference of a vector function of one scalar at x0
template <class F>
VecX diff4(F f, double x0, double h) {
  return (f(x0 - 2.0 * h) - 8.0 * f(x0 - h) + 8.0 * f(x0 + h) - f(x0 + 2.0 * h)) / (12.0 * h);
}

// the same of a function of the state along q_k (speed false) or qdot_k (speed true)
template <class G>
VecX diffState(G g, const State& s, int k, bool speed, double h) {
  return diff4(
      [&](double x) {
        State t = s;
        (speed ? t.qdot : t.q)[k] = x;
        return VecX(g(t));
      },
      speed ? s.qdot[k] : s.q[k], h);
}

// J_mr (dot false) or Jdot_mr (dot true) at t, as one vector
VecX kinematicMatrix(const Model& m, const State& t, bool dot) {
  SkeletonWorkspace sk(m);
  calcKinematics(m, t, sk);
  const MatX& J = dot ? sk.Jdot_mr : sk.J_mr;
  return Eigen::Map<const VecX>(J.data(), J.size());
}

// |a - ref|_inf / max(1, |ref|_inf) for a matrix a and its reference as one vector
double flatError(const MatX& a, const VecX& ref) {
  return (Eigen::Map<const VecX>(a.data(), a.size()) - ref).lpNorm<Eigen::Infinity>() /
         std::max(1.0, ref.lpNorm<Eigen::Infinity>());
}

// worst |a - b| per column relative to max(1, |b column|_inf)
double worstColumnError(const MatX& a, const MatX& b) {
  double worst = 0.0;
  for (Eigen::Index c = 0; c < a.cols(); ++c)
    worst = std::max(worst, (a.col(c) - b.col(c)).lpNorm<Eigen::Infinity>() /
                                std::max(1.0, b.col(c).lpNorm<Eigen::Infinity>()));
  return worst;
}

// a model with joint springs and dampers on every coordinate
Model withSprings(const Model& m, std::mt19937& rng) {
  ModelBuilder b(m);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < m.nr(); ++k) {
    Coordinate& c = b.coordinateAt(k);
    c.stiffness = 20.0 * u(rng);
    c.damping = 2.0 * u(rng);
    c.rest_value = u(rng) - 0.5;
  }
  return b.finalize();
}

struct Differences {
  MatX dq, dqd;
};

Differences idDifferences(const Model& m, const State& s, const VecX& qddot) {
  const int n = m.nr();
  Differences d{MatX(n, n), MatX(n, n)};
  for (int k = 0; k < n; ++k) {
    d.dq.col(k) = diffState([&](const State& t) { return inverseDynamicsRecursive(m, t, qddot); }, s, k, false, 1e-3);
    d.dqd.col(k) = diffState([&](const State& t) { return inverseDynamicsRecursive(m, t, qddot); }, s, k, true, 1e-3);
  }
  return d;
}

TEST(IdDerivatives, SkeletonEqualsCentralDifferencesForEveryJointType) {
  std::mt19937 rng(41);
  double worst = 0.0;
  for (int seed = 0; seed < 6; ++seed) {
    const Model m = withSprings(scenes::randomTree(8, 900 + seed, scenes::TreeJoints::All), rng);
    for (int trial = 0; trial < 3; ++trial) {
      const State s = test::randomState(m.nr(), rng);
      const VecX qddot = test::randomState(m.nr(), rng).qdot;
      MatX dq, dqd;
      skeletonIdDerivatives(m, s, qddot, dq, dqd);
      const Differences d = idDifferences(m, s, qddot);
      worst = std::max({worst, worstColumnError(dq, d.dq), worstColumnError(dqd, d.dqd)});
    }
  }
  std::printf("[ measured ] dtau/dq, dtau/dqdot against central differences: worst %.2e\n", worst);
  EXPECT_LT(worst, kBound);
}

// every JointVariant alternative alone under a single body (so that a joint's own terms, not the
// tree, dominate the columns)
TEST(IdDerivatives, EachJointTypeAlone) {
  std::mt19937 rng(7);
  for (std::size_t index = 0; index < std::variant_size_v<JointVariant>; ++index) {
    const Joint j = scenes::randomJoint(index, rng);
    if (j.nq() == 0) continue;
    ModelBuilder b("one");
    b.addBody("b", 2.0, Vec3(0.05, -0.1, 0.02), Vec3(0.1, 0.2, 0.15).asDiagonal().toDenseMatrix(), -1, "j", j,
              Mat4::Identity(), makeTranslation(Vec3(0.1, -0.2, 0.05)));
    const Model m = b.finalize();
    double worst = 0.0, worst_jdot = 0.0;
    for (int trial = 0; trial < 4; ++trial) {
      const State s = test::randomState(m.nr(), rng, 0.8);
      const VecX qddot = test::randomState(m.nr(), rng).qdot;
      MatX dq, dqd;
      skeletonIdDerivatives(m, s, qddot, dq, dqd);
      const Differences d = idDifferences(m, s, qddot);
      worst = std::max({worst, worstColumnError(dq, d.dq), worstColumnError(dqd, d.dqd)});
      // and Jdot_mr's derivative (the joint's own dSdot/dq is all there is to it here)
      for (int k = 0; k < m.nr(); ++k) {
        MatX tJ, tJdot;
        jacobianDerivatives(m, s, k, tJ, tJdot);
        const VecX ref = diffState([&](const State& t) { return kinematicMatrix(m, t, true); }, s, k, false, 1e-3);
        worst_jdot = std::max(worst_jdot, flatError(tJdot, ref));
      }
    }
    std::printf("[ measured ] %-14s worst %.2e, dJdot_mr/dq %.2e\n", j.typeName().c_str(), worst, worst_jdot);
    EXPECT_LT(worst, kBound) << j.typeName();
    EXPECT_LT(worst_jdot, kBound) << j.typeName();
  }
}

// what the ID derivatives hold: dtau/dq(qddot) - dtau/dq(0) = dM/dq qddot, dtau/dq(0) = -df/dq,
// dtau/dqdot = -df/dqdot, each against differences of the REDMAX route's M and f [D Eq. 4.18];
// dJ_mr/dq_c = Jdot_mr(q, e_c) against differences of J_mr, and the tangent of the kinematic
// recursion (jacobianDerivatives): its dJ_mr against that, its dJdot_mr against differences
TEST(IdDerivatives, MassMatrixForceAndJacobianDerivatives) {
  std::mt19937 rng(3);
  const Model m = withSprings(scenes::randomTree(7, 77, scenes::TreeJoints::All), rng);
  const System sys(m);
  DynamicsWorkspace ws(sys);
  const int n = m.nr();
  double wM = 0.0, wf = 0.0, wfd = 0.0, wJ = 0.0, wJt = 0.0, wJd = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    const State s = test::randomState(n, rng);
    const VecX qddot = test::randomState(n, rng).qdot;
    MatX dq_a, dqd_a, dq_0, dqd_0;
    skeletonIdDerivatives(m, s, qddot, dq_a, dqd_a);
    skeletonIdDerivatives(m, s, VecX::Zero(n), dq_0, dqd_0);
    auto mass = [&](const State& t) {
      sys.calcMassAndForce(t, ws);
      return MatX(ws.M);
    };
    auto force = [&](const State& t) {
      sys.calcMassAndForce(t, ws);
      return VecX(ws.f);
    };
    MatX dMa(n, n), df(n, n), dfd(n, n);
    for (int k = 0; k < n; ++k) {
      dMa.col(k) = diffState([&](const State& t) { return VecX(mass(t) * qddot); }, s, k, false, 1e-3);
      df.col(k) = diffState([&](const State& t) { return force(t); }, s, k, false, 1e-3);
      dfd.col(k) = diffState([&](const State& t) { return force(t); }, s, k, true, 1e-3);
      const MatX dJ = jacobianDerivative(m, s, k);
      wJ = std::max(wJ, flatError(dJ, diffState([&](const State& t) { return kinematicMatrix(m, t, false); }, s, k,
                                                false, 1e-3)));
      // the tangent of the recursion: its dJ equals Jdot at unit speeds, its dJdot the differences
      MatX tJ, tJdot;
      jacobianDerivatives(m, s, k, tJ, tJdot);
      wJt = std::max(wJt, (tJ - dJ).lpNorm<Eigen::Infinity>() / std::max(1.0, dJ.lpNorm<Eigen::Infinity>()));
      wJd = std::max(wJd, flatError(tJdot, diffState([&](const State& t) { return kinematicMatrix(m, t, true); }, s,
                                                     k, false, 1e-3)));
    }
    wM = std::max(wM, worstColumnError(dq_a - dq_0, dMa));
    wf = std::max(wf, worstColumnError(-dq_0, df));
    wfd = std::max(wfd, worstColumnError(-dqd_0, dfd));
  }
  std::printf("[ measured ] dM/dq qddot %.2e, df/dq %.2e, df/dqdot %.2e, dJ_mr/dq %.2e (the recursion's tangent "
              "%.2e from it), dJdot_mr/dq %.2e\n", wM, wf, wfd, wJ, wJt, wJd);
  EXPECT_LT(wJt, 1e-13);  // two exact routes to the same matrix
  EXPECT_LT(wJd, kBound);
  EXPECT_LT(wM, kBound);
  EXPECT_LT(wf, kBound);
  EXPECT_LT(wfd, kBound);
  EXPECT_LT(wJ, kBound);
}

// the system's: springs on coordinates, coordinate limit forces inside and across their
// transitions, coordinate actuators; against differences of System::inverseDynamics
TEST(IdDerivatives, SystemWithPassiveTermsAndActuators) {
  std::mt19937 rng(5);
  const Model m = scenes::randomTree(6, 31, scenes::TreeJoints::All);
  const int n = m.nr();
  System sys(m);
  std::vector<CoordinateLimitForceTerm::Limit> limits;
  for (int k = 0; k < n; k += 2)
    limits.push_back({"limit" + std::to_string(k), k, 0.2, -0.2, 40.0, 30.0, 1.5, 0.5});
  sys.addTerm(std::make_shared<CoordinateLimitForceTerm>(m, limits));
  sys.addTerm(std::make_shared<SpringGeneralizedForceTerm>(
      m, std::vector<SpringGeneralizedForceTerm::Spring>{{"s", 1, 12.0, 0.3, 0.7}}));
  sys.addTerm(std::make_shared<CoordinateActuatorTerm>(
      m, std::vector<CoordinateActuatorTerm::Actuator>{{"u", 0, 3.0}}));
  DynamicsWorkspace ws(sys);
  ws.controls = VecX::Constant(sys.numControls(), 0.4);
  double worst = 0.0;
  for (int trial = 0; trial < 4; ++trial) {
    const State s = test::randomState(n, rng);  // q in [-1, 1]: inside, across and past the transitions
    const VecX qddot = test::randomState(n, rng).qdot;
    MatX dq, dqd;
    std::string why;
    ASSERT_TRUE(systemIdDerivatives(sys, s, qddot, ws, dq, dqd, &why)) << why;
    MatX rq(n, n), rqd(n, n);
    for (int k = 0; k < n; ++k) {
      rq.col(k) = diffState([&](const State& t) { return sys.inverseDynamics(t, qddot, ws); }, s, k, false, 1e-5);
      rqd.col(k) = diffState([&](const State& t) { return sys.inverseDynamics(t, qddot, ws); }, s, k, true, 1e-5);
    }
    worst = std::max({worst, worstColumnError(dq, rq), worstColumnError(dqd, rqd)});
  }
  std::printf("[ measured ] system with limit forces, springs, actuators: worst %.2e\n", worst);
  EXPECT_LT(worst, 5e-9);
}

// Type I and II muscles with mass points (straight, via points with a moving point, a
// conditional point): the mass points' share, against differences of the mass-matrix route
// (System::inverseDynamics, sum_a J_ar^T m_a (J_ar qddot + Jdot_ar qdot - g)); and the dual pass's
// value equals the optimized path-wise pass (addMuscleInverseDynamics)
// (dq, dqd) column by column against fourth-order differences of tau at the step h1; a column whose
// difference at h2 disagrees with it by more than 1e-7 of the column (a stencil across a kink:
// J_ar jumps where a mass point passes a via point or a tangent point, core/muscles/path.hpp) is
// left out and counted, and with `speeds_follow` the speed column of such a coordinate too (formed
// from the same stencil). A column whose stencil meets a degenerate path (MuscleError) is skipped.
struct ColumnCheck {
  double worst = 0.0;
  int columns = 0, kinked = 0;
};
template <class Tau>
void checkColumns(Tau tau, const State& s, const MatX& dq, const MatX& dqd, double h1, double h2, bool speeds_follow,
                  ColumnCheck& out) {
  const int n = static_cast<int>(s.q.size());
  std::vector<char> kinked_q(static_cast<size_t>(n), 0);
  for (int k = 0; k < 2 * n; ++k) {
    const bool speed = k >= n;
    const int c = speed ? k - n : k;
    VecX d1, d2;
    try {
      d1 = diffState(tau, s, c, speed, h1);
      d2 = diffState(tau, s, c, speed, h2);
    } catch (const MuscleError&) {
      continue;
    }
    const double scale = std::max(1.0, d1.lpNorm<Eigen::Infinity>());
    ++out.columns;
    if ((d1 - d2).lpNorm<Eigen::Infinity>() > 1e-7 * scale || (speed && speeds_follow && kinked_q[c])) {
      ++out.kinked;
      if (!speed) kinked_q[c] = 1;
      continue;
    }
    const VecX got = speed ? VecX(dqd.col(c)) : VecX(dq.col(c));
    out.worst = std::max(out.worst, (got - d1).lpNorm<Eigen::Infinity>() / scale);
  }
}

TEST(IdDerivatives, TypeOneAndTwoMusclesWithMass) {
  std::mt19937 rng(29);
  double worst_value = 0.0, effect = 0.0;
  ColumnCheck check;
  for (int seed = 0; seed < 4; ++seed) {
    const Model m = scenes::randomTree(7, 640 + seed, scenes::TreeJoints::All);
    const int n = m.nr();
    std::vector<Muscle> muscles = {test::straightMuscle(m, rng, 0.8), test::conditionalMuscle(m, rng, 1.5)};
    for (int k = 0; k < 3; ++k) muscles.push_back(test::randomViaMuscle(m, rng, 0.5 + k, "via" + std::to_string(k)));
    System sys(m);
    sys.addTerm(std::make_shared<MuscleTerm>(m, muscles));
    DynamicsWorkspace ws(sys);
    for (int trial = 0; trial < 2; ++trial) {
      const State s = test::randomState(n, rng);
      const VecX qddot = test::randomState(n, rng).qdot;
      MatX dq, dqd;
      std::string why;
      ASSERT_TRUE(systemIdDerivatives(sys, s, qddot, ws, dq, dqd, &why)) << why;
      // a mass point crossing a via point (or a conditional point switching) within a stencil puts
      // a kink in tau there: such columns are left out and counted (checkColumns). The reference
      // differences at 2.5e-4: the paths' curvature gave 1.8e-9 of truncation at 1e-3 (falling
      // 16-fold per halving)
      checkColumns([&](const State& t) { return sys.inverseDynamics(t, qddot, ws); }, s, dq, dqd, 2.5e-4, 5e-4, false,
                   check);
      MatX bq, bqd;
      skeletonIdDerivatives(m, s, qddot, bq, bqd);
      effect = std::max(effect, (dq - bq).lpNorm<Eigen::Infinity>() / dq.lpNorm<Eigen::Infinity>());
      // the dual pass's value against the path-wise pass, muscle by muscle
      RecursiveIdWorkspace rid(m);
      recursiveIdForward(m, s, qddot, rid);
      std::vector<BodyWorldMotion> world;
      calcBodyWorldMotion(rid.motion(), world);
      for (const Muscle& mu : muscles) {
        std::vector<Vec6> w1(m.nb(), Vec6::Zero()), w2(m.nb(), Vec6::Zero()), ww(m.nb(), Vec6::Zero());
        VecX t1 = VecX::Zero(n), t2 = VecX::Zero(n), zero = VecX::Zero(n);
        MuscleIdTangentScratch tsc;
        addMuscleIdShareTangent(mu, s, qddot, zero, zero, world, nullptr, m.gravity(), w1, t1, nullptr, nullptr, tsc);
        MuscleKinematics mk;
        initMuscleKinematics(m, mu, mk);
        MuscleIdScratch sc;
        addMuscleInverseDynamics(m, s, qddot, world, m.gravity(), mu, mk, sc, ww, t2);
        addWorldWrenches(world, ww, w2);
        double scale = 1.0, err = (t1 - t2).lpNorm<Eigen::Infinity>();
        for (int b = 0; b < m.nb(); ++b) {
          scale = std::max(scale, w2[b].lpNorm<Eigen::Infinity>());
          err = std::max(err, (w1[b] - w2[b]).lpNorm<Eigen::Infinity>());
        }
        worst_value = std::max(worst_value, err / scale);
      }
    }
  }
  std::printf("[ measured ] Type I/II muscles with mass: derivatives %.2e (%d of %d columns left out at a "
              "kink); dual pass value %.2e; the muscles' share of dtau/dq: %.0f%% of its largest entry\n",
              check.worst, check.kinked, check.columns, worst_value, 100 * effect);
  EXPECT_LT(check.worst, 5e-10);  // measured 1.2e-10: the references' round-off at their smaller step
  EXPECT_LE(check.kinked, check.columns / 10);
  EXPECT_LT(worst_value, 1e-13);
  EXPECT_GT(effect, 1e-2);  // the muscles' share is not negligible in these derivatives
}

TEST(IdDerivatives, TypeThreeMusclesByLocalDifferences) {
  // the smooth wrap model over each surface type; the share's derivatives are a muscle-local
  // fourth-order difference at 1e-4 (addWrappingMuscleIdDerivatives), the reference a
  // fourth-order difference of the whole system's ID at 3e-5 (its truncation at 2.5e-4 was 4.6e-9
  // here). A column whose reference disagrees with the difference at 2e-4, a stencil wider than
  // the local one, is at a kink (the ellipsoid's and torus's blends, a mass point meeting a
  // tangent point) and is left out and counted, and so is the speed column of a coordinate at a
  // kink (it is formed from the same stencil's dJ/dq: 2.2e-8 on this torus state).
  const Model m = scenes::revoluteChain(3);
  const int n = m.nr();
  std::mt19937 rng(37);
  const WrapSurface surfaces[] = {WrapSurface::makeCylinder(0.08, 0.4), WrapSurface::makeSphere(0.1),
                                  WrapSurface::makeEllipsoid(Vec3(0.14, 0.1, 0.12)),
                                  WrapSurface::makeTorus(0.05, 0.15)};
  double effect = 0.0;
  int wrapped = 0;
  ColumnCheck check;
  for (int k = 0; k < 4; ++k) {
    const std::vector<Muscle> muscles = {test::chainWrapMuscle(surfaces[k], WrapModel::Smooth, "wrap" + std::to_string(k), 1.5),
                                         test::straightMuscle(m, rng, 0.7)};
    System sys(m);
    sys.addTerm(std::make_shared<MuscleTerm>(m, muscles));
    DynamicsWorkspace ws(sys);
    std::string why;
    ASSERT_TRUE(systemIdDerivativesAvailable(sys, &why)) << why;
    for (int trial = 0, tested = 0; trial < 200 && tested < 3; ++trial) {
      const State s = test::randomState(n, rng, 1.2, 2.0);
      const VecX qddot = test::randomState(n, rng).qdot;
      MatX dq, dqd;
      try {
        test::evalMuscle(m, muscles[0], s);  // end points inside the surface throw
        ASSERT_TRUE(systemIdDerivatives(sys, s, qddot, ws, dq, dqd, &why)) << why;
      } catch (const MuscleError&) {
        continue;
      }
      wrapped += test::offStraightLine(test::evalMuscle(m, muscles[0], s)) > 1e-9;
      ++tested;
      checkColumns([&](const State& t) { return sys.inverseDynamics(t, qddot, ws); }, s, dq, dqd, 3e-5, 2e-4, true,
                   check);
      MatX bq, bqd;
      skeletonIdDerivatives(m, s, qddot, bq, bqd);
      effect = std::max(effect, (dq - bq).lpNorm<Eigen::Infinity>() / dq.lpNorm<Eigen::Infinity>());
    }
  }
  std::printf("[ measured ] Type III muscles with mass (4 surfaces, smooth model): derivatives %.2e (%d of %d "
              "columns left out at a kink; %d of the states wrapped); the muscles' share of dtau/dq: %.0f%% of its "
              "largest entry\n",
              check.worst, check.kinked, check.columns, wrapped, 100 * effect);
  // measured 5.4e-9: a torus state whose own references at 3e-5 and 2e-4 differ by 3.0e-9 (the
  // other columns below 1e-9)
  EXPECT_LT(check.worst, 2e-8);
  EXPECT_LE(check.kinked, check.columns / 10);
  EXPECT_GE(wrapped, 6);
  EXPECT_GT(effect, 1e-2);
}

TEST(IdDerivatives, LimitForceDerivativesAcrossTheTransition) {
  const CoordinateLimitForceTerm::Limit l{"l", 0, 0.5, -0.3, 80.0, 50.0, 2.0, 0.1};
  double worst = 0.0;
  for (double q = -0.6; q <= 0.8; q += 0.0137) {
    for (double v : {-1.3, 0.0, 0.7}) {
      double dq = 0.0, dv = 0.0;
      CoordinateLimitForceTerm::forceDerivatives(l, q, v, dq, dv);
      const double h = 1e-6;
      const double rq = (CoordinateLimitForceTerm::force(l, q + h, v) - CoordinateLimitForceTerm::force(l, q - h, v)) / (2 * h);
      const double rv = (CoordinateLimitForceTerm::force(l, q, v + h) - CoordinateLimitForceTerm::force(l, q, v - h)) / (2 * h);
      worst = std::max({worst, std::abs(dq - rq) / std::max(1.0, std::abs(rq)), std::abs(dv - rv)});
    }
  }
  std::printf("[ measured ] CoordinateLimitForce derivatives: worst %.2e\n", worst);
  EXPECT_LT(worst, 1e-6);  // second-order differences at 1e-6 of a C2 force of stiffness 80 / 0.1
}

TEST(IdDerivatives, RefusesWhatHasNoWrittenDerivatives) {
  const Model m = scenes::randomTree(4, 12, scenes::TreeJoints::All);
  System sys(m);
  sys.addTerm(std::make_shared<SpringGeneralizedForceTerm>(
      m, std::vector<SpringGeneralizedForceTerm::Spring>{{"s", 0, 1.0, 0.0, 0.0}}));
  DynamicsWorkspace ws(sys);
  std::mt19937 rng(1);
  const State s = test::randomState(m.nr(), rng);
  MatX dq, dqd;
  std::string why;
  EXPECT_TRUE(systemIdDerivatives(sys, s, VecX::Zero(m.nr()), ws, dq, dqd, &why));
  ws.loads.point_forces.push_back({0, Vec3::Zero(), Vec3(1.0, 0.0, 0.0)});
  EXPECT_FALSE(systemIdDerivatives(sys, s, VecX::Zero(m.nr()), ws, dq, dqd, &why));
  EXPECT_EQ(why, "external loads");
}

}  // namespace
}  // namespace redmax
