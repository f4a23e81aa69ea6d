// The node-space stepper of the speed study against the System path: one linearly implicit step
// of a deformable body alone (DeformableTerm in a System without bodies, integrator bdf1) and
// stepNodeSpace with dense and with sparse solves give the same state.
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "core/deformable/deformable_term.hpp"
#include "core/deformable/node_solver.hpp"
#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"

namespace redmax {
namespace {

TEST(NodeSpaceStepper, MatchesTheSystemsLinearlyImplicitStep) {
  const TetMesh mesh = makeBoxTetMesh(Vec3(0.4, 0.1, 0.1), 4, 1, 1);
  DeformableBody body = makeFemBody(mesh, 1e5, 0.3, 1000);
  body.rayleigh_mass = 0.5;
  body.rayleigh_stiffness = 0.01;
  NodeSpaceProblem p;
  p.body = &body;
  p.gravity = Vec3(0, -9.81, 0);
  p.fixed.assign(mesh.numNodes(), 0);
  std::vector<NodeAttachment> att;
  for (int n = 0; n < mesh.numNodes(); ++n)
    if (mesh.nodes[n].x() < 1e-12) {
      p.fixed[n] = 1;
      att.push_back({n, -1});
    }
  // a deformed, moving start
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  VecX x = restPositions(body), v = VecX::Zero(x.size());
  for (int n = 0; n < mesh.numNodes(); ++n)
    if (!p.fixed[n])
      for (int c = 0; c < 3; ++c) x[3 * n + c] += 0.01 * u(rng), v[3 * n + c] = 0.3 * u(rng);

  ModelBuilder mb("none");
  mb.setGravity(p.gravity);
  System sys(mb.finalize());
  auto term = addDeformableBody(sys, body, att);
  State s = sys.defaultState();
  int k = 0;
  for (int n = 0; n < mesh.numNodes(); ++n)
    if (!p.fixed[n]) {
      s.q.segment<3>(3 * k) = x.segment<3>(3 * n);
      s.qdot.segment<3>(3 * k) = v.segment<3>(3 * n);
      ++k;
    }
  ASSERT_EQ(3 * k, sys.ndof());
  const double h = 2e-3;
  IntegratorOptions io;
  io.dt = h;
  makeIntegrator("bdf1", io)->advance(sys, s, h);

  for (LinearSolve solve : {LinearSolve::Dense, LinearSolve::Sparse}) {
    VecX xs = x, vs = v;
    stepNodeSpace(p, xs, vs, h, solve);
    const std::vector<int> dofs = p.freeDofs();
    double dx = 0, dv = 0;
    for (size_t i = 0; i < dofs.size(); ++i) {
      dx = std::max(dx, std::abs(xs[dofs[i]] - s.q[i]));
      dv = std::max(dv, std::abs(vs[dofs[i]] - s.qdot[i]));
    }
    EXPECT_LE(dx, 1e-13);
    EXPECT_LE(dv, 1e-10 * (1 + s.qdot.lpNorm<Eigen::Infinity>()));
    EXPECT_GT((xs - x).norm(), 1e-4);  // it moved
  }
}

}  // namespace
}  // namespace redmax
