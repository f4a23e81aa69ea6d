// The wrapping double pendulum (Type III, smooth wrap model) in the work-precision ladder
// (validation/work_precision/work_precision.hpp), quick mode: every integrator runs its ladder,
// the scene crosses the contact change inside the quick run, two different tight integrators
// (rk45 and cvode) agree on the end state, and the scene conserves energy like a smooth one.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/integrators/integrator.hpp"
#include "validation/report/csv.hpp"
#include "validation/work_precision/work_precision.hpp"

namespace {

namespace fs = std::filesystem;
using namespace redmax;
using namespace redmax::validation;

std::string modelsDir() { return std::string(REDMAX_SOURCE_DIR) + "/osim_models"; }

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(WorkPrecisionWrap, QuickLadderRunsEveryIntegratorAndTightRunsAgree) {
  const fs::path dir = fs::temp_directory_path() / ("redmax_wp_wrap_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  WorkPrecisionOptions opt;
  opt.quick = true;
  opt.models_dir = modelsDir();
  opt.scenes = {"pendulum_wrap"};
  opt.studies = {"integrators"};
  opt.gnuplot = "none";
  const WorkPrecisionResult res = runWorkPrecision(dir.string(), opt);
  ASSERT_EQ(res.scenes.size(), 1u);
  const WorkPrecisionSceneResult& s = res.scenes[0];
  EXPECT_EQ(s.name, "pendulum_wrap");
  EXPECT_EQ(s.ndof, 2);
  // 6 integrators x 3 rungs, all in the CSV
  ASSERT_EQ(s.runs.size(), 18u);
  const CsvTable t = parseCsv(readText(dir / "pendulum_wrap.csv"));
  EXPECT_EQ(t.rows.size(), 18u);
  EXPECT_NE(readText(dir / "report.md").find("| pendulum_wrap (2 DoF"), std::string::npos);
  fs::remove_all(dir);

  double e_rk45 = -1.0, e_cvode = -1.0;
  for (const auto& r : s.runs) {
    std::printf("pendulum_wrap %s %s %.0e: %s error %.3e, drift %.3e J/s, %ld rhs\n", r.integrator.c_str(),
                r.knob.c_str(), r.value, r.ok ? "ok" : r.failure.c_str(), r.error, r.energy_drift, r.rhs_evals);
    EXPECT_TRUE(r.ok) << r.integrator << " " << r.value << ": " << r.failure;
    if (r.value == 1e-8 && r.integrator == "rk45") e_rk45 = r.error;
    if (r.value == 1e-8 && r.integrator == "cvode") e_cvode = r.error;
  }
  // the reference (rk45 rtol 1e-12) and the two tight runs: an explicit Runge-Kutta and a BDF
  // method agree on the end state (measured: rk45 1.1e-8, cvode 2.4e-7; bounds ~10x above)
  ASSERT_GE(e_rk45, 0.0);
  ASSERT_GE(e_cvode, 0.0);
  EXPECT_LT(e_rk45, 1e-7);
  EXPECT_LT(e_cvode, 3e-6);
  // the smooth model keeps the mass matrix continuous: the reference conserves energy (measured
  // 1.9e-11 J/s over 2 s; a via-point scene's reference drifts 1.5e-2 J/s)
  EXPECT_LT(s.reference_energy_drift, 1e-8);
}

// the quick run (0.5 s) crosses the contact change, so the ladder exercises the wrap model's
// transition and not only the wrapped or the straight branch
TEST(WorkPrecisionWrap, QuickRunCrossesTheContactChange) {
  const WrapPendulum p = makeWrapPendulum(modelsDir(), WrapModel::Smooth);
  IntegratorOptions o;
  o.rtol = 1e-10;
  o.atol = 1e-12;
  auto integ = makeIntegrator("rk45", o);
  State s = p.initial;
  double d_prev = wrapPenetration(p.system.model(), p.muscle, s);
  EXPECT_GT(d_prev, 0.0) << "wrapped at the start";
  int changes = 0;
  for (int k = 1; k <= 500; ++k) {
    integ->advance(p.system, s, 1e-3 * k);
    const double d = wrapPenetration(p.system.model(), p.muscle, s);
    changes += (d > 0) != (d_prev > 0);
    d_prev = d;
  }
  std::printf("contact changes in 0.5 s: %d\n", changes);
  EXPECT_GE(changes, 1);
}

}  // namespace
