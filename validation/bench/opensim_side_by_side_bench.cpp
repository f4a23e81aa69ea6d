// OpenSim 4.6 and redmax on the same setups, in one run (docs/performance.md §11). Built only when
// plugin/opensim finds an OpenSim installation; needs ../shared (REDMAX_SHARED_DIR).
//
//   forward/arm26_standard   OpenSim's arm26 ForwardTool test setup (Applications/Forward/tests), 1 s,
//                            its muscles read as Thelen2003Muscle_Deprecated as the test does
//   forward/arm26_thelen     the same setup with the model's own Thelen2003Muscle
//   forward/gait2354         gait2354 (23 DoF, 54 Thelen2003Muscle), every muscle at excitation 0.2
//                            (a ControlSet file) from equilibrium, 0.1 s, tolerance 1e-4
//   forward/gait2354_tight   the same at tolerance 1e-8 (both engines converged: their difference
//                            is the models', not the integrators')
//   forward/gait10dof18musc_tight  set F's subject01 (planar, 10 DoF, 18 Millard2012EquilibriumMuscle)
//                            at excitation 0.2 from equilibrium, 0.1 s, tolerance 1e-8
//   analyze/arm26            OpenSim's arm26 static-optimization test setup (Applications/Analyze/tests),
//                            read as Thelen2003Muscle_Deprecated as its first standard
//   analyze/gait2392_E       set E (gait2392, 92 muscles, GRF, 0.4-1.6 s, 6 Hz) with the reserves
//                            `redmax gait-study` generates (converter/analyze/setup_writer.hpp)
//   analyze/gait10dof18musc_F  set F (Gait10dof18musc subject01, 18 Millard muscles, GRF, 0-2.5 s,
//                            6 Hz) with the same generated reserves
//
// Each engine runs the same setup file: OpenSim's ForwardTool / AnalyzeTool (construction reads the
// model and inputs; run() integrates or solves every frame and writes its files), redmax's
// ForwardTool / AnalyzeTool (construction, then run and write). redmax also runs each case with
// physiological muscle mass in every muscle (OpenSim cannot). Both write into a temporary folder.
// After the runs a table gives each engine's run time, construction time, the ratio of run times
// (redmax / OpenSim, below 1: redmax is faster) and how far the two engines' results are apart
// (forward: largest difference of a coordinate over the common output rows; analyze: largest
// activation difference), so that a speed is never reported for a run that computed something else.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <OpenSim/Actuators/RegisterTypes_osimActuators.h>
#include <OpenSim/Analyses/RegisterTypes_osimAnalyses.h>
#include <OpenSim/Common/Function.h>  // before the tools: ArrayPtrs<Function> needs the complete type
#include <OpenSim/Common/Logger.h>
#include <OpenSim/Common/Object.h>
#include <OpenSim/Simulation/RegisterTypes_osimSimulation.h>
#include <OpenSim/Tools/AnalyzeTool.h>
#include <OpenSim/Tools/ForwardTool.h>
#include <OpenSim/Tools/RegisterTypes_osimTools.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "converter/analyze/analyze_tool.hpp"
#include "converter/analyze/setup_writer.hpp"
#include "converter/atomic_file.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "validation/forward/constant_excitation.hpp"
#include "validation/forward/forward_tool.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string shared(const std::string& rel) { return std::string(REDMAX_SHARED_DIR) + "/opensim/" + rel; }

fs::path scratch() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("redmax_side_by_side_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

// one case's timings and its agreement, filled by the benchmarks, printed by main
struct Row {
  double opensim_construct = NAN, opensim_run = NAN;
  double redmax_construct = NAN, redmax_run = NAN, redmax_mass_run = NAN;
  double span = NAN;  ///< simulated seconds (forward) or frames (analyze)
  double difference = NAN;
  std::string unit, difference_what;
};
std::map<std::string, Row>& rows() {
  static std::map<std::string, Row> r;
  return r;
}

// OpenSim's Object::renameType cannot be undone (renaming a type to itself is a no-op), so the cases
// that read the muscles as another class run last and a later case that needs the class as written
// is refused rather than silently run with the renamed one
bool renameThelen(benchmark::State& st, const std::string& muscle_class) {
  static std::string current;
  if (muscle_class == current) return true;
  if (!current.empty()) {
    st.SkipWithError(("OpenSim's Thelen2003Muscle is already read as " + current +
                      " in this process (renameType cannot be undone): run this case alone").c_str());
    return false;
  }
  OpenSim::Object::renameType("Thelen2003Muscle", muscle_class);
  current = muscle_class;
  return true;
}

// OpenSim resolves a setup's relative paths against the working directory (opensim-cmd run-tool
// runs in the setup's folder): do the same while an OpenSim tool is built and run
struct InDirectory {
  fs::path old = fs::current_path();
  explicit InDirectory(const fs::path& d) { fs::current_path(d); }
  ~InDirectory() { fs::current_path(old); }
};

// the column of `label` in s, or of the label whose last path element is the coordinate (OpenSim 4's
// /jointset/J/C/value against redmax's same names)
int column(const redmax::osim::Storage& s, const std::string& label) {
  for (std::size_t i = 0; i < s.labels.size(); ++i)
    if (s.labels[i] == label) return static_cast<int>(i);
  return -1;
}

// largest |a - b| over a's `/value` columns, at the rows of a whose times b also has (to 1e-9 s)
double coordinateDifference(const redmax::osim::Storage& a, const redmax::osim::Storage& b) {
  double worst = 0.0;
  int compared = 0;
  for (std::size_t c = 0; c < a.labels.size(); ++c) {
    const std::string& l = a.labels[c];
    if (l.size() < 6 || l.compare(l.size() - 6, 6, "/value") != 0) continue;
    const int cb = column(b, l);
    if (cb < 0) continue;
    std::size_t j = 0;
    for (std::size_t i = 0; i < a.time.size(); ++i) {
      while (j < b.time.size() && b.time[j] < a.time[i] - 1e-9) ++j;
      if (j < b.time.size() && std::abs(b.time[j] - a.time[i]) <= 1e-9) {
        worst = std::max(worst, std::abs(a.data(i, c) - b.data(j, cb)));
        ++compared;
      }
    }
  }
  return compared > 0 ? worst : NAN;
}

// ---------------------------------------------------------------------------------------------
// forward

std::string constantExcitationSetup(const std::string& model, const std::string& tag, double t1, double excitation,
                                    double tolerance) {
  return redmax::validation::writeConstantExcitationSetup(model, (scratch() / tag).string(), tag, t1, excitation,
                                                          tolerance);
}

struct ForwardCase {
  std::string setup, muscle_class;  ///< "" = as written
};

void OpenSimForward(benchmark::State& st, std::string name, ForwardCase fc) {
  Row& row = rows()[name];
  const fs::path out = scratch() / ("opensim_" + name);
  if (!renameThelen(st, fc.muscle_class)) return;
  for (auto _ : st) {
    InDirectory in(fs::path(fc.setup).parent_path());
    const auto t0 = Clock::now();
    OpenSim::ForwardTool tool(fc.setup);
    row.opensim_construct = since(t0);
    tool.setResultsDir(out.string());
    const auto t1 = Clock::now();
    const bool ok = tool.run();
    row.opensim_run = since(t1);
    row.span = tool.getFinalTime() - tool.getStartTime();
    if (!ok) st.SkipWithError("OpenSim's ForwardTool failed");
  }
  st.counters["sim_per_wall"] = row.span / row.opensim_run;
  row.unit = "simulated s / wall s";
}

void RedmaxForward(benchmark::State& st, std::string name, ForwardCase fc, bool mass) {
  Row& row = rows()[name];
  redmax::validation::ForwardToolSettings s;
  s.setup_file = fc.setup;
  s.muscle_class = fc.muscle_class;
  s.out_dir = (scratch() / ("redmax_" + name + (mass ? "_mass" : ""))).string();
  if (mass) s.muscle_mass.source = redmax::osim::MuscleMassOptions::Source::Physiological;
  for (auto _ : st) {
    try {
      const auto t0 = Clock::now();
      const redmax::validation::ForwardTool tool(s);
      const double construct = since(t0);
      const auto t1 = Clock::now();
      const redmax::validation::ForwardResult r = tool.run();
      if (r.failed) {
        st.SkipWithError(r.failure.c_str());
        return;
      }
      tool.write(r);
      const double run = since(t1);
      st.counters["steps"] = static_cast<double>(r.stats.steps);
      st.counters["sim_per_wall"] = (tool.setup().final_time - tool.setup().initial_time) / run;
      if (mass) {
        row.redmax_mass_run = run;
      } else {
        row.redmax_construct = construct;
        row.redmax_run = run;
        const fs::path theirs = scratch() / ("opensim_" + name) / (tool.setup().name + "_states.sto");
        if (fs::exists(theirs))
          row.difference = coordinateDifference(r.states, redmax::osim::readStorage(theirs.string()));
        row.difference_what = "max |q - q_OpenSim| at common rows (first, last; rad or m)";
      }
    } catch (const std::exception& e) {
      st.SkipWithError(e.what());
      return;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// analyze

std::string setE() {
  static const std::string setup = [] {
    redmax::osim::IdToolConfig t;
    const std::string e = "Pipelines/Gait2392_Simbody/";
    t.model_file = shared("opensim-models@a26e12c/" + e + "OutputReference/subject01_simbody.osim");
    t.coordinates_file = shared("opensim-models/" + e + "subject01_walk1_ik.mot");
    t.external_loads_file = shared("opensim-models/" + e + "subject01_walk1_grf.xml");
    t.lowpass_cutoff_hz = 6.0;
    t.t0 = 0.4;
    t.t1 = 1.6;
    return redmax::osim::writeStaticOptimizationSetup(t, {}, (scratch() / "gait2392_E").string()).setup_file;
  }();
  return setup;
}

std::string setF() {
  static const std::string setup = [] {
    redmax::osim::IdToolConfig t;
    const std::string f = "Pipelines/Gait10dof18musc/OutputReference/";
    t.model_file = shared("opensim-models@a26e12c/" + f + "subject01.osim");
    t.coordinates_file = shared("opensim-models/" + f + "IK/subject01_walk_IK.mot");
    t.external_loads_file = shared("opensim-models/" + f + "ExperimentalData/subject01_walk_grf.xml");
    t.lowpass_cutoff_hz = 6.0;
    t.t0 = 0.0;
    t.t1 = 2.5;
    return redmax::osim::writeStaticOptimizationSetup(t, {}, (scratch() / "gait10dof18musc_F").string()).setup_file;
  }();
  return setup;
}

std::string arm26SO() {
  return shared("opensim-core/Applications/Analyze/tests/resources/arm26_Setup_StaticOptimization.xml");
}

// the activation file an AnalyzeTool writes for its StaticOptimization
fs::path activationFile(const fs::path& dir, const std::string& tool) {
  return dir / (tool + "_StaticOptimization_activation.sto");
}

struct AnalyzeCase {
  std::string setup, muscle_class;  ///< "" = as written
};

void OpenSimAnalyze(benchmark::State& st, std::string name, AnalyzeCase ac) {
  Row& row = rows()[name];
  const fs::path out = scratch() / ("opensim_" + name);
  const std::string setup = ac.setup;
  if (!renameThelen(st, ac.muscle_class)) return;
  for (auto _ : st) {
    InDirectory in(fs::path(setup).parent_path());
    const auto t0 = Clock::now();
    OpenSim::AnalyzeTool tool(setup);
    row.opensim_construct = since(t0);
    tool.setResultsDir(out.string());
    const auto t1 = Clock::now();
    const bool ok = tool.run();
    row.opensim_run = since(t1);
    if (!ok) st.SkipWithError("OpenSim's AnalyzeTool failed");
    const fs::path f = activationFile(out, tool.getName());
    if (fs::exists(f)) row.span = static_cast<double>(redmax::osim::readStorage(f.string()).time.size());
  }
  st.counters["frames_per_s"] = row.span / row.opensim_run;
  row.unit = "frames / s";
}

void RedmaxAnalyze(benchmark::State& st, std::string name, AnalyzeCase ac, bool mass) {
  Row& row = rows()[name];
  redmax::osim::AnalyzeToolSettings s;
  s.setup_file = ac.setup;
  if (!ac.muscle_class.empty()) s.muscle_class = ac.muscle_class;
  s.out_dir = (scratch() / ("redmax_" + name + (mass ? "_mass" : ""))).string();
  if (mass) s.muscle_mass.source = redmax::osim::MuscleMassOptions::Source::Physiological;
  for (auto _ : st) {
    try {
      const auto t0 = Clock::now();
      const redmax::osim::AnalyzeTool tool(s);
      const double construct = since(t0);
      const auto t1 = Clock::now();
      const redmax::osim::StaticOptimizationRun r = tool.runStaticOptimization();
      tool.writeStaticOptimization(r);
      const double run = since(t1);
      st.counters["frames_per_s"] = static_cast<double>(r.frames.size()) / run;
      st.counters["failed_frames"] = r.failed;
      if (mass) {
        row.redmax_mass_run = run;
        continue;
      }
      row.redmax_construct = construct;
      row.redmax_run = run;
      const fs::path theirs = activationFile(scratch() / ("opensim_" + name), tool.setup().name);
      if (!fs::exists(theirs)) continue;
      const redmax::osim::Storage o = redmax::osim::readStorage(theirs.string());
      const redmax::osim::Storage m = redmax::osim::readStorage(activationFile(*s.out_dir, tool.setup().name).string());
      double worst = 0.0;
      for (std::size_t c = 0; c < m.labels.size(); ++c) {
        const int co = column(o, m.labels[c]);
        if (co < 0) continue;
        for (std::size_t i = 0; i < std::min(m.time.size(), o.time.size()); ++i)
          worst = std::max(worst, std::abs(m.data(i, c) - o.data(i, co)));
      }
      row.difference = worst;
      row.difference_what = "max |activation - OpenSim's|";
    } catch (const std::exception& e) {
      st.SkipWithError(e.what());
      return;
    }
  }
}

// ---------------------------------------------------------------------------------------------

const std::string kArm26Forward = "opensim-core/Applications/Forward/tests/resources/arm26_Setup_Forward.xml";

void registerAll() {
  const std::string deprecated = "Thelen2003Muscle_Deprecated";
  const ForwardCase arm26_std{shared(kArm26Forward), deprecated};
  const ForwardCase arm26_own{shared(kArm26Forward), ""};
  const ForwardCase gait2354{
      constantExcitationSetup(shared("opensim-models/Models/Gait2354_Simbody/gait2354_simbody.osim"), "gait2354", 0.1,
                              0.2, 1e-4),
      ""};
  auto forward = [](const std::string& name, const ForwardCase& fc) {
    // OpenSim first: redmax's run compares its states with the file OpenSim wrote
    benchmark::RegisterBenchmark(("opensim/forward/" + name).c_str(), OpenSimForward, name, fc)
        ->Unit(benchmark::kMillisecond)->Iterations(1);
    benchmark::RegisterBenchmark(("redmax/forward/" + name).c_str(), RedmaxForward, name, fc, false)
        ->Unit(benchmark::kMillisecond)->Iterations(1);
    benchmark::RegisterBenchmark(("redmax/forward/" + name + "_muscle_mass").c_str(), RedmaxForward, name, fc, true)
        ->Unit(benchmark::kMillisecond)->Iterations(1);
  };
  auto analyze = [](const std::string& name, const AnalyzeCase& ac) {
    benchmark::RegisterBenchmark(("opensim/analyze/" + name).c_str(), OpenSimAnalyze, name, ac)
        ->Unit(benchmark::kMillisecond)->Iterations(1);
    benchmark::RegisterBenchmark(("redmax/analyze/" + name).c_str(), RedmaxAnalyze, name, ac, false)
        ->Unit(benchmark::kMillisecond)->Iterations(1);
    benchmark::RegisterBenchmark(("redmax/analyze/" + name + "_muscle_mass").c_str(), RedmaxAnalyze, name, ac, true)
        ->Unit(benchmark::kMillisecond)->Iterations(1);
  };
  // the same at 1e-8: how far the two engines' answers are apart once both have converged
  const ForwardCase gait2354_tight{
      constantExcitationSetup(shared("opensim-models/Models/Gait2354_Simbody/gait2354_simbody.osim"), "gait2354_tight",
                              0.1, 0.2, 1e-8),
      ""};
  // Millard2012EquilibriumMuscle with elastic tendons, planar gait model of set F
  const ForwardCase gait10dof{
      constantExcitationSetup(
          shared("opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim"), "gait10dof18musc",
          0.1, 0.2, 1e-8),
      ""};
  // the muscles as written first (renameType cannot be undone), then as the standards' class
  forward("arm26_thelen", arm26_own);
  forward("gait2354", gait2354);
  forward("gait2354_tight", gait2354_tight);
  forward("gait10dof18musc_tight", gait10dof);
  analyze("gait2392_E", {setE(), ""});
  analyze("gait10dof18musc_F", {setF(), ""});
  forward("arm26_standard", arm26_std);
  analyze("arm26", {arm26SO(), deprecated});
}

void printTable() {
  std::printf("\n%-16s %-22s %10s %10s %8s %12s %10s %9s %11s  %s\n", "case", "unit", "OpenSim", "redmax",
              "ratio", "redmax+mass", "setup OS s", "setup rm s", "difference", "(what)");
  for (const auto& [name, r] : rows()) {
    const double os = r.span / r.opensim_run, rm = r.span / r.redmax_run, rmm = r.span / r.redmax_mass_run;
    std::printf("%-16s %-22s %10.3g %10.3g %8.3f %12.3g %10.3f %9.3f %11.2e  %s\n", name.c_str(), r.unit.c_str(), os, rm,
                r.redmax_run / r.opensim_run, rmm, r.opensim_construct, r.redmax_construct, r.difference,
                r.difference_what.c_str());
  }
  std::printf("ratio = redmax run time / OpenSim run time on the same setup (below 1: redmax faster); "
              "redmax+mass: physiological mass in every muscle (OpenSim cannot)\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (!fs::exists(std::string(REDMAX_SHARED_DIR) + "/opensim")) {
    std::printf("skipped: %s/opensim is absent (the shared OpenSim data)\n", REDMAX_SHARED_DIR);
    return 0;
  }
  // OpenSim's log off (it prints every step); REDMAX_OPENSIM_LOG=1 keeps it, to see why a run failed
  if (!std::getenv("REDMAX_OPENSIM_LOG")) OpenSim::Logger::setLevel(OpenSim::Logger::Level::Off);
  RegisterTypes_osimSimulation();
  RegisterTypes_osimActuators();
  RegisterTypes_osimAnalyses();
  RegisterTypes_osimTools();
  registerAll();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  printTable();
  // REDMAX_KEEP_OUTPUT=1 keeps both engines' files (the folder is printed)
  std::error_code ec;
  if (std::getenv("REDMAX_KEEP_OUTPUT")) std::printf("outputs kept in %s\n", scratch().c_str());
  else fs::remove_all(scratch(), ec);
  return 0;
}
