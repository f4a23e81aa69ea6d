#pragma once
// Shared by the unilateral tests: the ground plane, and the normal rows of a unilateral-constraint
// set against central differences of its gaps along the state's velocity (d gap / dt = J_n qdot,
// and the rows' recorded approach speeds).
#include <gtest/gtest.h>

#include <cmath>

#include "core/dynamics/system.hpp"
#include "core/dynamics/unilateral/unilateral.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::test {

/// the ground as a half-space with outward normal +y (OpenSim's ContactHalfSpace fills x > 0)
inline CollisionGeometry groundPlane() {
  CollisionGeometry g;
  g.name = "ground";
  g.shape = CollisionShape::HalfSpace;
  g.X_body = makeE(rotationAxisAngle(Vec3::UnitZ(), -M_PI / 2), Vec3::Zero());
  return g;
}

/// detect's rows at s (asserting `expected_rows` of them) checked against (gap(q + d qdot) -
/// gap(q - d qdot)) / 2d, d = 1e-6, to tol (1 + |rate|); returns the rows
inline UnilateralRows expectNormalRowsAreGapRates(const System& sys, const UnilateralConstraints& u, const State& s,
                                                  size_t expected_rows, double tol) {
  DynamicsWorkspace ws(sys);
  sys.calcMassAndForce(s, ws);
  UnilateralRows rows;
  u.detect(sys.model(), s, ws.sk, sys.ndof(), 1e-3, rows);
  EXPECT_EQ(rows.c.size(), expected_rows);
  auto gapsAt = [&](const VecX& q) {
    State t = s;
    t.q = q;
    DynamicsWorkspace w(sys);
    sys.kineticEnergy(t, w);
    return u.gaps(sys.model(), t, w.sk);
  };
  const double d = 1e-6;
  const auto gp = gapsAt(s.q + d * s.qdot), gm = gapsAt(s.q - d * s.qdot);
  for (size_t i = 0; i < rows.c.size() && i < gp.size(); ++i) {
    const double fd = (gp[i] - gm[i]) / (2 * d);
    EXPECT_NEAR(rows.Jn.row(static_cast<int>(i)).dot(s.qdot), fd, tol * (1 + std::abs(fd))) << "row " << i;
    EXPECT_NEAR(rows.c[i].approach, fd, tol * (1 + std::abs(fd))) << "row " << i;
  }
  return rows;
}

}  // namespace redmax::test
