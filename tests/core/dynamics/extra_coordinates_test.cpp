// Extra maximal coordinates [D Sec. 4.6.3]: a free point mass that the skeleton does not own,
// tied to a pendulum tip by a spring, added through System::addExtraCoordinates and a ForceTerm.
#include <gtest/gtest.h>

#include <memory>

#include "core/dynamics/system.hpp"
#include "core/integrators/integrator.hpp"
#include "core/skeleton/kinematics.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

// a point of mass m at x = q.segment<3>(first), spring k to the tip of body `body` at x_tip
class SpringParticle final : public ForceTerm {
 public:
  SpringParticle(int first, int body, Vec3 x_tip, double m, double k, Vec3 g)
      : first_(first), body_(body), x_tip_(x_tip), m_(m), k_(k), g_(g) {}
  std::string name() const override { return "spring_particle"; }
  void addMass(const Model&, const State&, const TermContext&, MatX& M) const override {
    M.block<3, 3>(first_, first_) += m_ * Mat3::Identity();
  }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override {
    const SkeletonWorkspace& ws = ctx.sk;
    const Vec3 x = s.q.segment<3>(first_);
    const Vec3 tip = transformPoint(ws.E_wi[body_], x_tip_);
    const Vec3 F = k_ * (tip - x);  // pulls the particle towards the tip
    f.segment<3>(first_) += F + m_ * g_;
    MatX J(3, model.nr());
    pointJacobian(model, ws, body_, x_tip_, J);
    f.head(model.nr()) -= J.transpose() * F;
  }
  double kineticEnergy(const Model&, const State& s, const TermContext&) const override {
    return 0.5 * m_ * s.qdot.segment<3>(first_).squaredNorm();
  }
  double potentialEnergy(const Model&, const State& s, const TermContext& ctx) const override {
    const SkeletonWorkspace& ws = ctx.sk;
    const Vec3 x = s.q.segment<3>(first_);
    const Vec3 tip = transformPoint(ws.E_wi[body_], x_tip_);
    return 0.5 * k_ * (tip - x).squaredNorm() - m_ * g_.dot(x);
  }

 private:
  int first_, body_;
  Vec3 x_tip_;
  double m_, k_;
  Vec3 g_;
};

System makeScene() {
  System sys(scenes::doublePendulum());
  const int first = sys.addExtraCoordinates(3);
  EXPECT_EQ(first, 2);
  sys.addTerm(std::make_shared<SpringParticle>(first, 1, Vec3(0, -1, 0), 0.3, 200.0, sys.model().gravity));
  return sys;
}

TEST(ExtraCoordinates, SizesAndZeroSkeletonBlocks) {
  System sys = makeScene();
  EXPECT_EQ(sys.ndof(), 5);
  EXPECT_EQ(sys.numExtraCoordinates(), 3);
  State s = sys.defaultState();
  ASSERT_EQ(s.q.size(), 5);
  s.q << 0.4, -0.3, 0.5, -1.8, 0.1;
  s.qdot << 0.2, 0.7, -0.1, 0.3, 0.05;
  DynamicsWorkspace ws(sys.model());
  sys.calcMassAndForce(s, ws);
  ASSERT_EQ(ws.M.rows(), 5);
  // the particle couples to the skeleton only through forces, never through mass
  EXPECT_EQ(ws.M.block(0, 2, 2, 3).norm(), 0.0);
  EXPECT_TRUE(nearRel(MatX(ws.M.block(2, 2, 3, 3)), MatX(0.3 * Mat3::Identity()), 1e-15));
  // forward then inverse dynamics over all five coordinates
  const VecX qddot = sys.forwardDynamics(s, ws);
  EXPECT_LE(sys.inverseDynamics(s, qddot, ws).norm(), 1e-10 * (1 + ws.f.norm()));
}

TEST(ExtraCoordinates, EnergyIsConservedWithRk45) {
  System sys = makeScene();
  State s = sys.defaultState();
  s.q << 0.8, 0.3, 0.6, -1.5, 0.05;  // spring stretched, particle off the plane
  s.qdot.setZero();
  DynamicsWorkspace ws(sys.model());
  const double E0 = sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
  IntegratorOptions opt;
  opt.rtol = 1e-11;
  opt.atol = 1e-12;
  auto integ = makeIntegrator("rk45", opt);
  integ->advance(sys, s, 2.0);
  const double E1 = sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
  EXPECT_LE(std::abs(E1 - E0), 1e-7 * (1 + std::abs(E0)));
  // the particle moved in 3D: it really is a degree of freedom of the system
  EXPECT_GT(std::abs(s.q[4] - 0.05), 1e-3);
}

TEST(ExtraCoordinates, RejectedWithACoordinateMap) {
  System sys(scenes::doublePendulum());
  sys.addExtraCoordinates(2);
  EXPECT_THROW(sys.setCoordinateMap(std::make_shared<CoordinateMap>(sys.model())), ModelError);
}

}  // namespace
}  // namespace redmax
