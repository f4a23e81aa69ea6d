// `redmax gradient` end to end (docs/gradients.md §3): --check passes on the Type II double
// pendulum with muscle mass, a tolerance it cannot meet exits 1, bad SPECs exit 2 with the item
// named.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "tests/cli/cli_test_util.hpp"

namespace {

using namespace redmax::cli_test;
namespace fs = std::filesystem;

class GradientCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (redmaxExe().empty()) GTEST_SKIP() << "redmax executable not built next to cli_tests (build target redmax)";
    dir_ = fs::temp_directory_path() / ("redmax_gradient_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  CmdResult run(const std::string& args) const { return runRedmax(dir_, "gradient --model " + scene("double_pendulum_via.osim") + " " + args); }
  fs::path dir_;
};

const std::string kRun =
    "--duration 0.1 --dt 0.005 --muscle-mass-kg via_muscle=0.5 --mass-points 6 "
    "--params 'torques:q1@2=0.5,q2=-1;qdot0:q1=0.3;masses:via_muscle' "
    "--objective 'point:link2@0,-1,0=0.5,-1.5,0;0.1*speed;0.01*effort'";

TEST_F(GradientCli, CheckAgreesWithCentralDifferences) {
  for (const char* integrator : {"euler", "bdf1"}) {
    const CmdResult r = run(kRun + " --integrator " + integrator + " --check");
    EXPECT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("objective "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("torque q1 piece 2/2"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("mass via_muscle"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("-> ok"), std::string::npos) << r.out;
  }
}

TEST_F(GradientCli, SplineForcesAgreeWithCentralDifferences) {
  // q1 on a cubic B-spline of 5 control points, q2 piecewise linear on 3 nodes (docs/gradients.md §3)
  const CmdResult r = run(
      "--duration 0.1 --dt 0.005 --muscle-mass-kg via_muscle=0.5 --mass-points 6 "
      "--params 'torques:q1@5~cubic=0.5,q2@3~linear=-1' "
      "--objective 'point:link2@0,-1,0=0.5,-1.5,0;0.1*speed;0.01*effort' --check --check-tolerance 5e-9");
  EXPECT_EQ(r.code, 0) << r.out << r.err;  // measured worst relative error 6.8e-11 (6.2e-10 differenced)
  EXPECT_NE(r.out.find("torque q1 control point 5/5"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("torque q2 node 3/3"), std::string::npos) << r.out;
  const CmdResult bad = run("--duration 0.1 --params 'torques:q1@3~cubic' --objective speed");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("at least 4 control points"), std::string::npos) << bad.err;
}

TEST_F(GradientCli, WhatTheGradientDoesNotApplyIsNamed) {
  // reach_arm.osim: elbow_limit is applied (docs/gradients.md §2); its six Thelen muscles pull only
  // with excitation parameters, and say so
  const CmdResult r = runRedmax(dir_, "gradient --model " + scene("reach_arm.osim") +
                                          " --duration 0.02 --params 'torques:elbow_flexion' --objective speed");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: not applied: 6 path forces exert no force without excitation parameters"),
            std::string::npos) << r.err;
  EXPECT_NE(r.err.find("DELT1 (Thelen2003Muscle)"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("elbow_limit"), std::string::npos) << r.err;
}

// --step-jacobians (docs/gradients.md §2.1): the lumped pendulum takes the analytic route under
// auto and meets central differences of whole runs, and so does a Type II muscle's mass as a
// parameter; a wrapping muscle's mass points: auto falls back and says why, analytic is refused
TEST_F(GradientCli, StepJacobianRoutes) {
  const std::string lumped =
      "--duration 0.1 --dt 0.005 --params 'torques:q1@2=0.5,q2=-1;qdot0:q1=0.3' "
      "--objective 'point:link2@0,-1,0=0.5,-1.5,0;0.1*speed' --check --check-tolerance 1e-9";
  for (const char* integrator : {"euler", "bdf1", "sdirk2"}) {
    const CmdResult r = run(lumped + " --integrator " + integrator);
    EXPECT_EQ(r.code, 0) << r.out << r.err;  // measured worst relative errors 4.5e-11 (euler, bdf1), 3.9e-10 (sdirk2)
    EXPECT_NE(r.out.find("step Jacobians: analytic"), std::string::npos) << r.out;
  }
  const CmdResult d = run(lumped + " --step-jacobians differences");
  EXPECT_EQ(d.code, 0) << d.out << d.err;
  EXPECT_NE(d.out.find("step Jacobians: central differences of the step\n"), std::string::npos) << d.out;
  // a Type II muscle's mass as a parameter takes the analytic route too (dtau/ds, docs/gradients.md §2.1)
  const CmdResult massive = run(kRun + " --check --check-tolerance 1e-9");
  EXPECT_EQ(massive.code, 0) << massive.out << massive.err;
  EXPECT_NE(massive.out.find("step Jacobians: analytic"), std::string::npos) << massive.out;
  // sdirk2: the mass's force through each stage (measured 1.8e-9, the reference's: the differenced
  // route meets it to 1.9e-9)
  const CmdResult staged = run(kRun + " --integrator sdirk2 --check --check-tolerance 5e-9");
  EXPECT_EQ(staged.code, 0) << staged.out << staged.err;
  EXPECT_NE(staged.out.find("step Jacobians: analytic"), std::string::npos) << staged.out;
  // Type II mass points take the analytic route, a wrapping (Type III) muscle's too, its share by
  // muscle-local differences (said so); q2 starts at 0.8
  const CmdResult via = run("--duration 0.1 --dt 0.005 --muscle-mass-kg via_muscle=0.5 --params 'torques:q1' --objective speed "
                            "--step-jacobians analytic --check");
  EXPECT_EQ(via.code, 0) << via.out << via.err;
  const std::string wrap = "gradient --model " + scene("double_pendulum_wrap.osim") +
                           " --duration 0.1 --dt 0.005 --muscle-mass-kg wrap_muscle=0.5 --params 'torques:q1;q0:q2=0.8' "
                           "--objective 'point:link2@0,-1,0=0.5,-1.5,0;speed' ";
  const CmdResult wrapped = runRedmax(dir_, wrap + "--step-jacobians analytic --check --check-tolerance 1e-9");
  EXPECT_EQ(wrapped.code, 0) << wrapped.out << wrapped.err;  // measured 1.4e-12
  EXPECT_NE(wrapped.out.find("step Jacobians: analytic (derivatives of inverse dynamics, docs/gradients.md §2.1); the "
                             "mass points of 1 wrapping (Type III) muscle ('wrap_muscle') by muscle-local fourth-order "
                             "differences"),
            std::string::npos)
      << wrapped.out;
  // fibre-following mass points have no written derivatives: analytic exits 2 naming them, auto
  // differences the steps and says why
  const std::string fibre = "--duration 0.1 --dt 0.005 --muscle-mass-kg via_muscle=0.5 --mass-placement fibre "
                            "--params 'torques:q1' --objective speed ";
  const CmdResult refused = run(fibre + "--step-jacobians analytic");
  EXPECT_EQ(refused.code, 2) << refused.out << refused.err;
  EXPECT_NE(refused.err.find("analytic step Jacobians do not apply: the mass points of muscle 'via_muscle', which has "
                             "fibre-following mass points"),
            std::string::npos)
      << refused.err;
  const CmdResult fell_back = run(fibre);
  EXPECT_EQ(fell_back.code, 0) << fell_back.out << fell_back.err;
  EXPECT_NE(fell_back.out.find("step Jacobians: central differences of the step; not analytic: the mass points of "
                               "muscle 'via_muscle', which has fibre-following mass points"),
            std::string::npos)
      << fell_back.out;
  const CmdResult bad = run("--duration 0.1 --params 'torques:q1' --objective speed --step-jacobians exact");
  EXPECT_EQ(bad.code, 2) << bad.err;
}

TEST_F(GradientCli, CheckAboveTheToleranceExitsOne) {
  // no gradient meets differences of whole runs to 1e-15
  const CmdResult r = run(kRun + " --check --check-tolerance 1e-15");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("-> FAILED"), std::string::npos) << r.out;
}

// reach_arm.osim's hand_point marker: at the final time (marker:) and tracked over the run
// against a TRC the test writes (track:, a straight path of the marker from its start, in mm);
// --check compares the adjoint with central differences of whole runs
TEST_F(GradientCli, MarkerAndTrackedMarkerObjectivesAgreeWithCentralDifferences) {
  const fs::path trc = dir_ / "path.trc";
  {
    std::ofstream f(trc);
    f << "PathFileType\t4\t(X/Y/Z)\tpath.trc\n"
         "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n"
         "100\t100\t11\t1\tmm\t100\t1\t11\n"
         "Frame#\tTime\thand_point\t\t\n"
         "\t\tX1\tY1\tZ1\n";
    // from near the hanging hand toward the front, 0.1 s
    for (int r = 0; r <= 10; ++r) {
      const double a = r / 10.0;
      f << r + 1 << "\t" << 0.01 * r << "\t" << 50.0 + 150.0 * a << "\t" << -600.0 + 100.0 * a << "\t" << 0.0 << "\n";
    }
  }
  const std::string base = "gradient --model " + scene("reach_arm.osim") +
                           " --duration 0.1 --dt 0.005 --params 'torques:shoulder_flexion@2,elbow_flexion=0.5'";
  for (const std::string objective :
       {std::string("marker:hand_point=0.2,-0.5,0.05;0.1*speed"), "track:hand_point=" + trc.string(),
        "10*track:hand_point=" + trc.string() + ";marker:hand_point=0.2,-0.5,0.05"}) {
    // measured worst relative errors 5.9e-12, 2.9e-10, 3.2e-10 (the differences' own error)
    const CmdResult r = runRedmax(dir_, base + " --objective '" + objective + "' --check --check-tolerance 5e-9");
    EXPECT_EQ(r.code, 0) << objective << "\n" << r.out << r.err;
    EXPECT_NE(r.out.find("-> ok"), std::string::npos) << objective << "\n" << r.out;
  }
  // bad input: an unknown marker, a file without the marker, a file that does not cover the run
  CmdResult r = runRedmax(dir_, base + " --objective 'marker:nose=0,0,0'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no marker named 'nose'"), std::string::npos) << r.err;
  r = runRedmax(dir_, "gradient --model " + scene("reach_arm.osim") +
                          " --duration 0.2 --params 'torques:elbow_flexion' --objective 'track:hand_point=" +
                          trc.string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("does not cover the run"), std::string::npos) << r.err;
}

// coords: on running_leg.osim against osim_models/running_leg_swing.mot (11 coordinates, degrees and
// metres): --check compares the adjoint with central differences of whole runs; a malformed motion
// exits 2 with the reader's FILE:LINE, an unknown coordinate name with the names listed
TEST_F(GradientCli, CoordinateTrackingAgreesWithCentralDifferences) {
  const std::string swing = std::string(REDMAX_SOURCE_DIR) + "/osim_models/running_leg_swing.mot";
  CmdResult r = runRedmax(dir_, "gradient --model " + scene("running_leg.osim") +
                                    " --duration 0.05 --dt 0.001 --params "
                                    "'torques:hip_flexion_r@2,knee_angle_r,ankle_angle_r;q0:knee_angle_r;qdot0:hip_"
                                    "flexion_r' --objective 'coords:" + swing + "' --check --check-tolerance 1e-11");
  EXPECT_EQ(r.code, 0) << r.out << r.err;  // measured worst relative error 1.4e-12
  EXPECT_NE(r.out.find("-> ok"), std::string::npos) << r.out;
  const fs::path broken = dir_ / "broken.mot";
  {
    std::ofstream f(broken);
    f << "broken\nversion=1\nnRows=2\nnColumns=2\ninDegrees=yes\nendheader\ntime\telbow_flexion\n0\t1\n0.1\tx\n";
  }
  const std::string base = "gradient --model " + scene("reach_arm.osim") + " --duration 0.1 --params torques:elbow_flexion ";
  r = runRedmax(dir_, base + "--objective coords:" + broken.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: " + broken.string() + ":9: 'x' is not a number\n");
  r = runRedmax(dir_, base + "--objective 'coords:" + swing + "@elbow_flexion,knee,hip'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("': the model has no coordinate named knee, hip\n"), std::string::npos) << r.err;
}

TEST_F(GradientCli, BadSpecsExitTwo) {
  CmdResult r = run("--duration 0.1 --params 'torques:elbow' --objective speed");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: --params 'torques:elbow': no coordinate named 'elbow'\n");
  r = run("--duration 0.1 --params 'torques:q1' --objective 'point:link2@0,0,0'");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: --objective 'point:link2@0,0,0': expected point:BODY@x,y,z=X,Y,Z\n");
  r = run("--duration 0.1 --params 'masses:via_muscle' --objective speed");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("needs a positive mass for it in --muscle-mass-kg via_muscle=KG"), std::string::npos) << r.err;
  r = run("--duration 0.1 --objective speed");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: gradient needs --params\n(see `redmax gradient --help`)\n");
}

}  // namespace
