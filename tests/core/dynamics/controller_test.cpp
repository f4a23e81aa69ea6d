// Controllers (core/dynamics/controller.hpp): controls add up over controllers from zero at every
// evaluation; PrescribedControls evaluates its functions at s.t; ProportionalController is
// bias + kp (target - q) - kd qdot, clamped; a System without controllers keeps the caller's.
#include "core/dynamics/controller.hpp"

#include <gtest/gtest.h>

#include <memory>

#include "core/dynamics/coordinate_actuator_term.hpp"
#include "core/dynamics/system.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax {
namespace {

TEST(Controller, ControllersAddUpAndDriveCoordinateActuators) {
  const Model m = scenes::randomTree(3, 4, scenes::TreeJoints::SimbodyComparable);
  ASSERT_GE(m.nr(), 2);
  System sys(m);
  sys.addTerm(std::make_shared<CoordinateActuatorTerm>(
      m, std::vector<CoordinateActuatorTerm::Actuator>{{"a0", 0, 2.0}, {"a1", 1, 10.0}}));
  ASSERT_EQ(sys.numControls(), 2);
  ASSERT_EQ(sys.controlNames(), (std::vector<std::string>{"a0", "a1"}));
  State s = sys.defaultState();
  s.t = 0.5;
  s.q[1] = 0.2;
  s.qdot[1] = -1.0;
  System bare(m);
  DynamicsWorkspace wb(bare), ws(sys);
  bare.calcMassAndForce(s, wb);
  // no controllers: the caller's controls
  ws.controls = (VecX(2) << 0.5, -0.25).finished();
  sys.calcMassAndForce(s, ws);
  EXPECT_NEAR(ws.f[0] - wb.f[0], 1.0, 1e-12);
  EXPECT_NEAR(ws.f[1] - wb.f[1], -2.5, 1e-12);
  // u0 = 3 t (prescribed); u1 = prescribed 0.1 + PD clamp(0.05 + 2 (0.5 - 0.2) - 0.1 (-1)) = 0.1 + 0.75
  auto ramp = std::make_shared<LinearFunction>(std::vector<double>{3.0, 0.0});
  auto c01 = std::make_shared<ConstantFunction>(0.1, 1);
  sys.addController(std::make_shared<PrescribedControls>(
      "p", std::vector<PrescribedControls::Entry>{{0, ramp}, {1, c01}}));
  ProportionalController::Rule r;
  r.control = 1;
  r.coordinate = 1;
  r.target = 0.5;
  r.kp = 2.0;
  r.kd = 0.1;
  r.bias = 0.05;
  r.min = 0.0;
  r.max = 0.75;
  sys.addController(std::make_shared<ProportionalController>(std::vector<ProportionalController::Rule>{r}));
  DynamicsWorkspace ws2(sys);
  ws2.controls = VecX::Constant(2, 100.0);  // overwritten: controllers start from zero
  sys.calcMassAndForce(s, ws2);
  EXPECT_NEAR(ws2.controls[0], 1.5, 1e-12);
  EXPECT_NEAR(ws2.controls[1], 0.85, 1e-12);
  EXPECT_NEAR(ws2.f[0] - wb.f[0], 3.0, 1e-12);
  EXPECT_NEAR(ws2.f[1] - wb.f[1], 8.5, 1e-12);
  EXPECT_THROW(CoordinateActuatorTerm(m, {{"bad", m.nr(), 1.0}}), ModelError);
}

}  // namespace
}  // namespace redmax
