#pragma once
// Shared by the `redmax id` and `redmax validate` CLI tests: find the redmax executable of the
// same build, run it in a temporary directory, and write a planar double pendulum (Pin, Pin) with
// the closed-form motion q1 = 0.7 sin(2 pi 0.8 t), q2 = 0.9 sin(2 pi 1.1 t) (degrees in the file,
// 2 s at 500 Hz) whose inverse-dynamics torques are known in closed form.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/cli/cli_test_util.hpp"

namespace redmax_test {

namespace fs = std::filesystem;

// the redmax executable of the same build, output capture: shared with the CLI tests
using redmax::cli_test::CmdResult;
using redmax::cli_test::redmaxExe;
using redmax::cli_test::slurp;

inline std::string num(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}

// closed-form torques of the pendulum below (Lagrange; link inertia Izz 0.05 about the COM),
// for q1 = 0.7 sin(2 pi 0.8 t), q2 = 0.9 sin(2 pi 1.1 t)
inline Eigen::Vector2d closedFormTau(double t) {
  const double m1 = 1.3, c1 = 0.45, I1 = 0.05, L1 = 0.9, m2 = 0.8, c2 = 0.35, I2 = 0.05, g = 9.80665;
  const double w1 = 2 * M_PI * 0.8, w2 = 2 * M_PI * 1.1;
  const double a = 0.7 * std::sin(w1 * t), b = 0.9 * std::sin(w2 * t);
  const double ad = 0.7 * w1 * std::cos(w1 * t), bd = 0.9 * w2 * std::cos(w2 * t);
  const double add = -w1 * w1 * a, bdd = -w2 * w2 * b;
  const double h = m2 * L1 * c2 * std::sin(b);
  const double M11 = I1 + m1 * c1 * c1 + I2 + m2 * (L1 * L1 + c2 * c2 + 2 * L1 * c2 * std::cos(b));
  const double M12 = I2 + m2 * (c2 * c2 + L1 * c2 * std::cos(b)), M22 = I2 + m2 * c2 * c2;
  return {M11 * add + M12 * bdd - h * (2 * ad * bd + bd * bd) + (m1 * c1 + m2 * L1) * g * std::sin(a) +
              m2 * c2 * g * std::sin(a + b),
          M12 * add + M22 * bdd + h * ad * ad + m2 * c2 * g * std::sin(a + b)};
}

/// temporary directory with the pendulum model (dp.osim) and motion (dp.mot) written in it
class PendulumCliTest : public ::testing::Test {
 protected:
  void makeDir(const std::string& prefix) {
    dir_ = fs::temp_directory_path() / (prefix + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    writePendulum();
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  CmdResult run(const std::string& args) const { return redmax::cli_test::runRedmax(dir_, args, true); }
  void write(const std::string& name, const std::string& text) const {
    fs::create_directories((dir_ / name).parent_path());
    std::ofstream(dir_ / name) << text;
  }

  // a planar double pendulum (Pin, Pin), the motion above in degrees, 2 s at 500 Hz
  void writePendulum() {
    auto body = [](const std::string& n, double m, double c) {
      return "<Body name=\"" + n + "\"><mass>" + num(m) + "</mass><mass_center>0 " + num(-c) +
             " 0</mass_center><inertia>0.1 0.1 0.05 0 0 0</inertia></Body>\n";
    };
    auto pin = [](const std::string& n, const std::string& parent, const std::string& child,
                  const std::string& at, const std::string& q) {
      return "<PinJoint name=\"" + n + "\"><socket_parent_frame>" + n + "_p</socket_parent_frame>"
             "<socket_child_frame>" + n + "_c</socket_child_frame><coordinates><Coordinate name=\"" + q +
             "\"/></coordinates><frames><PhysicalOffsetFrame name=\"" + n + "_p\"><socket_parent>" + parent +
             "</socket_parent><translation>" + at + "</translation><orientation>0 0 0</orientation>"
             "</PhysicalOffsetFrame><PhysicalOffsetFrame name=\"" + n + "_c\"><socket_parent>" + child +
             "</socket_parent><translation>0 0 0</translation><orientation>0 0 0</orientation>"
             "</PhysicalOffsetFrame></frames></PinJoint>\n";
    };
    write("dp.osim", "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
                     "<Model name=\"dp\"><Ground name=\"ground\"/><gravity>0 -9.80665 0</gravity>\n"
                     "<BodySet name=\"bodyset\"><objects>\n" + body("l1", 1.3, 0.45) + body("l2", 0.8, 0.35) +
                     "</objects></BodySet>\n<JointSet name=\"jointset\"><objects>\n" +
                     pin("j1", "/ground", "/bodyset/l1", "0 0 0", "q1") +
                     pin("j2", "/bodyset/l1", "/bodyset/l2", "0 -0.9 0", "q2") +
                     "</objects></JointSet>\n</Model>\n</OpenSimDocument>\n");
    std::ostringstream os;
    os.precision(17);
    os << "motion\nversion=1\nnRows=1001\nnColumns=3\ninDegrees=yes\nendheader\ntime\tq1\tq2\n";
    for (int i = 0; i <= 1000; ++i) {
      const double t = 0.002 * i;
      os << t << "\t" << 0.7 * std::sin(2 * M_PI * 0.8 * t) * 180 / M_PI << "\t"
         << 0.9 * std::sin(2 * M_PI * 1.1 * t) * 180 / M_PI << "\n";
    }
    write("dp.mot", os.str());
  }

  fs::path dir_;
};

}  // namespace redmax_test
