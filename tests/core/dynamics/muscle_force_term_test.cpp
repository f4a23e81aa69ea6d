// MuscleForceTerm and the auxiliary states of a System (docs/forward.md):
//   - the generalized force is -F_t dl/dq, dl/dq by central differences of the path length
//     (h = 1e-6, relative 1e-6) on random trees with via and moving points; where OpenSim applies
//     the tension otherwise (a segment within one body, a moving point outside its coordinate's
//     range) as OpenSim does, in closed form on a slider;
//   - the power identity f . qdot = -F_t ldot;
//   - zdot is the model's; states and controls get their offsets and names;
//   - rk45, cvode and the fixed-step methods integrate z (first-order activation against its
//     closed form), a NaN rate is reported with the state's name;
//   - equilibrateStates balances the toy tendon.
#include "core/dynamics/muscle_force_term.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "core/skeleton/kinematics.hpp"
#include "tests/core/dynamics/random_muscle.hpp"
#include "tests/core/dynamics/toy_muscle_model.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

using Models = std::vector<std::shared_ptr<const hill::MuscleModel>>;

double pathLengthAt(const Model& m, const Muscle& mu, const VecX& q) {
  std::vector<Mat4> E;
  calcBodyPoses(m, q, E);
  return calcPathLength(m, mu.path, q, E);
}

struct Scene {
  Model m;
  std::vector<Muscle> muscles;
  Models models;
};

Scene randomScene(unsigned seed) {
  Scene sc{scenes::randomTree(6, seed, scenes::TreeJoints::SimbodyComparable), {}, {}};
  std::mt19937 rng(seed);
  for (int k = 0; k < 3; ++k) {
    sc.muscles.push_back(test::randomViaMuscle(sc.m, rng, 0.0, "m" + std::to_string(k)));
    auto toy = std::make_shared<test::ToyMuscleModel>();
    toy->l_ts = 0.1 * k;
    sc.models.push_back(toy);
  }
  sc.models[1] = nullptr;  // a muscle without a model: no states, no force
  return sc;
}

TEST(MuscleForceTerm, GeneralizedForceIsMinusTendonForceTimesDlDq) {
  for (unsigned seed : {3u, 11u, 29u}) {
    const Scene sc = randomScene(seed);
    System sys(sc.m);
    auto term = std::make_shared<MuscleForceTerm>(sc.m, sc.muscles, sc.models);
    sys.addTerm(term);
    ASSERT_EQ(sys.numStates(), 4);
    ASSERT_EQ(sys.numControls(), 2);
    std::mt19937 rng(seed + 1);
    State s = test::randomState(sc.m.nr(), rng);
    s.z = sys.defaultState().z;
    s.z[1] = 0.05;
    DynamicsWorkspace ws(sys);
    ws.controls = VecX::Constant(2, 0.4);
    System bare(sc.m);
    DynamicsWorkspace wb(bare);
    sys.calcMassAndForce(s, ws);
    bare.calcMassAndForce(s, wb);
    const VecX f_muscle = ws.f - wb.f;
    // expected: -sum_m F_t dl/dq with central differences of the length
    VecX expected = VecX::Zero(sc.m.nr());
    double power = 0.0;
    const double h = 1e-6;
    for (int k = 0; k < static_cast<int>(term->actuated().size()); ++k) {
      const Muscle& mu = term->actuated()[k].muscle;
      const hill::MuscleOutput out = term->calcOutput(sc.m, s, TermContext(ws.sk, nullptr, 0), k);
      VecX dl(sc.m.nr());
      for (int j = 0; j < sc.m.nr(); ++j) {
        VecX qp = s.q, qm = s.q;
        qp[j] += h;
        qm[j] -= h;
        dl[j] = (pathLengthAt(sc.m, mu, qp) - pathLengthAt(sc.m, mu, qm)) / (2 * h);
      }
      double len, speed;
      VecX dl_an;
      term->calcPath(sc.m, s, ws.sk, k, len, speed, dl_an);
      EXPECT_NEAR(len, pathLengthAt(sc.m, mu, s.q), 1e-12);
      EXPECT_LE((dl_an - dl).norm(), 1e-6 * (1 + dl.norm())) << "seed " << seed << " muscle " << k;
      EXPECT_NEAR(speed, dl.dot(s.qdot), 1e-6 * (1 + std::abs(speed)));
      // tendon force of the toy at the state: k (l - lf - l_ts)
      const auto& toy = static_cast<const test::ToyMuscleModel&>(*term->actuated()[k].model);
      const double lf = s.z[term->actuated()[k].z_offset + 1];
      const double Ft = toy.k * (len - lf - toy.l_ts);
      EXPECT_NEAR(out.tendon_force, Ft, 1e-9 * (1 + std::abs(Ft)));
      expected -= Ft * dl;
      // the path's rate along the motion, by a central difference in time (not through dl/dq)
      const double ldot = (pathLengthAt(sc.m, mu, s.q + h * s.qdot) - pathLengthAt(sc.m, mu, s.q - h * s.qdot)) / (2 * h);
      power -= Ft * ldot;
    }
    EXPECT_LE((f_muscle - expected).norm(), 1e-6 * (1 + expected.norm())) << "seed " << seed;
    // power identity f . qdot = -sum F_t ldot, ldot differenced along the motion
    EXPECT_NEAR(f_muscle.dot(s.qdot), power, 1e-6 * (1 + std::abs(power)));
  }
}

TEST(MuscleForceTerm, NamesOffsetsDefaultsAndRates) {
  const Scene sc = randomScene(7);
  System sys(sc.m);
  auto term = std::make_shared<MuscleForceTerm>(sc.m, sc.muscles, sc.models);
  sys.addTerm(term);
  const std::vector<std::string> names = sys.stateNames();
  ASSERT_EQ(names.size(), 4u);
  EXPECT_EQ(names[0], "/forceset/m0/activation");
  EXPECT_EQ(names[1], "/forceset/m0/fiber_length");
  EXPECT_EQ(names[2], "/forceset/m2/activation");
  EXPECT_EQ(sys.controlNames(), (std::vector<std::string>{"m0", "m2"}));
  const State s0 = sys.defaultState();
  EXPECT_EQ(s0.z, (VecX(4) << 0.05, 0.1, 0.05, 0.1).finished());
  DynamicsWorkspace ws(sys);
  ws.controls = (VecX(2) << 1.0, 0.0).finished();
  sys.forwardDynamics(s0, ws);
  ASSERT_EQ(ws.zdot.size(), 4);
  EXPECT_NEAR(ws.zdot[0], (1.0 - 0.05) / 0.02, 1e-12);
  EXPECT_NEAR(ws.zdot[2], (0.0 - 0.05) / 0.02, 1e-12);
  // calcStateDerivatives alone gives the same rates
  const VecX zd = ws.zdot;
  sys.calcStateDerivatives(s0, ws);
  EXPECT_EQ(ws.zdot, zd);
  // equilibrium: lfdot = 0
  State se = s0;
  sys.equilibrateStates(se, ws);
  sys.calcStateDerivatives(se, ws);
  EXPECT_NEAR(ws.zdot[1], 0.0, 1e-9);
  EXPECT_NEAR(ws.zdot[3], 0.0, 1e-9);
}

// constant excitation u from a = a0: a(t) = u + (a0 - u) exp(-t / tau), whatever the skeleton does
class ConstantControl final : public Controller {
 public:
  explicit ConstantControl(double u) : u_(u) {}
  std::string name() const override { return "constant"; }
  void addControls(const Model&, const State&, const SkeletonWorkspace&, Eigen::Ref<VecX> u) const override {
    u.array() += u_;
  }

 private:
  double u_;
};

TEST(MuscleForceTerm, IntegratorsIntegrateTheAuxiliaryStates) {
  const Scene sc = randomScene(5);
  Models act_only;
  for (const auto& m : sc.models) {
    if (!m) {
      act_only.push_back(nullptr);
      continue;
    }
    auto toy = std::make_shared<test::ToyMuscleModel>();
    toy->with_fiber = false;
    toy->k = 50.0;  // soft, so that the skeleton moves gently
    act_only.push_back(toy);
  }
  System sys(sc.m);
  sys.addTerm(std::make_shared<MuscleForceTerm>(sc.m, sc.muscles, act_only));
  sys.addController(std::make_shared<ConstantControl>(0.7));
  const double T = 0.05, tau = 0.02, a0 = 0.05, u = 0.7;
  const double exact = u + (a0 - u) * std::exp(-T / tau);
  struct Case {
    const char* name;
    double tol;
  };
  for (const Case c : {Case{"rk45", 1e-6}, Case{"cvode", 1e-4}, Case{"euler", 2e-3}, Case{"bdf1", 2e-3},
                       Case{"sdirk2", 2e-3}, Case{"symplectic", 2e-3}}) {
    IntegratorOptions opt;
    opt.dt = 1e-4;
    opt.rtol = 1e-8;
    opt.atol = 1e-10;
    auto integ = makeIntegrator(c.name, opt);
    State s = sys.defaultState();
    integ->advance(sys, s, T);
    ASSERT_EQ(s.z.size(), 2) << c.name;
    EXPECT_NEAR(s.z[0], exact, c.tol) << c.name;
    EXPECT_NEAR(s.z[1], exact, c.tol) << c.name;
    EXPECT_TRUE(s.q.allFinite()) << c.name;
  }
}

TEST(MuscleForceTerm, NanRateNamesTheState) {
  const Scene sc = randomScene(5);
  Models bad = sc.models;
  auto toy = std::make_shared<test::ToyMuscleModel>();
  toy->nan_rate = true;
  bad[2] = toy;
  System sys(sc.m);
  sys.addTerm(std::make_shared<MuscleForceTerm>(sc.m, sc.muscles, bad));
  for (const char* name : {"rk45", "euler"}) {
    auto integ = makeIntegrator(name, IntegratorOptions{});
    State s = sys.defaultState();
    try {
      integ->advance(sys, s, 0.01);
      ADD_FAILURE() << name << ": no error";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("/forceset/m2/activation"), std::string::npos) << name << ": " << e.what();
    }
  }
}

TEST(MuscleForceTerm, StateOfTheWrongSizeIsRefused) {
  const Scene sc = randomScene(5);
  System sys(sc.m);
  sys.addTerm(std::make_shared<MuscleForceTerm>(sc.m, sc.muscles, sc.models));
  State s = sys.defaultState();
  s.z.resize(1);
  auto integ = makeIntegrator("rk45", IntegratorOptions{});
  EXPECT_THROW(integ->advance(sys, s, 0.01), std::invalid_argument);
  DynamicsWorkspace ws(sys);
  EXPECT_THROW(sys.calcMassAndForce(s, ws), ModelError);
}

// The tension is applied as OpenSim's GeometryPath::produceForces applies it (docs/forward.md §3),
// in closed form on a slider: ground point P1 = (0, 1, 0); a body on a prismatic joint along x
// (coordinate q) carries a moving point P2 with x location a clamp(q, -0.1, 0.1) and a fixed point
// P3 = (0, -0.5, 0). Segment P1-P2 spans two bodies: the tension acts along it, with the moving
// point's own term at the unclamped q (getdPointdQ): dl/dq applied = d1 (1 + a), inside and outside
// the range (d1: the x component of the unit vector P1 -> P2). Segment P2-P3 lies in one body: no
// force, although the moving point changes its length there. The lengthening speed runs over every
// segment with the unclamped velocity (getVelocity): (d1 (1 + a) - a d2) qdot, d2 the x component of
// the unit vector P2 -> P3. The length's own gradient differs: d1 (1 + a) - a d2 inside, d1 outside.
TEST(MuscleForceTerm, AppliesTheTensionAsOpenSimsGeometryPath) {
  ModelBuilder b("slider");
  b.addBody("link", 1.0, Vec3::Zero(), Mat3::Identity(), -1, "slide", Prismatic{});
  const Model m = b.finalize();
  const double a = 0.5;
  Muscle mu;
  mu.name = "m";
  PathPoint moving = makeMovingPoint(0, 0, {std::make_shared<const LinearFunction>(a, 0.0), nullptr, nullptr});
  moving.clamp = true;
  moving.clamp_lo = -0.1;
  moving.clamp_hi = 0.1;
  mu.path.points = {makeFixedPoint(-1, Vec3(0.0, 1.0, 0.0)), moving, makeFixedPoint(0, Vec3(0.0, -0.5, 0.0))};
  const MuscleForceTerm term(m, {mu}, {std::make_shared<test::ToyMuscleModel>()});
  for (double q : {0.05, 0.25, -0.3}) {
    State s;
    s.q = VecX::Constant(1, q);
    s.qdot = VecX::Constant(1, 0.7);
    SkeletonWorkspace sk(m);
    calcKinematics(m, s, sk);
    double length = 0.0, speed = 0.0;
    VecX dl_dq;
    term.calcPath(m, s, sk, 0, length, speed, dl_dq);
    const double c = std::clamp(q, -0.1, 0.1);
    const Vec3 p1(0.0, 1.0, 0.0), p2(q + a * c, 0.0, 0.0), p3(q, -0.5, 0.0);
    const double d1 = (p2 - p1).normalized().x(), d2 = (p3 - p2).normalized().x();
    EXPECT_NEAR(length, (p2 - p1).norm() + (p3 - p2).norm(), 1e-15) << q;
    ASSERT_EQ(dl_dq.size(), 1);
    EXPECT_NEAR(dl_dq[0], d1 * (1.0 + a), 1e-14) << q;
    EXPECT_NEAR(speed, (d1 * (1.0 + a) - a * d2) * 0.7, 1e-14) << q;
    // and not the length's gradient, which differs here by a d2 (inside) or a d1 (outside)
    const double gradient = q > -0.1 && q < 0.1 ? d1 * (1.0 + a) - a * d2 : d1;
    EXPECT_GT(std::abs(dl_dq[0] - gradient), 0.02) << q;
    EXPECT_NEAR((pathLengthAt(m, mu, VecX::Constant(1, q + 1e-6)) - pathLengthAt(m, mu, VecX::Constant(1, q - 1e-6))) / 2e-6,
                gradient, 1e-8)
        << q;
  }
}

}  // namespace
}  // namespace redmax
