// Muscles attached to deformable nodes (PathPointKind::Node, core/muscles/path.hpp; issue 24): a
// path point on a free node is the node's three coordinates, so the muscle's mass points and its
// tension reach the node through the same chain J_ar = J_ax J_xr as on bones. Checked:
//   - J_ar, Jdot_ar and dl/dq of a muscle from a bone, over a via point, onto a free node of an
//     FEM block, against central differences over every coordinate (links and nodes);
//   - a muscle inserting on a node tied to its bone by NodeConstraint gives the same accelerations
//     as the same muscle inserting on the bone point (one physical system, two descriptions);
//   - energy: mass points on a muscle between a bone and a soft node keep the total energy of an
//     undamped swing (and lose it when their quadratic velocity forces are dropped);
//   - what the chain cannot take is refused with a message.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "core/integrators/integrator.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "core/muscles/path_kinematics.hpp"
#include "tests/core/deformable/coupled_scene.hpp"

namespace redmax {
namespace {

using namespace test::coupled;

// mass-point positions and path length at s (world)
void pointsAt(const Scene& sc, const State& s, VecX& x, double& length) {
  const Model& model = sc.sys.model();
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  MuscleKinematics mk;
  calcMuscleKinematics(model, s, sk, sc.muscle, mk, true);
  x.resize(3 * static_cast<int>(mk.x_a.size()));
  for (size_t a = 0; a < mk.x_a.size(); ++a) x.segment<3>(3 * static_cast<int>(a)) = mk.x_a[a];
  length = mk.length;
}

TEST(NodeMuscle, JacobiansAndLengthDerivativeMatchDifferences) {
  const Scene sc = makeScene(AttachBy::Jacobian, Insertion::FarNode, 0.0, true);
  const Model& model = sc.sys.model();
  const int nq = sc.sys.ndof();
  ASSERT_GT(nq, model.nr());
  ASSERT_EQ(sc.muscle.path.points.back().kind, PathPointKind::Node);
  for (std::uint32_t seed : {1u, 2u}) {
    const State s = randomState(sc, seed);
    SkeletonWorkspace sk(model);
    calcKinematics(model, s, sk);
    MuscleKinematics mk;
    calcMuscleKinematics(model, s, sk, sc.muscle, mk, true);
    // the pose-only length (reports, fibre placement) reads the node from q as the workspace does
    std::vector<Mat4> E;
    calcBodyPoses(model, s.q, E);
    EXPECT_NEAR(calcPathLength(model, sc.muscle.path, s.q, E), mk.length, 1e-15 * mk.length);
    const MatX J = expandColumns(mk.J_ar, mk, nq), Jdot = expandColumns(mk.Jdot_ar, mk, nq);
    ASSERT_EQ(J.cols(), nq);
    // the insertion's three node columns are in the Jacobian
    const int c = sc.muscle.path.points.back().coordinate;
    EXPECT_GT(J.middleCols(c, 3).norm(), 0.1);
    const double h = 1e-6;
    MatX J_fd(J.rows(), nq);
    VecX dl_fd(nq);
    for (int j = 0; j < nq; ++j) {
      State p = s, m = s;
      p.q[j] += h;
      m.q[j] -= h;
      VecX xp, xm;
      double lp, lm;
      pointsAt(sc, p, xp, lp);
      pointsAt(sc, m, xm, lm);
      J_fd.col(j) = (xp - xm) / (2 * h);
      dl_fd[j] = (lp - lm) / (2 * h);
    }
    const double eJ = (J - J_fd).cwiseAbs().maxCoeff() / J.cwiseAbs().maxCoeff();
    // Jdot along the motion: (J(q + h qdot) - J(q - h qdot)) / 2h
    State p = s, m = s;
    p.q += h * s.qdot;
    m.q -= h * s.qdot;
    MuscleKinematics mp, mm;
    SkeletonWorkspace skp(model), skm(model);
    calcKinematics(model, p, skp);
    calcKinematics(model, m, skm);
    calcMuscleKinematics(model, p, skp, sc.muscle, mp, true);
    calcMuscleKinematics(model, m, skm, sc.muscle, mm, true);
    const MatX Jdot_fd = (expandColumns(mp.J_ar, mp, nq) - expandColumns(mm.J_ar, mm, nq)) / (2 * h);
    const double eJd = (Jdot - Jdot_fd).cwiseAbs().maxCoeff() / Jdot.cwiseAbs().maxCoeff();
    // the Hill term's dl/dq (the tension's generalized force is -F_t dl/dq)
    const auto& force = dynamic_cast<const MuscleForceTerm&>(*sc.sys.terms().back());
    double len, speed;
    VecX dl;
    force.calcPath(model, s, sk, 0, len, speed, dl);
    ASSERT_EQ(dl.size(), nq);
    const double el = (dl - dl_fd).cwiseAbs().maxCoeff() / dl.cwiseAbs().maxCoeff();
    EXPECT_NEAR(speed, dl.dot(s.qdot), 1e-12 * std::abs(speed) + 1e-14);
    std::printf("[ measured ] seed %u: J_ar %.2e, Jdot_ar %.2e, dl/dq %.2e relative to central differences\n", seed,
                eJ, eJd, el);
    EXPECT_LE(eJ, 2e-9);   // measured 1.3e-10 .. 1.5e-10 (the differences' error at h = 1e-6)
    EXPECT_LE(eJd, 2e-9);  // measured 1.6e-10 .. 2.4e-10
    EXPECT_LE(el, 2e-9);   // measured 1.5e-10
  }
}

TEST(NodeMuscle, OnATiedNodeEqualsTheSameMuscleOnItsBodyPoint) {
  // nodes of the held face tied by NodeConstraint: the node moves exactly with its body point, so
  // a muscle inserting on the node (mass points and tension through the node's coordinates and
  // the constraint's multipliers) is the muscle inserting on the bone point
  const Scene on_node = makeScene(AttachBy::Constraint, Insertion::FaceNode, 0.5, true);
  const Scene on_bone = makeScene(AttachBy::Constraint, Insertion::FaceBodyPoint, 0.5, true);
  ASSERT_EQ(on_node.muscle.path.points.back().kind, PathPointKind::Node);
  ASSERT_EQ(on_bone.muscle.path.points.back().kind, PathPointKind::Fixed);
  const Scene none = makeScene(AttachBy::Constraint, Insertion::FaceNode, 0.5, false, {}, false);
  const Model& model = on_node.sys.model();
  const int nr = model.nr();
  for (std::uint32_t seed : {3u, 4u, 5u}) {
    // links at random, the tied nodes on their body points, the other nodes deformed
    State s = randomState(on_node, seed);
    DynamicsWorkspace w0(on_node.sys);
    on_node.sys.projectPositions(s, w0, 1e-14);
    on_node.sys.projectVelocities(s, w0);
    DynamicsWorkspace wn(on_node.sys), wb(on_bone.sys);
    wn.controls = wb.controls = VecX::Constant(1, 0.6);
    const VecX qn = on_node.sys.forwardDynamics(s, wn), qb = on_bone.sys.forwardDynamics(s, wb);
    ASSERT_LE(wn.pos_err.cwiseAbs().maxCoeff(), 1e-13);
    const double scale = qn.cwiseAbs().maxCoeff();
    const double links = (qn.head(nr) - qb.head(nr)).cwiseAbs().maxCoeff() / scale;
    const double nodes = (qn.tail(qn.size() - nr) - qb.tail(qb.size() - nr)).cwiseAbs().maxCoeff() / scale;
    // the muscle matters here: without it the links' accelerations differ by far more
    DynamicsWorkspace w_none(none.sys);
    State s_none = s;
    s_none.z.resize(0);
    const VecX q_none = none.sys.forwardDynamics(s_none, w_none);
    const double effect = (qn.head(nr) - q_none.head(nr)).cwiseAbs().maxCoeff() / scale;
    std::printf("[ measured ] seed %u: links %.2e, nodes %.2e relative to %.3g (the muscle's own effect %.2e)\n", seed,
                links, nodes, scale, effect);
    EXPECT_GT(effect, 1e-3);
    EXPECT_LE(links, 5e-11);  // measured 9e-13 .. 5.5e-12 (the KKT solve's round-off)
    EXPECT_LE(nodes, 1e-12);  // measured 1.9e-14 .. 7.7e-14
  }
}

// total energy (links, block, muscle mass points) over an undamped swing, rk45 at 1e-10
struct SwingEnergy {
  double drift = 0.0, range = 0.0;  // largest |E - E0|, and the kinetic energy's largest value
};

SwingEnergy swing(const Scene& sc, double duration) {
  const Model& model = sc.sys.model();
  State s = sc.sys.defaultState();
  s.qdot.head(model.nr()) = Vec3(2.0, -1.5, 1.0);
  sc.term->setRestState(model, s, 2);  // the block undeformed, carried by link 2
  IntegratorOptions io;
  io.rtol = io.atol = 1e-10;
  auto integ = makeIntegrator("rk45", io);
  DynamicsWorkspace ws(sc.sys);
  const double E0 = sc.sys.kineticEnergy(s, ws) + sc.sys.potentialEnergy(s, ws);
  SwingEnergy out;
  for (int k = 1; k <= 40; ++k) {
    integ->advance(sc.sys, s, duration * k / 40);
    const double T = sc.sys.kineticEnergy(s, ws);
    out.drift = std::max(out.drift, std::abs(T + sc.sys.potentialEnergy(s, ws) - E0));
    out.range = std::max(out.range, T);
  }
  return out;
}

TEST(NodeMuscle, MassPointsOnASoftInsertionKeepTheEnergyOfAnUndampedSwing) {
  // a straight muscle (link 0 to the block's far node): over a via point on a moving link the mass
  // points' kinetic energy jumps as they pass the corner (core/muscles/path.hpp), 7.1e-3 J here
  // (measured), so the energy check takes the straight path
  const Scene full = makeScene(AttachBy::Jacobian, Insertion::FarNode, 0.0, false, {}, true, false);
  MuscleTermOptions no_qvv;
  no_qvv.quadratic_velocity = false;
  const Scene dropped = makeScene(AttachBy::Jacobian, Insertion::FarNode, 0.0, false, no_qvv, true, false);
  const SwingEnergy a = swing(full, 0.4), b = swing(dropped, 0.4);
  std::printf("[ measured ] rk45 1e-10, 0.4 s, largest kinetic energy %.3f J: energy drift %.2e J with the mass "
              "points' quadratic velocity forces, %.2e J without them\n", a.range, a.drift, b.drift);
  EXPECT_GT(a.range, 1.0);
  EXPECT_LT(a.drift / a.range, 1e-11);  // measured 7.9e-12 J of 12.3 J (6.4e-13)
  EXPECT_GT(b.drift / b.range, 1e-4);   // measured 7.1e-3 J
}

TEST(NodeMuscle, WhatTheChainCannotTakeIsRefused) {
  const Scene sc = makeScene(AttachBy::Jacobian, Insertion::FarNode, 0.0, false);
  const Model& model = sc.sys.model();
  // a node point inside q_r
  Muscle bad = sc.muscle;
  bad.path.points.back().coordinate = 1;
  EXPECT_THROW(validatePath(model, bad.path, bad.name), ModelError);
  // a node point on a wrapping path
  bad = sc.muscle;
  PathWrap w;
  w.name = "cyl";
  w.surface.type = WrapType::Cylinder;
  w.surface.radius = 0.02;
  w.surface.length = 0.1;
  w.body = 1;
  bad.path.wraps.push_back(w);
  bad.path.num_wraps = 1;
  try {
    validatePath(model, bad.path, bad.name);
    ADD_FAILURE() << "accepted a node point on a wrapping path";
  } catch (const ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("wrap objects are not supported"), std::string::npos) << e.what();
  }
  // a state without the node's coordinates
  State s = sc.sys.defaultState();
  s.q.conservativeResize(model.nr());
  s.qdot.conservativeResize(model.nr());
  SkeletonWorkspace sk(model);
  calcKinematics(model, s, sk);
  MuscleKinematics mk;
  EXPECT_THROW(calcMuscleKinematics(model, s, sk, sc.muscle, mk, true), ModelError);
  // node bindings out of range
  EXPECT_THROW(musclePointAtNode(*sc.term, 99), ModelError);
  // attached and world nodes give body and world points
  EXPECT_EQ(musclePointAtNode(*sc.term, nodeAt(blockMesh(), kFaceNode)).kind, PathPointKind::Fixed);
  EXPECT_EQ(musclePointAtNode(*sc.term, nodeAt(blockMesh(), kFaceNode)).body, 2);
}

}  // namespace
}  // namespace redmax
