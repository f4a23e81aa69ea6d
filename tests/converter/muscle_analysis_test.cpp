// MuscleAnalysis, Actuation and states_file of the AnalyzeTool (converter/analyze/muscle_analysis.hpp,
// states_file.hpp): the equilibrium identity per frame (tendon force = fibre force along the tendon),
// the path split into fibre and tendon (l_T + l_f cos(phi) = l), moment arms against central
// differences of the path length, equilibrium at rest (zero fibre velocity), states taken from a
// states file, OpenSim's testAnalyzeTool checks on Tug_of_War_Millard_Iso and the same identities on
// arm26, Actuation against MuscleAnalysis, OpenSim's file names.
#include "converter/analyze/muscle_analysis.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "converter/analyze/analyze_tool.hpp"
#include "converter/build/build_core_model.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "core/muscles/hill/millard2012_equilibrium_muscle.hpp"
#include "tests/converter/converter_test_util.hpp"

namespace redmax::osim {
namespace {

namespace fs = std::filesystem;

// two links on pins about z: a biarticular pennated Millard muscle over a via point and a
// Thelen2003Muscle across the elbow, and a CoordinateActuator on the shoulder
std::string armModel() {
  auto frame = [](const std::string& name, const std::string& parent, const std::string& t) {
    return "<PhysicalOffsetFrame name=\"" + name + "\"><socket_parent>" + parent + "</socket_parent><translation>" + t +
           "</translation><orientation>0 0 0</orientation></PhysicalOffsetFrame>\n";
  };
  auto pin = [&](const std::string& name, const std::string& parent, const std::string& child, const std::string& t) {
    return "<PinJoint name=\"" + name + "\"><socket_parent_frame>" + name + "_p</socket_parent_frame><socket_child_frame>" +
           name + "_c</socket_child_frame><coordinates><Coordinate name=\"" + name +
           "_q\"><default_value>0.4</default_value><range>-2 2</range></Coordinate></coordinates><frames>" +
           frame(name + "_p", parent, t) + frame(name + "_c", child, "0 0 0") + "</frames></PinJoint>\n";
  };
  const std::string bodies =
      "<Body name=\"upper\"><mass>2</mass><mass_center>0 -0.15 0</mass_center><inertia>0.02 0.02 0.02 0 0 0</inertia></Body>\n"
      "<Body name=\"lower\"><mass>1</mass><mass_center>0 -0.15 0</mass_center><inertia>0.01 0.01 0.01 0 0 0</inertia></Body>\n";
  const std::string joints = pin("shoulder", "/ground", "/bodyset/upper", "0 0 0") +
                             pin("elbow", "/bodyset/upper", "/bodyset/lower", "0 -0.3 0");
  auto point = [](const std::string& name, const std::string& body, const std::string& at) {
    return "<PathPoint name=\"" + name + "\"><socket_parent_frame>" + body + "</socket_parent_frame><location>" + at +
           "</location></PathPoint>\n";
  };
  const std::string forces =
      "<ForceSet><objects>\n"
      "<Millard2012EquilibriumMuscle name=\"bi\"><GeometryPath name=\"path\"><PathPointSet><objects>\n" +
      point("o", "/ground", "0.05 0.02 0") + point("v", "/bodyset/upper", "0.04 -0.15 0") +
      point("i", "/bodyset/lower", "0.03 -0.05 0") +
      "</objects></PathPointSet></GeometryPath><max_isometric_force>300</max_isometric_force>"
      "<optimal_fiber_length>0.14</optimal_fiber_length><tendon_slack_length>0.21</tendon_slack_length>"
      "<pennation_angle_at_optimal>0.3</pennation_angle_at_optimal><default_activation>0.3</default_activation>"
      "<default_fiber_length>0.12</default_fiber_length></Millard2012EquilibriumMuscle>\n"
      "<Thelen2003Muscle name=\"tri\"><GeometryPath name=\"path\"><PathPointSet><objects>\n" +
      point("o", "/bodyset/upper", "-0.03 -0.05 0") + point("i", "/bodyset/lower", "-0.02 0.02 0") +
      "</objects></PathPointSet></GeometryPath><max_isometric_force>200</max_isometric_force>"
      "<optimal_fiber_length>0.1</optimal_fiber_length><tendon_slack_length>0.14</tendon_slack_length>"
      "<pennation_angle>0.2</pennation_angle><default_activation>0.2</default_activation>"
      "<default_fiber_length>0.09</default_fiber_length></Thelen2003Muscle>\n"
      "<CoordinateActuator name=\"sh_reserve\"><coordinate>shoulder_q</coordinate><optimal_force>10</optimal_force>"
      "</CoordinateActuator>\n"
      "</objects></ForceSet>\n";
  return test::modernOsim(bodies, joints, forces);
}

double qShoulder(double t) { return 0.3 + 0.2 * std::sin(2 * t); }
double qElbow(double t) { return 0.6 + 0.3 * std::sin(3 * t); }
double uShoulder(double t) { return 0.4 * std::cos(2 * t); }
double uElbow(double t) { return 0.9 * std::cos(3 * t); }

std::string armMotion() {
  std::ostringstream os;
  os.precision(17);
  os << "Coordinates\nversion=1\nnRows=51\nnColumns=3\ninDegrees=no\nendheader\ntime\tshoulder_q\telbow_q\n";
  for (int k = 0; k <= 50; ++k) os << 0.02 * k << "\t" << qShoulder(0.02 * k) << "\t" << qElbow(0.02 * k) << "\n";
  return os.str();
}

std::string muscleAnalysisXml(const std::string& extra = "") {
  return "<MuscleAnalysis name=\"MuscleAnalysis\"><on>true</on>" + extra + "</MuscleAnalysis>\n"
         "<Actuation name=\"Actuation\"><on>true</on></Actuation>\n";
}

std::string setupXml(const std::string& analyses, const std::string& data, bool equilibrium = true,
                     const std::string& model = "m.osim", double t0 = 0.0, double t1 = 1.0) {
  std::ostringstream os;
  os << "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
     << "<AnalyzeTool name=\"arm\"><model_file>" << model << "</model_file><results_directory>Results</results_directory>"
     << "<output_precision>12</output_precision><initial_time>" << t0 << "</initial_time><final_time>" << t1
     << "</final_time><solve_for_equilibrium_for_auxiliary_states>" << (equilibrium ? "true" : "false")
     << "</solve_for_equilibrium_for_auxiliary_states><AnalysisSet name=\"Analyses\"><objects>\n"
     << analyses << "</objects></AnalysisSet>" << data << "</AnalyzeTool>\n</OpenSimDocument>\n";
  return os.str();
}

const hill::MuscleOutput& out(const MuscleFrame& f, int m) { return f.out[static_cast<size_t>(m)]; }

// per frame and muscle: tendon force = (active + passive) cos(phi) and l_T + l_f cos(phi) = l
void expectIdentities(const MuscleAnalysisRun& run, const std::vector<double>& fmax, double force_tol_rel,
                      const char* what) {
  double worst_force = 0.0, worst_length = 0.0;
  for (const MuscleFrame& f : run.frames)
    for (size_t c = 0; c < run.columns.muscle_index.size(); ++c) {
      const int m = run.columns.muscle_index[c];
      const hill::MuscleOutput& o = out(f, m);
      const double along = (o.active_fiber_force + o.passive_fiber_force) * std::cos(o.pennation_angle);
      worst_force = std::max(worst_force, std::abs(o.tendon_force - along) / fmax[c]);
      worst_length = std::max(worst_length, std::abs(o.tendon_length + o.fiber_length * std::cos(o.pennation_angle) -
                                                     f.length[m]));
      EXPECT_TRUE(std::isfinite(o.tendon_force)) << what << " " << run.columns.muscles[c] << " t " << f.time;
    }
  std::printf("[ measured ] %s: max |F_T - F_M cos(phi)| / F_max %.3g, max |l_T + l_f cos(phi) - l| %.3g m\n", what,
              worst_force, worst_length);
  EXPECT_LE(worst_force, force_tol_rel) << what;
  EXPECT_LE(worst_length, 1e-15) << what;  // measured 2.8e-17 .. 5.6e-17 m
}

TEST(MuscleAnalysis, EquilibriumAndPathIdentitiesAndOpenSimsFiles) {
  test::TempDir dir;
  dir.write("m.osim", armModel());
  dir.write("q.mot", armMotion());
  AnalyzeToolSettings s;
  s.setup_file = dir.write("setup.xml", setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>"));
  const AnalyzeTool tool(s);
  EXPECT_FALSE(tool.runsStaticOptimization());
  EXPECT_TRUE(tool.unsupportedAnalyses().empty());
  const MuscleAnalysisRun run = tool.runMuscleAnalyses();
  ASSERT_EQ(run.frames.size(), 51u);
  EXPECT_TRUE(run.failures.empty());
  ASSERT_EQ(run.columns.muscles, (std::vector<std::string>{"bi", "tri"}));
  ASSERT_EQ(run.columns.coordinates, (std::vector<std::string>{"shoulder_q", "elbow_q"}));
  // measured 3.3e-14 (the damped Millard's velocity solve; Thelen's balance is exact)
  expectIdentities(run, {300, 200}, 2e-13, "arm");
  // q and u as the coordinates' splines give them; the tri spans the elbow only
  for (const MuscleFrame& f : run.frames) {
    EXPECT_NEAR(f.q[0], qShoulder(f.time), 1e-12);
    EXPECT_NEAR(f.u[1], uElbow(f.time), 2e-3);  // natural quintic spline at the ends; measured below
    EXPECT_NEAR(f.dl_dq(1, 0), 0.0, 1e-15);  // round-off of the two links' Jacobians
    EXPECT_NE(f.dl_dq(0, 0), 0.0);
    EXPECT_NEAR(out(f, 0).activation, 0.3, 1e-15);
    EXPECT_NEAR(out(f, 1).activation, 0.2, 1e-15);
  }
  const auto files = tool.writeMuscleAnalyses(run);
  // MomentArm / Moment per coordinate, 16 quantities, then Actuation's three
  ASSERT_EQ(files.size(), 4u + 16u + 3u);
  EXPECT_EQ(fs::path(files[0]).filename(), "arm_MuscleAnalysis_MomentArm_shoulder_q.sto");
  EXPECT_EQ(fs::path(files[3]).filename(), "arm_MuscleAnalysis_Moment_elbow_q.sto");
  for (const char* q : {"FiberLength", "TendonLength", "NormalizedFiberLength", "PennationAngle", "ActiveFiberForce",
                        "PassiveFiberForce", "TendonForce", "FiberVelocity", "Length"})
    EXPECT_TRUE(fs::exists(dir.file(std::string("Results/arm_MuscleAnalysis_") + q + ".sto"))) << q;
  for (const char* q : {"force", "speed", "power"})
    EXPECT_TRUE(fs::exists(dir.file(std::string("Results/arm_Actuation_") + q + ".sto"))) << q;
  const Storage fl = readStorage(dir.file("Results/arm_MuscleAnalysis_FiberLength.sto"));
  EXPECT_EQ(fl.name, "FiberLength");
  EXPECT_EQ(fl.labels, (std::vector<std::string>{"bi", "tri"}));
  ASSERT_EQ(fl.numRows(), 51);
  EXPECT_NEAR(fl.data(10, 0), out(run.frames[10], 0).fiber_length, 1e-12);
  const Storage moment = readStorage(dir.file("Results/arm_MuscleAnalysis_Moment_elbow_q.sto"));
  EXPECT_NEAR(moment.data(7, 1), -run.frames[7].dl_dq(1, 1) * out(run.frames[7], 1).tendon_force, 1e-9);

  // Actuation: the muscles' tendon force, lengthening speed and -F ldot; the CoordinateActuator
  // has no controller: force 0, its coordinate's speed
  const Storage af = readStorage(dir.file("Results/arm_Actuation_force.sto"));
  const Storage as = readStorage(dir.file("Results/arm_Actuation_speed.sto"));
  const Storage ap = readStorage(dir.file("Results/arm_Actuation_power.sto"));
  ASSERT_EQ(af.labels, (std::vector<std::string>{"bi", "tri", "sh_reserve"}));
  for (int r : {0, 20, 50}) {
    const MuscleFrame& f = run.frames[static_cast<size_t>(r)];
    EXPECT_NEAR(af.data(r, 0), out(f, 0).tendon_force, 1e-9);
    EXPECT_NEAR(as.data(r, 1), f.dl_dq.row(1).dot(f.u), 1e-12);
    EXPECT_NEAR(ap.data(r, 0), -out(f, 0).tendon_force * f.speed[0], 1e-9);
    EXPECT_EQ(af.data(r, 2), 0.0);
    EXPECT_NEAR(as.data(r, 2), f.u[0], 1e-12);
  }
  // step_interval: every 5th row, the first and the last
  s.setup_file = dir.write("step.xml", setupXml("<MuscleAnalysis name=\"MA\"><step_interval>5</step_interval>"
                                                "<moment_arm_coordinate_list>elbow_q nothere</moment_arm_coordinate_list>"
                                                "<muscle_list>tri</muscle_list></MuscleAnalysis>\n",
                                                "<coordinates_file>q.mot</coordinates_file>"));
  const AnalyzeTool step(s);
  const MuscleAnalysisRun sr = step.runMuscleAnalyses();
  EXPECT_EQ(sr.frames.size(), 11u);
  EXPECT_EQ(sr.columns.muscles, std::vector<std::string>{"tri"});
  EXPECT_EQ(sr.columns.coordinates, std::vector<std::string>{"elbow_q"});
  bool warned = false;
  for (const auto& w : step.warnings()) warned = warned || w.find("nothere") != std::string::npos;
  EXPECT_TRUE(warned);
}

// moment arms: -dl/dq of the evaluator against central differences of the path length it reports
TEST(MuscleAnalysis, MomentArmsAreMinusCentralDifferencesOfLength) {
  test::TempDir dir;
  const ModelDescription d = readOsimModel(dir.write("m.osim", armModel()));
  BuildOptions bo;
  bo.simbody_compat = true;
  bo.constraints = false;
  bo.muscles = true;
  const BuildResult b = buildCoreModel(d, bo);
  const MuscleFrameEvaluator eval(b.model.skeleton(), b.model);
  double worst = 0.0;
  for (double t : {0.1, 0.45, 0.8}) {
    MuscleFrameInput in;
    in.q = VecX(2);
    in.q << qShoulder(t), qElbow(t);
    in.u = VecX::Zero(2);
    const MuscleFrame f = eval.evaluate(in, false);
    for (int k = 0; k < 2; ++k) {
      const double h = 1e-6;
      MuscleFrameInput p = in, m = in;
      p.q[k] += h;
      m.q[k] -= h;
      const MuscleFrame fp = eval.evaluate(p, false), fm = eval.evaluate(m, false);
      for (int j = 0; j < 2; ++j) {
        const double cd = (fp.length[j] - fm.length[j]) / (2 * h);
        worst = std::max(worst, std::abs(f.dl_dq(j, k) - cd));
      }
    }
  }
  std::printf("[ measured ] max |dl/dq - central difference| %.3g m\n", worst);
  EXPECT_LE(worst, 1e-10);  // measured 2.9e-11 (round-off of the differences)
}

// equilibrium at rest: with u = 0 the equilibrated fibre does not move; without
// solve_for_equilibrium the fibre stays at its given length and does
TEST(MuscleAnalysis, StatesFileStatesAndEquilibriumAtRest) {
  test::TempDir dir;
  dir.write("m.osim", armModel());
  std::ostringstream st;
  st.precision(17);
  st << "states\nversion=1\nnRows=11\nnColumns=7\ninDegrees=no\nendheader\ntime\t/jointset/shoulder/shoulder_q/value"
        "\t/jointset/shoulder/shoulder_q/speed\t/jointset/elbow/elbow_q/value\t/jointset/elbow/elbow_q/speed"
        "\t/forceset/bi/activation\t/forceset/bi/fiber_length\n";
  for (int k = 0; k <= 10; ++k) {
    const double t = 0.1 * k;
    st << t << "\t" << qShoulder(t) << "\t0\t" << qElbow(t) << "\t0\t" << 0.2 + 0.5 * t << "\t" << 0.11 + 0.01 * t
       << "\n";
  }
  dir.write("states.sto", st.str());
  AnalyzeToolSettings s;
  s.setup_file = dir.write("eq.xml", setupXml(muscleAnalysisXml(), "<states_file>states.sto</states_file>"));
  const MuscleAnalysisRun eq = AnalyzeTool(s).runMuscleAnalyses();
  ASSERT_EQ(eq.frames.size(), 11u);
  expectIdentities(eq, {300, 200}, 2e-10, "states file, equilibrium");  // measured 4.6e-11
  double worst_v = 0.0;
  for (const MuscleFrame& f : eq.frames) {
    EXPECT_EQ(f.q[0], qShoulder(f.time));
    EXPECT_EQ(f.u[1], 0.0);
    EXPECT_EQ(out(f, 0).activation, 0.2 + 0.5 * f.time);  // the file's activation
    EXPECT_EQ(out(f, 1).activation, 0.2);                 // tri: its default_activation
    for (int m = 0; m < 2; ++m) worst_v = std::max(worst_v, std::abs(out(f, m).fiber_velocity));
  }
  std::printf("[ measured ] equilibrium at rest: max |fibre velocity| %.3g m/s\n", worst_v);
  EXPECT_LE(worst_v, 1e-8);  // measured 1.6e-9 m/s
  s.setup_file = dir.write("noeq.xml", setupXml(muscleAnalysisXml(), "<states_file>states.sto</states_file>", false));
  const MuscleAnalysisRun no = AnalyzeTool(s).runMuscleAnalyses();
  double moving = 0.0;
  for (const MuscleFrame& f : no.frames) {
    EXPECT_EQ(out(f, 0).fiber_length, 0.11 + 0.01 * f.time);  // the file's fibre length
    EXPECT_EQ(out(f, 1).fiber_length, 0.09);                  // tri: default_fiber_length
    moving = std::max(moving, std::abs(out(f, 0).fiber_velocity));
  }
  EXPECT_GT(moving, 1e-3);
}

// static optimization from a states file: q and u from the file's rows (not splined) give the
// coordinates file's optimum where the coordinates' spline derivative matches u
TEST(MuscleAnalysis, StaticOptimizationFromStatesFileMatchesCoordinates) {
  test::TempDir dir;
  dir.write("m.osim", armModel());
  dir.write("q.mot", armMotion());
  std::ostringstream st;
  st.precision(17);
  st << "states\nversion=1\nnRows=51\nnColumns=5\ninDegrees=no\nendheader\ntime\tshoulder_q\tshoulder_q_u\telbow_q"
        "\telbow_q_u\n";
  for (int k = 0; k <= 50; ++k) {
    const double t = 0.02 * k;
    st << t << "\t" << qShoulder(t) << "\t" << uShoulder(t) << "\t" << qElbow(t) << "\t" << uElbow(t) << "\n";
  }
  dir.write("states.sto", st.str());
  const std::string so =
      "<StaticOptimization name=\"StaticOptimization\"><use_muscle_physiology>false</use_muscle_physiology>"
      "</StaticOptimization>\n";
  AnalyzeToolSettings s;
  s.setup_file = dir.write("c.xml", setupXml(so, "<coordinates_file>q.mot</coordinates_file>", true, "m.osim", 0.2, 0.8));
  const StaticOptimizationRun rc = AnalyzeTool(s).runStaticOptimization();
  s.setup_file = dir.write("s.xml", setupXml(so, "<states_file>states.sto</states_file>", true, "m.osim", 0.2, 0.8));
  const StaticOptimizationRun rs = AnalyzeTool(s).runStaticOptimization();
  ASSERT_EQ(rc.failed, 0);
  ASSERT_EQ(rs.failed, 0);
  ASSERT_EQ(rc.frames.size(), rs.frames.size());
  double worst = 0.0;
  for (size_t k = 0; k < rc.frames.size(); ++k)
    worst = std::max(worst, (rc.frames[k].activation - rs.frames[k].activation).cwiseAbs().maxCoeff());
  std::printf("[ measured ] static optimization, states file vs coordinates file: max |da| %.3g\n", worst);
  EXPECT_LE(worst, 2e-6);  // measured 3.3e-7: the spline's u against the exact u
  EXPECT_GT(worst, 0.0);  // two different derivations of u: not the same computation
}

// OpenSim's testAnalyzeTool on Tug_of_War_Millard_Iso: at default activations 0.01 and 1 from the
// coordinates file, and with the ramp activation of the states file (minimum_activation 0), the
// activation is the one given, the tendon force equals the fibre force along the tendon within
// F_max SqrtEps, the fibre is at or above its minimum length and the force steps by less than F_max/10
TEST(MuscleAnalysis, TugOfWarMillardIsoAsOpenSimsTestAnalyzeTool) {
  REDMAX_REQUIRE_SHARED();
  const std::string res = test::sharedOpenSim("opensim-core/Applications/Analyze/tests/resources");
  std::ifstream in(res + "/Tug_of_War_Millard_Iso.osim");
  std::stringstream text;
  text << in.rdbuf();
  const std::string model = text.str();
  struct Case {
    const char* data;
    double default_activation;
    bool ramp;
  };
  for (const Case& c : {Case{"Tug_of_War_ConstantVelocity.sto", 0.01, false},
                        Case{"Tug_of_War_ConstantVelocity.sto", 1.0, false},
                        Case{"Tug_of_War_ConstantVelocity_RampActivation.sto", 0.0, true}}) {
    test::TempDir dir;
    std::string m = model;
    auto set = [&](const std::string& tag, const std::string& value) {
      const size_t a = m.find("<" + tag + ">"), b = m.find("</" + tag + ">");
      ASSERT_NE(a, std::string::npos) << tag;
      m = m.substr(0, a) + "<" + tag + ">" + value + m.substr(b);
    };
    std::ostringstream da;
    da << c.default_activation;
    set("default_activation", da.str());
    if (c.ramp) set("minimum_activation", "0");
    dir.write("tow.osim", m);
    const std::string data = std::string(c.ramp ? "<states_file>" : "<coordinates_file>") + res + "/" + c.data +
                             (c.ramp ? "</states_file>" : "</coordinates_file>");
    AnalyzeToolSettings s;
    s.setup_file = dir.write("setup.xml", setupXml(muscleAnalysisXml(), data, true, "tow.osim"));
    const AnalyzeTool tool(s);
    const MuscleAnalysisRun run = tool.runMuscleAnalyses();
    ASSERT_EQ(run.frames.size(), 101u) << c.data;
    const int k = 0;  // LeftMuscle
    ASSERT_EQ(run.columns.muscles[0], "LeftMuscle");
    const double fmax = 1000.0;  // the file's max_isometric_force
    const BuildResult b = buildCoreModel(readOsimModel(dir.file("tow.osim")));
    const auto* mus = dynamic_cast<const hill::Millard2012EquilibriumMuscle*>(b.model.muscleModels()[0].get());
    ASSERT_NE(mus, nullptr);
    double worst = 0.0, prev = -1.0;
    for (const MuscleFrame& f : run.frames) {
      const hill::MuscleOutput& o = out(f, run.columns.muscle_index[k]);
      if (c.ramp) EXPECT_NEAR(o.activation, f.time, 1e-15) << f.time;
      else EXPECT_EQ(o.activation, c.default_activation);
      const double along = (o.active_fiber_force + o.passive_fiber_force) * std::cos(o.pennation_angle);
      worst = std::max(worst, std::abs(o.tendon_force - along));
      EXPECT_GE(o.fiber_length, mus->minFiberLength()) << f.time;
      if (prev >= 0) EXPECT_LT(std::abs(o.tendon_force - prev), fmax / 10) << f.time;
      prev = o.tendon_force;
    }
    std::printf("[ measured ] Tug_of_War_Millard_Iso %s a = %g: max |F_T - F_M,AT| %.3g N\n", c.data,
                c.default_activation, worst);
    EXPECT_LE(worst, fmax * 1.4901161193847656e-8);  // OpenSim's tolerance
    EXPECT_LE(worst, 5e-7);  // measured 8.1e-8 .. 1.0e-7 N
    EXPECT_TRUE(run.failures.empty());
  }
}

// arm26 (wrapping over cylinders and ellipsoids) read as Millard2012EquilibriumMuscle: the same
// identities at every frame of OpenSim's static-optimization trial
TEST(MuscleAnalysis, Arm26Identities) {
  REDMAX_REQUIRE_SHARED();
  const std::string res = test::sharedOpenSim("opensim-core/Applications/Analyze/tests/resources");
  test::TempDir dir;
  AnalyzeToolSettings s;
  s.setup_file = dir.write("setup.xml", setupXml(muscleAnalysisXml(),
                                                 "<coordinates_file>" + res + "/arm26_InverseKinematics.mot</coordinates_file>"
                                                 "<lowpass_cutoff_frequency_for_coordinates>6</lowpass_cutoff_frequency_for_coordinates>",
                                                 true, res + "/arm26.osim", 0.25, 0.75));
  s.muscle_class = "Millard2012EquilibriumMuscle";
  const AnalyzeTool tool(s);
  const MuscleAnalysisRun run = tool.runMuscleAnalyses();
  EXPECT_EQ(run.frames.size(), 61u);
  ASSERT_EQ(run.columns.muscles.size(), 6u);
  // arm26's max isometric forces, TRIlong .. BRA
  expectIdentities(run, {798.52, 624.3, 624.3, 624.3, 435.56, 987.26}, 5e-10, "arm26 Millard");  // measured 9.6e-11
  EXPECT_TRUE(run.failures.empty());
}


// bad input: a coordinates file without a coordinate static optimization must drive is an error
// at the file's column-label line; an analysis OpenSim does not have is an error at its line
TEST(MuscleAnalysis, BadInputNamesFileAndLine) {
  test::TempDir dir;
  dir.write("m.osim", armModel());
  std::ostringstream mot;
  mot << "Coordinates\nversion=1\nnRows=11\nnColumns=2\ninDegrees=no\nendheader\ntime\tshoulder_q\n";
  for (int k = 0; k <= 10; ++k) mot << 0.1 * k << "\t" << qShoulder(0.1 * k) << "\n";
  dir.write("q.mot", mot.str());
  AnalyzeToolSettings s;
  s.setup_file = dir.write("so.xml", setupXml("<StaticOptimization name=\"so\"/>\n", "<coordinates_file>q.mot</coordinates_file>"));
  try {
    AnalyzeTool t(s);
    ADD_FAILURE() << "a missing coordinate was accepted";
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.line(), 7);
    EXPECT_NE(std::string(e.what()).find("q.mot:7: no column for coordinate(s) elbow_q"), std::string::npos) << e.what();
  }
  // MuscleAnalysis alone holds a missing coordinate at its default, as OpenSim does (warned)
  s.setup_file = dir.write("ma.xml", setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>"));
  const AnalyzeTool ma(s);
  EXPECT_EQ(ma.runMuscleAnalyses().frames.front().q[1], 0.4);
  s.setup_file = dir.write("typo.xml", setupXml("<MuscleAnalysys name=\"x\"/>\n", "<coordinates_file>q.mot</coordinates_file>"));
  try {
    AnalyzeTool t(s);
    ADD_FAILURE() << "an unknown analysis was accepted";
  } catch (const ConvertError& e) {
    EXPECT_NE(std::string(e.what()).find("typo.xml:4: unknown analysis <MuscleAnalysys>"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace redmax::osim
