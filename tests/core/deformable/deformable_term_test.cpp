// DeformableTerm [D Sec. 4.6.3, Eq. 4.90-4.95] against finite differences: forces against the
// energy, K = -df/dq against differences of f in q and D = -df/dqdot against differences in qdot,
// for free nodes, nodes on three bodies of a 3-D chain (cross blocks and the geometric stiffness)
// and nodes fixed in the world, with the co-rotated FEM block deformed and rotated by the chain.
#include <gtest/gtest.h>

#include <random>

#include "core/deformable/deformable_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

struct Scene {
  System sys;
  std::shared_ptr<const DeformableTerm> fem, strand;
};

// a 3-link chain (axes z, x, y); an FEM block on link 2 (its x = 0 face attached) and a strand
// from link 1 through two free nodes to a node fixed in the world
Scene makeScene(double alpha, double beta, bool qvv, MassModel mass = MassModel::Lumped) {
  Scene sc{System(scenes::revoluteChain(3)), nullptr, nullptr};
  DeformableTermOptions opt;
  opt.quadratic_velocity = qvv;
  TetMesh mesh = makeBoxTetMesh(Vec3(0.2, 0.1, 0.1), 2, 1, 1, Vec3(0.0, -1.25, -0.05));
  DeformableBody fem = makeFemBody(mesh, 2e4, 0.3, 1000.0, mass);
  fem.rayleigh_mass = alpha;
  fem.rayleigh_stiffness = beta;
  std::vector<NodeAttachment> att;
  for (int n = 0; n < mesh.numNodes(); ++n)
    if (mesh.nodes[n].x() < 1e-12) att.push_back({n, 2});
  sc.fem = addDeformableBody(sc.sys, fem, att, opt);
  DeformableBody strand = makeStrand({Vec3(0.1, -0.7, 0.05), Vec3(0.3, -0.5, 0.1), Vec3(0.6, -0.6, 0), Vec3(0.9, -0.5, 0)}, 0.2, 30.0);
  strand.rayleigh_mass = alpha;
  strand.rayleigh_stiffness = beta;
  sc.strand = addDeformableBody(sc.sys, strand, {{0, 1}, {3, -1}}, opt);
  return sc;
}

State randomState(const Scene& sc, std::uint32_t seed, double speed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  State s = sc.sys.defaultState();
  sc.fem->setRestState(s);
  sc.strand->setRestState(s);
  const int nr = sc.sys.model().nr();
  for (int i = 0; i < s.q.size(); ++i) {
    s.q[i] += i < nr ? 0.8 * u(rng) : 0.03 * u(rng);
    s.qdot[i] = speed * u(rng);
  }
  return s;
}

VecX termForce(const System& sys, const ForceTerm& term, const State& s) {
  SkeletonWorkspace sk(sys.model());
  calcKinematics(sys.model(), s, sk);
  VecX f = VecX::Zero(sys.ndof());
  term.addForce(sys.model(), s, TermContext(sk), f);
  return f;
}

void termKD(const System& sys, const ForceTerm& term, const State& s, MatX& K, MatX& D) {
  SkeletonWorkspace sk(sys.model());
  calcKinematics(sys.model(), s, sk);
  K.setZero(sys.ndof(), sys.ndof());
  D.setZero(sys.ndof(), sys.ndof());
  term.addStiffnessDamping(sys.model(), s, TermContext(sk), K, D);
}

// -df/dq and -df/dqdot by central differences (f is at most quadratic in qdot, where a central
// difference is exact: a larger step there keeps round-off of the large elastic forces out)
void differenceKD(const System& sys, const ForceTerm& term, const State& s, MatX& K, MatX& D) {
  const int n = sys.ndof();
  const double h = 1e-6, hv = 1e-3;
  K.resize(n, n);
  D.resize(n, n);
  for (int j = 0; j < n; ++j) {
    State p = s, m = s;
    p.q[j] += h;
    m.q[j] -= h;
    K.col(j) = -(termForce(sys, term, p) - termForce(sys, term, m)) / (2 * h);
    p = s;
    m = s;
    p.qdot[j] += hv;
    m.qdot[j] -= hv;
    D.col(j) = -(termForce(sys, term, p) - termForce(sys, term, m)) / (2 * hv);
  }
}

double relErr(const MatX& A, const MatX& B) { return (A - B).norm() / (1 + B.norm()); }

// K and D of a term at s against differences: relative errors, and K itself
struct KDCheck {
  double K_err, D_err;
  MatX K;
};
KDCheck checkKD(const Scene& sc, const ForceTerm& term, const State& s) {
  MatX K, D, Kfd, Dfd;
  termKD(sc.sys, term, s, K, D);
  differenceKD(sc.sys, term, s, Kfd, Dfd);
  return {relErr(K, Kfd), relErr(D, Dfd), K};
}

TEST(DeformableTerm, ForcesAreMinusTheEnergyGradientAtRest) {
  Scene sc = makeScene(0.0, 0.0, true);
  State s = randomState(sc, 1, 0.0);
  for (const auto& term : {sc.fem, sc.strand}) {
    const VecX f = termForce(sc.sys, *term, s);
    VecX g(sc.sys.ndof());
    for (int j = 0; j < g.size(); ++j) {
      State p = s, m = s;
      p.q[j] += 1e-6;
      m.q[j] -= 1e-6;
      SkeletonWorkspace sk(sc.sys.model());
      calcKinematics(sc.sys.model(), p, sk);
      const double Vp = term->potentialEnergy(sc.sys.model(), p, TermContext(sk));
      calcKinematics(sc.sys.model(), m, sk);
      const double Vm = term->potentialEnergy(sc.sys.model(), m, TermContext(sk));
      g[j] = -(Vp - Vm) / 2e-6;
    }
    EXPECT_LE((f - g).norm() / (1 + g.norm()), 1e-8) << term->name();
    EXPECT_GT(f.head(3).norm(), 1e-3);  // the skeleton feels the body
  }
}

TEST(DeformableTerm, StiffnessAndDampingMatchDifferencesAtZeroVelocity) {
  // everything on (gravity, Rayleigh alpha and beta, quadratic velocity terms): at qdot = 0 K and D are exact
  Scene sc = makeScene(0.7, 0.02, true);
  int compared = 0;
  for (std::uint32_t seed : {2u, 3u, 4u}) {
    const State s = randomState(sc, seed, 0.0);
    for (const auto& term : {sc.fem, sc.strand}) {
      const KDCheck c = checkKD(sc, *term, s);
      EXPECT_LE(c.K_err, 2e-8) << term->name() << " seed " << seed;
      EXPECT_LE(c.D_err, 2e-8) << term->name() << " seed " << seed;
      // the cross blocks between attached and free nodes are really there
      EXPECT_GT(c.K.topRightCorner(3, c.K.cols() - 3).norm(), 1e-2 * c.K.norm());
      ++compared;
    }
  }
  EXPECT_EQ(compared, 6);
}

TEST(DeformableTerm, StiffnessAndDampingMatchDifferencesAtSpeedWithMassDamping) {
  // qdot != 0: the geometric terms and the velocities' dependence on q; beta = 0, and the
  // quadratic velocity terms (explicit by the integrators' convention) off
  Scene sc = makeScene(0.7, 0.0, false);
  for (std::uint32_t seed : {5u, 6u}) {
    const State s = randomState(sc, seed, 1.5);
    for (const auto& term : {sc.fem, sc.strand}) {
      const KDCheck c = checkKD(sc, *term, s);
      EXPECT_LE(c.K_err, 2e-8) << term->name() << " seed " << seed;
      EXPECT_LE(c.D_err, 2e-8) << term->name() << " seed " << seed;
    }
  }
}

TEST(DeformableTerm, DampingIsExactWithStiffnessDampingAtSpeed) {
  Scene sc = makeScene(0.7, 0.02, false);
  const State s = randomState(sc, 7, 1.5);
  for (const auto& term : {sc.fem, sc.strand}) EXPECT_LE(checkKD(sc, *term, s).D_err, 2e-8) << term->name();
}

TEST(DeformableTerm, OmittedRayleighPositionDerivativeScalesWithVelocity) {
  // beta K_x(x) xdot's dependence on x is left out of K (docs/deformable.md §2): the mismatch
  // is linear in the velocity, so doubling qdot doubles it
  Scene sc = makeScene(0.0, 0.02, false);
  const State s1 = randomState(sc, 8, 0.5);
  State s2 = s1;
  s2.qdot *= 2.0;
  for (const auto& term : {sc.fem, sc.strand}) {
    MatX K1, D1, K1fd, D1fd, K2, D2, K2fd, D2fd;
    termKD(sc.sys, *term, s1, K1, D1);
    differenceKD(sc.sys, *term, s1, K1fd, D1fd);
    termKD(sc.sys, *term, s2, K2, D2);
    differenceKD(sc.sys, *term, s2, K2fd, D2fd);
    const double e1 = (K1 - K1fd).norm(), e2 = (K2 - K2fd).norm();
    std::printf("[ measured ] %s: omitted d(beta K v)/dq at |qdot| = %.3g: %.3g of |K| = %.3g\n", term->name().c_str(),
                s1.qdot.norm(), e1, K1fd.norm());
    EXPECT_GT(e1, 1e-6 * K1fd.norm());
    EXPECT_NEAR(e2 / e1, 2.0, 0.02);
  }
}

TEST(DeformableTerm, MassMatrixGivesTheKineticEnergyAndItsRate) {
  Scene sc = makeScene(0.0, 0.0, true);
  const State s = randomState(sc, 9, 1.0);
  for (const auto& term : {sc.fem, sc.strand}) {
    SkeletonWorkspace sk(sc.sys.model());
    calcKinematics(sc.sys.model(), s, sk);
    MatX M = MatX::Zero(sc.sys.ndof(), sc.sys.ndof());
    term->addMass(sc.sys.model(), s, TermContext(sk), M);
    EXPECT_NEAR(0.5 * s.qdot.dot(M * s.qdot), term->kineticEnergy(sc.sys.model(), s, TermContext(sk)), 1e-12);
    // analytic Mdot qdot against the base class's central difference along qdot
    VecX a = VecX::Zero(sc.sys.ndof()), b = VecX::Zero(sc.sys.ndof());
    term->addMassDotTimesVelocity(sc.sys.model(), s, TermContext(sk), a);
    term->ForceTerm::addMassDotTimesVelocity(sc.sys.model(), s, TermContext(sk), b);
    EXPECT_LE((a - b).norm(), 1e-8 * (1 + b.norm())) << term->name();
    EXPECT_GT(b.norm(), 1e-6) << term->name();
  }
}

TEST(DeformableTerm, ConsistentMassCouplesTheNodesAndKeepsKDExact) {
  // consistent mass: the block's M_x couples the nodes of each tet (free with attached ones too);
  // the kinetic energy, the analytic Mdot qdot, and K, D with Rayleigh alpha (alpha M_x v) hold as
  // for lumped mass, and M differs from the lumped one while its total (rigid translation) does not
  Scene sc = makeScene(0.7, 0.0, false, MassModel::Consistent), lumped = makeScene(0.7, 0.0, false);
  for (std::uint32_t seed : {5u, 6u}) {
    const State s = randomState(sc, seed, 1.5);
    const KDCheck c = checkKD(sc, *sc.fem, s);
    EXPECT_LE(c.K_err, 2e-8) << "seed " << seed;
    EXPECT_LE(c.D_err, 2e-8) << "seed " << seed;
  }
  Scene qv = makeScene(0.0, 0.0, true, MassModel::Consistent);
  const State s = randomState(qv, 9, 1.0);
  SkeletonWorkspace sk(qv.sys.model());
  calcKinematics(qv.sys.model(), s, sk);
  MatX M = MatX::Zero(qv.sys.ndof(), qv.sys.ndof()), Ml = M;
  qv.fem->addMass(qv.sys.model(), s, TermContext(sk), M);
  lumped.fem->addMass(lumped.sys.model(), s, TermContext(sk), Ml);
  EXPECT_NEAR(0.5 * s.qdot.dot(M * s.qdot), qv.fem->kineticEnergy(qv.sys.model(), s, TermContext(sk)), 1e-12);
  VecX a = VecX::Zero(qv.sys.ndof()), b = VecX::Zero(qv.sys.ndof());
  qv.fem->addMassDotTimesVelocity(qv.sys.model(), s, TermContext(sk), a);
  qv.fem->ForceTerm::addMassDotTimesVelocity(qv.sys.model(), s, TermContext(sk), b);
  EXPECT_LE((a - b).norm(), 1e-8 * (1 + b.norm()));
  EXPECT_GT(b.norm(), 1e-6);
  EXPECT_GT((M - Ml).norm(), 1e-3 * Ml.norm());
  // node space: a rigid translation has the same kinetic energy in both models (each row of the
  // consistent M_x sums to the node's lumped mass, so gravity loads agree too)
  const SparseMat Mc = nodeMassMatrix(qv.fem->body()), Mlx = nodeMassMatrix(lumped.fem->body());
  const VecX ones = VecX::Ones(Mc.rows());
  EXPECT_LE((Mc * ones - Mlx * ones).cwiseAbs().maxCoeff(), 1e-15 * (Mlx * ones).maxCoeff());
  EXPECT_GT(Mc.nonZeros(), 3 * Mlx.nonZeros());
}

TEST(DeformableTerm, ConsistentMassConservesEnergyWithQuadraticVelocityTerms) {
  // no damping: the chain swinging the consistent-mass block (and the strand) under gravity keeps
  // its energy to the rk45 error; without the quadratic velocity terms it would not
  for (const bool qvv : {true, false}) {
    Scene sc = makeScene(0.0, 0.0, qvv, MassModel::Consistent);
    State s = randomState(sc, 11, 0.0);
    sc.fem->setRestState(sc.sys.model(), s, 2);
    sc.strand->setRestState(s);
    s.qdot.head(sc.sys.model().nr()).setConstant(1.0);
    DynamicsWorkspace ws(sc.sys);
    const double E0 = sc.sys.kineticEnergy(s, ws) + sc.sys.potentialEnergy(s, ws);
    IntegratorOptions io;
    io.rtol = io.atol = 1e-10;
    auto integ = makeIntegrator("rk45", io);
    double worst = 0.0;
    for (int k = 1; k <= 20; ++k) {
      integ->advance(sc.sys, s, 0.01 * k);
      worst = std::max(worst, std::abs(sc.sys.kineticEnergy(s, ws) + sc.sys.potentialEnergy(s, ws) - E0));
    }
    std::printf("[ measured ] consistent-mass block, rk45 1e-10, 0.2 s, %s: max |E - E0| %.3e J of %.3e J\n",
                qvv ? "with QVV" : "without QVV", worst, std::abs(E0));
    if (qvv) EXPECT_LT(worst, 1e-6 * std::abs(E0));
    else EXPECT_GT(worst, 1e-4 * std::abs(E0));
  }
}

TEST(DeformableTerm, SystemScratchGivesTheSameAsDirectCalls) {
  Scene sc = makeScene(0.7, 0.02, true);
  const State s = randomState(sc, 10, 1.0);
  DynamicsWorkspace ws(sc.sys);
  sc.sys.calcMassAndForce(s, ws);
  sc.sys.calcStiffnessDamping(s, ws);
  const VecX f0 = ws.f;
  const MatX K0 = ws.K;
  // direct, scratch-free evaluation of everything
  SkeletonWorkspace sk(sc.sys.model());
  calcKinematics(sc.sys.model(), s, sk);
  VecX f_r;
  calcSkeletonForce(sc.sys.model(), s, sk, f_r);
  VecX f = VecX::Zero(sc.sys.ndof());
  f.head(f_r.size()) = f_r;
  MatX K = MatX::Zero(sc.sys.ndof(), sc.sys.ndof()), D = K;
  for (const auto& term : sc.sys.terms()) {
    term->addForce(sc.sys.model(), s, TermContext(sk), f);
    term->addStiffnessDamping(sc.sys.model(), s, TermContext(sk), K, D);
  }
  EXPECT_LE((f - f0).norm(), 1e-12 * (1 + f0.norm()));
  EXPECT_LE((K - K0).norm(), 1e-12 * (1 + K0.norm()));
}

TEST(DeformableTerm, RejectsBadBindings) {
  const Model model = scenes::revoluteChain(2);
  DeformableBody strand = makeStrand({Vec3(0, 0, 0), Vec3(1, 0, 0)}, 1.0, 1.0);
  EXPECT_THROW(DeformableTerm(model, strand, {NodeBinding{}}), ModelError);
  NodeBinding bad_body{NodeBinding::Kind::Body, 7, Vec3::Zero()};
  NodeBinding free_in_skeleton{NodeBinding::Kind::Free, 0, Vec3::Zero()};
  NodeBinding ok{NodeBinding::Kind::Free, 2, Vec3::Zero()};
  EXPECT_THROW(DeformableTerm(model, strand, {bad_body, ok}), ModelError);
  EXPECT_THROW(DeformableTerm(model, strand, {free_in_skeleton, ok}), ModelError);
  System sys(model);
  EXPECT_THROW(addDeformableBody(sys, strand, {{5, -1}}), ModelError);
  EXPECT_THROW(addDeformableBody(sys, strand, {{0, 4}}), ModelError);
}

}  // namespace
}  // namespace redmax
