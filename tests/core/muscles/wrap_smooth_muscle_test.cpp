// Type III muscles over ellipsoids, tori and quadrant spheres with the smooth model: accepted by the supported-shape
// check (wrapMassPointsUnsupportedReason goes through smoothWrapUnsupportedReason), and their
// J_ar, Jdot_ar through a surface on a moving body against central differences.
#include <gtest/gtest.h>

#include <random>

#include "core/muscles/wrap_muscle.hpp"
#include "core/spatial/se3.hpp"
#include "tests/core/dynamics/random_muscle.hpp"
#include "tests/core/muscles/muscle_test_util.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

bool nearRel(const MatX& A, const MatX& B, double tol) { return (A - B).norm() <= tol * (1.0 + B.norm()); }

// J_ar against central differences of x_a in q, and Jdot_ar against central differences of J_ar
// along qdot; false (not a test) when the differences at h and 2h disagree by more than the
// tolerance (a stencil across one of the library's own kinks, e.g. the hybrid ellipsoid method's
// linear blends, or a mass point crossing a tangent point)
bool checkAgainstFd(const Model& m, const Muscle& mu, const State& s, const char* what) {
  const double h = 1e-6;
  const MatX J1 = test::calcJarFd(m, mu, s, h), J2 = test::calcJarFd(m, mu, s, 2 * h);
  const MatX D1 = test::calcJdotArFd(m, mu, s, h), D2 = test::calcJdotArFd(m, mu, s, 2 * h);
  if (!nearRel(J2, J1, 3e-7) || !nearRel(D2, D1, 3e-7)) return false;
  const MuscleKinematics mk = test::evalMuscle(m, mu, s);
  EXPECT_TRUE(nearRel(mk.J_ar, J1, 1e-6)) << what << ": |J_ar - FD| " << (mk.J_ar - J1).norm() << " |J| " << J1.norm();
  EXPECT_TRUE(nearRel(mk.Jdot_ar, D1, 1e-6)) << what << ": |Jdot_ar - FD| " << (mk.Jdot_ar - D1).norm() << " |Jdot| "
                                            << D1.norm();
  return true;
}

TEST(WrapSmoothMuscle, EllipsoidTorusAndQuadrantSphereOnAMovingBody) {
  const Model m = scenes::revoluteChain(3);
  std::mt19937 rng(19);
  const WrapSurface surfaces[] = {WrapSurface::makeEllipsoid(Vec3(0.14, 0.1, 0.12)), WrapSurface::makeTorus(0.05, 0.15),
                                  WrapSurface::makeEllipsoid(Vec3(0.14, 0.1, 0.12), 0, 1),
                                  WrapSurface::makeSphere(0.1, 0, 1)};
  for (const WrapSurface& surface : surfaces) {
    const Muscle mu = test::chainWrapMuscle(surface, WrapModel::Smooth);
    EXPECT_EQ(wrapMassPointsUnsupportedReason(mu), "");
    validateMuscle(m, mu);
    const char* what = surface.type == WrapType::Torus    ? "chain torus"
                       : surface.type == WrapType::Sphere ? "chain quadrant sphere"
                       : surface.quadrant_sign != 0       ? "chain quadrant ellipsoid"
                                                          : "chain ellipsoid";
    int n_wrapped = 0, n_straight = 0, tested = 0;
    for (int trial = 0; trial < 300 && tested < 10; ++trial) {
      const State s = test::randomState(m.nr(), rng, 1.2, 2.0);
      MuscleKinematics mk;
      try {
        mk = test::evalMuscle(m, mu, s);  // end points inside the surface throw
      } catch (const MuscleError&) {
        continue;
      }
      // wrapped: some mass point off the straight origin-insertion line
      const bool wraps = test::offStraightLine(mk) > 1e-9;
      if ((wraps && n_wrapped >= 6) || (!wraps && n_straight >= 4)) continue;
      if (!checkAgainstFd(m, mu, s, what)) continue;
      ++tested;
      (wraps ? n_wrapped : n_straight)++;
    }
    EXPECT_GE(n_wrapped, 4) << what;
    EXPECT_GE(tested, 6) << what;
  }
}

}  // namespace
}  // namespace redmax
