// Static optimization with OpenSim's residual actuators and passive forces
// (converter/analyze/analyze_tool.hpp): a planar "pelvis" held against gravity by residuals from
// force_set_files (PointActuators FX, FY; TorqueActuator MZ) and a reserve CoordinateActuator in
// the model, with a CoordinateLimitForce in the model bearing part of the tilt moment. The
// optimum has a closed form; the KKT conditions are checked on the tool's answer with a program
// built here, independently of the tool.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "converter/analyze/analyze_tool.hpp"
#include "converter/analyze/static_optimization.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

constexpr double kMass = 12.0, kG = 9.80665;
constexpr double kTiltDeg = 20.0;  // 10 deg beyond the limit's 10 deg, past its 5 deg transition
const Vec3 kCom(0.08, 0.1, 0.0), kPoint(0.05, -0.02, 0.0);

std::string pelvisModel(bool with_limit) {
  const std::string bodies = "<Body name=\"pelvis\"><mass>12</mass><mass_center>0.08 0.1 0</mass_center>"
                             "<inertia>0.1 0.1 0.1 0 0 0</inertia></Body>\n";
  const std::string joints =
      "<PlanarJoint name=\"ground_pelvis\"><socket_parent_frame>/ground</socket_parent_frame>"
      "<socket_child_frame>/bodyset/pelvis</socket_child_frame><coordinates>"
      "<Coordinate name=\"pelvis_tilt\"><range>-2 2</range></Coordinate>"
      "<Coordinate name=\"pelvis_tx\"><range>-5 5</range></Coordinate>"
      "<Coordinate name=\"pelvis_ty\"><range>-5 5</range></Coordinate>"
      "</coordinates></PlanarJoint>\n";
  std::string forces = "<CoordinateActuator name=\"tilt_reserve\"><coordinate>pelvis_tilt</coordinate>"
                       "<optimal_force>50</optimal_force></CoordinateActuator>\n";
  if (with_limit)
    forces += "<CoordinateLimitForce name=\"tilt_limit\"><coordinate>pelvis_tilt</coordinate>"
              "<upper_stiffness>2</upper_stiffness><upper_limit>10</upper_limit>"
              "<lower_stiffness>2</lower_stiffness><lower_limit>-30</lower_limit>"
              "<damping>0.1</damping><transition>5</transition></CoordinateLimitForce>\n";
  return test::modernOsim(bodies, joints, "<ForceSet><objects>" + forces + "</objects></ForceSet>\n");
}

const char* kResiduals =
    "<OpenSimDocument Version=\"40000\"><ForceSet name=\"residuals\"><objects>\n"
    "<PointActuator name=\"FX\"><body>pelvis</body><point>0.05 -0.02 0</point><point_is_global>false</point_is_global>"
    "<direction>1 0 0</direction><force_is_global>true</force_is_global><optimal_force>1000</optimal_force></PointActuator>\n"
    "<PointActuator name=\"FY\"><body>pelvis</body><point>0.05 -0.02 0</point><point_is_global>false</point_is_global>"
    "<direction>0 1 0</direction><force_is_global>true</force_is_global><optimal_force>1000</optimal_force></PointActuator>\n"
    "<TorqueActuator name=\"MZ\"><bodyA>pelvis</bodyA><bodyB>ground</bodyB><axis>0 0 1</axis>"
    "<torque_is_global>true</torque_is_global><optimal_force>100</optimal_force></TorqueActuator>\n"
    "</objects></ForceSet></OpenSimDocument>\n";

std::string motion() {
  std::ostringstream os;
  os << "Coordinates\nversion=1\nnRows=11\nnColumns=4\ninDegrees=yes\nendheader\ntime\tpelvis_tilt\tpelvis_tx\tpelvis_ty\n";
  for (int k = 0; k <= 10; ++k) os << 0.1 * k << "\t" << kTiltDeg << "\t0.3\t0.9\n";
  return os.str();
}

std::string setup() {
  return "<OpenSimDocument Version=\"40000\"><AnalyzeTool name=\"gait\"><model_file>m.osim</model_file>"
         "<force_set_files>residuals.xml</force_set_files><results_directory>out</results_directory>"
         "<initial_time>0.2</initial_time><final_time>0.6</final_time><coordinates_file>q.mot</coordinates_file>"
         "<AnalysisSet><objects><StaticOptimization name=\"StaticOptimization\"><on>true</on>"
         "</StaticOptimization></objects></AnalysisSet></AnalyzeTool></OpenSimDocument>\n";
}

// columns of A (generalized force per unit control) and b for the pose, by hand: rows tilt, tx, ty
StaticOptimizationProblem closedFormProblem(double limit_moment) {
  const double q = kTiltDeg * M_PI / 180.0, c = std::cos(q), s = std::sin(q);
  auto rx = [&](const Vec3& v) { return c * v.x() - s * v.y(); };  // world x of R(q) v
  auto ry = [&](const Vec3& v) { return s * v.x() + c * v.y(); };
  StaticOptimizationProblem pb;
  pb.A = MatX::Zero(3, 4);
  // FX at the point: torque about the origin -(R p)_y F; FY: (R p)_x F
  pb.A.col(0) << -ry(kPoint) * 1000, 1000, 0;
  pb.A.col(1) << rx(kPoint) * 1000, 0, 1000;
  pb.A.col(2) << 100, 0, 0;  // MZ
  pb.A.col(3) << 50, 0, 0;   // tilt_reserve
  // what the actuators supply: minus gravity's generalized force, minus the limit's moment
  pb.b.resize(3);
  pb.b << kMass * kG * rx(kCom) - limit_moment, 0, kMass * kG;
  pb.lower = VecX::Constant(4, -std::numeric_limits<double>::infinity());
  pb.upper = VecX::Constant(4, std::numeric_limits<double>::infinity());
  return pb;
}

TEST(AnalyzeResiduals, PointAndTorqueResidualsCarryThePelvisAtTheClosedForm) {
  for (bool with_limit : {false, true}) {
    test::TempDir dir;
    dir.write("m.osim", pelvisModel(with_limit));
    dir.write("residuals.xml", kResiduals);
    dir.write("q.mot", motion());
    AnalyzeToolSettings st;
    st.setup_file = dir.write("setup.xml", setup());
    const AnalyzeTool tool(st);
    const StaticOptimizationRun run = tool.runStaticOptimization();
    ASSERT_EQ(run.failed, 0);
    // the model's actuators first, then force_set_files' (OpenSim's append)
    ASSERT_EQ(run.actuators, (std::vector<std::string>{"tilt_reserve", "FX", "FY", "MZ"}));
    // the limit: 2 N m/deg over 10 deg beyond its limit (past the transition): -20 N m
    const double limit = with_limit ? -2.0 * (kTiltDeg - 10.0) : 0.0;
    StaticOptimizationProblem pb = closedFormProblem(limit);
    // closed form: FY = m g, FX = 0; the tilt moment tau left after FY's shared by MZ and the
    // reserve as tau c_i / sum c_j^2 (exponent 2)
    const double tau = pb.b[0] - pb.A(0, 1) * (kMass * kG / 1000.0);
    double worst_stationarity = 0.0, worst_equality = 0.0, worst_closed = 0.0;
    for (const auto& f : run.frames) {
      const VecX x = f.activation;
      // measured: every control within 3e-17 of its closed form
      EXPECT_NEAR(x[1], 0.0, 1e-14) << f.time;
      EXPECT_NEAR(x[2], kMass * kG / 1000.0, 1e-14) << f.time;
      EXPECT_NEAR(x[3], tau * 100 / (100 * 100 + 50 * 50), 1e-14) << f.time;
      EXPECT_NEAR(x[0], tau * 50 / (100 * 100 + 50 * 50), 1e-14) << f.time;
      EXPECT_NEAR(f.force[3], 100 * x[3], 1e-12);
      EXPECT_LT(f.constraint_violation, 1e-8);
      // KKT at the tool's optimum, on the program built here (controls reordered to its columns)
      VecX xr(4);
      xr << x[1], x[2], x[3], x[0];
      const OptimalityReport kkt = checkOptimality(pb, xr);
      worst_stationarity = std::max(worst_stationarity, kkt.stationarity);
      worst_equality = std::max(worst_equality, kkt.equality / pb.b.norm());
      worst_closed = std::max({worst_closed, std::abs(x[3] - tau * 100 / 12500), std::abs(x[0] - tau * 50 / 12500)});
    }
    std::printf("residuals%s: %zu frames, KKT stationarity %.2g, equality %.2g of |b|, closed form %.2g\n",
                with_limit ? " with the limit" : "", run.frames.size(), worst_stationarity, worst_equality, worst_closed);
    // measured: stationarity 0, equality 1.2e-16 of |b| (a square-plus-one program IPOPT solves exactly)
    EXPECT_LT(worst_stationarity, 1e-12);
    EXPECT_LT(worst_equality, 1e-14);
  }
}

TEST(AnalyzeResiduals, BadForceSetFilesAreErrorsAtTheirLine) {
  test::TempDir dir;
  dir.write("m.osim", pelvisModel(true));
  dir.write("q.mot", motion());
  AnalyzeToolSettings st;
  st.setup_file = dir.write("setup.xml", setup());
  auto message = [&](const std::string& residuals) {
    if (!residuals.empty()) dir.write("residuals.xml", residuals);
    try {
      AnalyzeTool t(st);
    } catch (const ConvertError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const std::string unknown = message(
      "<OpenSimDocument Version=\"40000\"><ForceSet><objects>\n<PointActuator name=\"FX\">\n<body>torso</body>"
      "</PointActuator>\n</objects></ForceSet></OpenSimDocument>\n");
  EXPECT_NE(unknown.find("residuals.xml:3: PointActuator 'FX': body 'torso'"), std::string::npos) << unknown;
  const std::string negative = message(
      "<OpenSimDocument Version=\"40000\"><ForceSet><objects>\n<CoordinateLimitForce name=\"l\">"
      "<coordinate>pelvis_tilt</coordinate>\n<lower_stiffness>-1</lower_stiffness></CoordinateLimitForce>\n"
      "</objects></ForceSet></OpenSimDocument>\n");
  EXPECT_NE(negative.find("residuals.xml:3: CoordinateLimitForce 'l': lower_stiffness"), std::string::npos) << negative;
  std::filesystem::remove(dir.file("residuals.xml"));
  const std::string missing = message("");
  EXPECT_NE(missing.find("residuals.xml"), std::string::npos) << missing;
}

}  // namespace
}  // namespace redmax::osim
