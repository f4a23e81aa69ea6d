// The forward routes (core/dynamics/structured_forward.hpp) on a converted OpenSim model: gait2354
// (23 DoF, 54 muscles, CustomJoints with spline functions) from ../shared, skipped with a message
// when absent. The skeleton alone goes by ABA, the skeleton with 0.2 kg on every non-wrapping
// muscle (20 points each) by LTDL over the tree (every leg muscle stays on one root-to-foot
// path); both equal the dense route. Errors normalised as in
// tests/core/dynamics/structured_forward_test.cpp: |qddot - qddot_dense|_inf / (|qddot_dense|_inf
// eps cond(M)); measured 3e-4 (printed), bound 1. The model's own system (with its
// constraints or coordinate map, if any) plans the dense route.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <random>

#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_term.hpp"
#include "core/dynamics/system.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax {
namespace {

double normalisedError(const VecX& a, const VecX& b, const MatX& M) {
  Eigen::JacobiSVD<MatX> svd(M);
  const VecX& sv = svd.singularValues();
  const double cond = sv[0] / sv[sv.size() - 1];
  return (a - b).lpNorm<Eigen::Infinity>() /
         (b.lpNorm<Eigen::Infinity>() * std::numeric_limits<double>::epsilon() * cond);
}

TEST(StructuredForwardOsim, Gait2354RoutesEqualTheDenseRoute) {
  REDMAX_REQUIRE_SHARED();
  const std::string path = osim::test::sharedOpenSim("opensim-models/Models/Gait2354_Simbody/gait2354_simbody.osim");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "not found: " << path;
  const osim::BuildResult res = osim::buildCoreModel(osim::readOsimModel(path));
  const Model& m = res.model.skeleton();
  ASSERT_GE(m.nr(), kTreeSparseMinDof);
  std::vector<double> masses;
  for (const Muscle& mu : res.model.muscles()) masses.push_back(mu.path.num_wraps == 0 ? 0.2 : 0.0);
  const std::vector<Muscle> muscles = osim::addMusclePointMasses(res.model.muscles(), masses);

  System bare(m), massive(m);
  massive.addTerm(std::make_shared<MuscleTerm>(m, muscles));
  EXPECT_EQ(bare.plannedForwardRoute(), ForwardRoute::Articulated);
  EXPECT_EQ(massive.plannedForwardRoute(), ForwardRoute::TreeSparse);
  const System full = res.model.makeSystem(true);
  if (full.numConstraintRows() > 0 || full.coordinateMap()) EXPECT_EQ(full.plannedForwardRoute(), ForwardRoute::Dense);

  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  double worst = 0.0;
  for (int trial = 0; trial < 5; ++trial) {
    State s = bare.defaultState();
    for (int k = 0; k < m.nr(); ++k) s.q[k] += u(rng), s.qdot[k] = 5.0 * u(rng);
    for (System* sys : {&bare, &massive}) {
      DynamicsWorkspace wa(*sys), wd(*sys);
      sys->forward_route = ForwardRoute::Auto;
      const VecX qa = sys->forwardDynamics(s, wa);
      EXPECT_EQ(wa.last_route, sys == &bare ? ForwardRoute::Articulated : ForwardRoute::TreeSparse);
      sys->forward_route = ForwardRoute::Dense;
      const VecX qd = sys->forwardDynamics(s, wd);
      worst = std::max(worst, normalisedError(qa, qd, wd.M));
    }
  }
  std::printf("gait2354: routes vs dense, worst %.4f eps cond(M) of |qddot|\n", worst);
  EXPECT_LT(worst, 1.0);
}

}  // namespace
}  // namespace redmax
