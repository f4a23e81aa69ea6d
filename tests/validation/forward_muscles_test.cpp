// Muscle-driven forward runs through the ForwardTool (validation/forward/forward_tool.hpp):
//   - arm26 with its own class, Thelen2003Muscle, under rk45: a trial stage once pushed TRImed's
//     fibre to 80 m (fal underflows, fpe infinite) and the run stopped at t = 0.184 s with a NaN
//     rate; rk45 now retries such a step from its start with a smaller step. The run completes
//     and agrees with cvode's;
//   - the wrist (25 Schutte1993Muscle_Deprecated with their SimmSpline curves) stays finite.
// A run that needs cvode (a stiff tendon) is in forward_hard_cases_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "converter/osim_reader.hpp"
#include "tests/converter/converter_test_util.hpp"
#include "validation/forward/forward_tool.hpp"

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;

std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }

/// a ForwardTool setup for `model` from t0 to t1, every muscle at a constant excitation
std::string constantExcitationSetup(const std::string& model, double t1, double excitation, double tolerance) {
  const osim::ModelDescription d = osim::readOsimModel(model);
  std::ostringstream f;
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenSimDocument Version=\"40000\">\n"
    << "<ForwardTool name=\"run\">\n<model_file>" << model << "</model_file>\n"
    << "<initial_time>0</initial_time>\n<final_time>" << t1 << "</final_time>\n"
    << "<solve_for_equilibrium_for_auxiliary_states>true</solve_for_equilibrium_for_auxiliary_states>\n"
    << "<maximum_number_of_integrator_steps>200000</maximum_number_of_integrator_steps>\n"
    << "<integrator_error_tolerance>" << tolerance << "</integrator_error_tolerance>\n"
    << "<ControllerSet><objects><PrescribedController name=\"constant\">\n<FunctionSet><objects>\n";
  for (const auto& m : d.muscles)
    if (m.is_muscle) f << "<Constant name=\"" << m.name << "\"><value>" << excitation << "</value></Constant>\n";
  f << "</objects></FunctionSet>\n</PrescribedController></objects></ControllerSet>\n</ForwardTool>\n</OpenSimDocument>\n";
  return f.str();
}

int column(const osim::Storage& s, const std::string& label) {
  for (int j = 0; j < s.numColumns(); ++j)
    if (s.labels[j] == label) return j;
  return -1;
}

/// RMS over the rows of each column (same labels, same rows), the worst over columns whose label
/// contains `part`
double worstRms(const osim::Storage& a, const osim::Storage& b, const std::string& part, std::string* which) {
  double worst = 0;
  for (int j = 0; j < a.numColumns(); ++j) {
    if (a.labels[j].find(part) == std::string::npos) continue;
    const int k = column(b, a.labels[j]);
    if (k < 0) return INFINITY;
    double ss = 0;
    for (int r = 0; r < a.numRows(); ++r) ss += std::pow(a.data(r, j) - b.data(r, k), 2);
    const double rms = std::sqrt(ss / a.numRows());
    if (rms > worst) {
      worst = rms;
      if (which) *which = a.labels[j];
    }
  }
  return worst;
}

TEST(ForwardMuscles, Arm26OwnThelenClassCompletesUnderRk45AndAgreesWithCvode) {
  const std::string dir = shared("opensim-core/Applications/Forward/tests/resources");
  if (!fs::exists(dir + "/arm26_Setup_Forward.xml")) GTEST_SKIP() << "shared OpenSim data not found: " << dir;
  ForwardToolSettings s;
  s.setup_file = dir + "/arm26_Setup_Forward.xml";
  s.report_interval = 0.005;
  ForwardResult run[2];
  const char* integrators[2] = {"rk45", "cvode"};
  for (int i = 0; i < 2; ++i) {
    s.integrator = integrators[i];
    // cvode's own error control at the setup's 1e-5 is looser than rk45's: the reference at 1e-8
    s.tolerance = i == 0 ? 1e-5 : 1e-8;
    const ForwardTool tool(s);
    run[i] = tool.run();
    ASSERT_FALSE(run[i].failed) << integrators[i] << ": " << run[i].failure;
    std::printf("[ measured ] arm26 Thelen2003Muscle %s: %ld steps, %ld rhs, %ld failed, %.2f s wall\n",
                integrators[i], run[i].stats.steps, run[i].stats.rhs_evals, run[i].stats.failed_steps,
                run[i].wall_s);
  }
  ASSERT_EQ(run[0].states.numRows(), run[1].states.numRows());
  std::string which;
  const double q = worstRms(run[0].states, run[1].states, "/value", &which);
  std::printf("[ measured ] rk45 vs cvode RMS: coordinates %.2e (%s)", q, which.c_str());
  const double u = worstRms(run[0].states, run[1].states, "/speed", &which);
  std::printf(", speeds %.2e (%s)", u, which.c_str());
  const double lf = worstRms(run[0].states, run[1].states, "fiber_length", &which);
  std::printf(", fibre lengths %.2e (%s)", lf, which.c_str());
  const double a = worstRms(run[0].states, run[1].states, "activation", &which);
  std::printf(", activations %.2e (%s)\n", a, which.c_str());
  EXPECT_LE(q, 1e-3);   // measured 1.9e-4
  EXPECT_LE(u, 3e-3);   // measured 7.7e-4 (rk45 1e-5 against cvode 1e-8)
  EXPECT_LE(lf, 3e-5);  // measured 7.6e-6
  EXPECT_LE(a, 1e-5);   // measured 1.5e-6
  // the run passes where it stopped before (t = 0.184 s); TRImed's fibre stays physical
  const int c = column(run[0].states, "/forceset/TRImed/fiber_length");
  ASSERT_GE(c, 0);
  for (int r = 0; r < run[0].states.numRows(); ++r) {
    EXPECT_GT(run[0].states.data(r, c), 0.03) << run[0].states.time[r];
    EXPECT_LT(run[0].states.data(r, c), 0.3) << run[0].states.time[r];
  }
}

TEST(ForwardMuscles, WristSchutteMusclesStayFinite) {
  const std::string model = shared("opensim-models/Models/WristModel/wrist.osim");
  if (!fs::exists(model)) GTEST_SKIP() << "shared OpenSim data not found: " << model;
  osim::test::TempDir dir;
  ForwardToolSettings s;
  s.setup_file = dir.write("setup.xml", constantExcitationSetup(model, 0.1, 0.3, 1e-5));
  s.report_interval = 0.01;
  s.integrator = "cvode";
  const ForwardTool tool(s);
  ASSERT_EQ(tool.system().numStates(), 2 * 25) << "every Schutte muscle has activation and fibre length";
  const ForwardResult r = tool.run();
  ASSERT_FALSE(r.failed) << r.failure;
  for (int j = 0; j < r.states.numColumns(); ++j)
    for (int k = 0; k < r.states.numRows(); ++k) ASSERT_TRUE(std::isfinite(r.states.data(k, j))) << r.states.labels[j];
  // activation rises towards the excitation: (u - a)(7.667 u + 1.46) / 0.1 from 0 (no states file)
  const int c = column(r.states, "/forceset/FCR/activation");
  ASSERT_GE(c, 0);
  EXPECT_GT(r.states.data(r.states.numRows() - 1, c), 0.29);
  std::printf("[ measured ] wrist 25 Schutte muscles, 0.1 s, cvode: %ld steps, %ld rhs, %.2f s wall\n", r.stats.steps,
              r.stats.rhs_evals, r.wall_s);
}

}  // namespace
}  // namespace redmax::validation
