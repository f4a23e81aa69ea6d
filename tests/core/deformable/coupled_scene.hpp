#pragma once
// A small coupled scene for the deformable tests: the 3-link chain of the NodeConstraint tests
// (axes z, x, y; links 0.5 m along -y) holding a consistent-mass FEM block (0.2 x 0.1 x 0.1 m) by
// its x = 0 face, and a muscle with mass points (and optionally a toy Hill model) from link 0,
// over a via point on link 1, onto a node of the block or a bone point.
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "core/deformable/deformable_term.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/spatial/se3.hpp"
#include "tests/core/dynamics/toy_muscle_model.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax::test::coupled {

// the block of the NodeConstraint tests: 0.2 x 0.1 x 0.1 m, its x = 0 face held by link 2 of a
// 3-link chain (axes z, x, y; links 0.5 m along -y)
inline TetMesh blockMesh() { return makeBoxTetMesh(Vec3(0.2, 0.1, 0.1), 2, 1, 1, Vec3(0.0, -1.25, -0.05)); }

inline int nodeAt(const TetMesh& mesh, const Vec3& x) {
  for (int n = 0; n < mesh.numNodes(); ++n)
    if ((mesh.nodes[n] - x).norm() < 1e-12) return n;
  ADD_FAILURE() << "no node at " << x.transpose();
  return 0;
}

inline const Vec3 kFarNode(0.2, -1.25, -0.05);  // free in both attachments
inline const Vec3 kFaceNode(0.0, -1.15, 0.05);  // on the held face

struct Scene {
  System sys;
  std::shared_ptr<const DeformableTerm> term;
  Muscle muscle;
};

// a muscle from link 0 over a via point on link 1 (or straight) to `insertion`, with 5 mass points
// of 0.06 kg
inline Muscle makeMuscle(PathPoint insertion, bool via = true) {
  Muscle mu;
  mu.name = "soft_insertion";
  mu.path.points = {makeFixedPoint(0, Vec3(0.05, -0.2, 0.02), "origin")};
  if (via) mu.path.points.push_back(makeFixedPoint(1, Vec3(0.08, -0.25, 0.0), "via"));
  mu.path.points.push_back(std::move(insertion));
  mu.mass_points = makeMassPoints({0.1, 0.3, 0.5, 0.7, 0.9}, {0.06, 0.06, 0.06, 0.06, 0.06});
  return mu;
}

// insertion: on the far (free) node, on the face node itself, or on the face node's body point
enum class Insertion { FarNode, FaceNode, FaceBodyPoint };

inline Scene makeScene(AttachBy by, Insertion ins, double rayleigh_mass, bool with_force,
                MuscleTermOptions mto = {}, bool with_muscle = true, bool via = true) {
  Scene sc{System(scenes::revoluteChain(3)), nullptr, {}};
  const TetMesh mesh = blockMesh();
  DeformableBody fem = makeFemBody(mesh, 2e4, 0.3, 1000.0, MassModel::Consistent);
  fem.rayleigh_mass = rayleigh_mass;
  std::vector<NodeAttachment> att;
  for (int n = 0; n < mesh.numNodes(); ++n)
    if (mesh.nodes[n].x() < 1e-12) att.push_back({n, 2});
  sc.term = addDeformableBody(sc.sys, fem, att, {}, by);
  const Model& model = sc.sys.model();
  PathPoint end;
  if (ins == Insertion::FarNode) end = musclePointAtNode(*sc.term, nodeAt(mesh, kFarNode), "insertion");
  if (ins == Insertion::FaceNode) end = musclePointAtNode(*sc.term, nodeAt(mesh, kFaceNode), "insertion");
  if (ins == Insertion::FaceBodyPoint) {
    // where the face node sits in link 2 at the default pose
    SkeletonWorkspace sk(model);
    const State s0 = sc.sys.defaultState();
    calcKinematics(model, s0, sk);
    const Mat4& E = sk.E_wi[2];
    end = makeFixedPoint(2, E.topLeftCorner<3, 3>().transpose() * (kFaceNode - E.topRightCorner<3, 1>()), "insertion");
  }
  sc.muscle = makeMuscle(end, via);
  if (!with_muscle) return sc;
  sc.sys.addTerm(std::make_shared<MuscleTerm>(model, std::vector<Muscle>{sc.muscle}, mto));
  if (with_force) {
    auto toy = std::make_shared<test::ToyMuscleModel>();
    toy->k = 500.0;
    toy->l_ts = 1.1;
    sc.sys.addTerm(std::make_shared<MuscleForceTerm>(model, std::vector<Muscle>{sc.muscle},
                                                     std::vector<std::shared_ptr<const hill::MuscleModel>>{toy}));
  }
  return sc;
}

// a deformed, moving state: links at random angles and speeds, free nodes off their rest positions
inline State randomState(const Scene& sc, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const int nr = sc.sys.model().nr();
  State s = sc.sys.defaultState();
  sc.term->setRestState(s);
  for (int i = 0; i < s.q.size(); ++i) {
    s.q[i] += i < nr ? 0.7 * u(rng) : 0.02 * u(rng);
    s.qdot[i] = u(rng);
  }
  return s;
}

}  // namespace redmax::test::coupled
