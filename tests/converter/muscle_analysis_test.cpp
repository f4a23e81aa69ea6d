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
std::string armModel(const std::string& extra_forces = "") {
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
      "</CoordinateActuator>\n" + extra_forces +
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
  // MomentArm / Moment per coordinate, 18 quantities, then Actuation's three
  ASSERT_EQ(files.size(), 4u + 18u + 3u);
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

// every frame of a run, as the tables take them
std::vector<const MuscleFrame*> framesOf(const MuscleAnalysisRun& run) {
  std::vector<const MuscleFrame*> f;
  for (const MuscleFrame& x : run.frames) f.push_back(&x);
  return f;
}

// the column of table `name` for muscle column c
std::vector<double> column(const std::vector<Storage>& tables, const std::string& name, int c) {
  for (const Storage& t : tables)
    if (t.name == name) return std::vector<double>(t.data.col(c).data(), t.data.col(c).data() + t.data.rows());
  ADD_FAILURE() << "no table " << name;
  return {};
}

// FiberActivePower and FiberPassivePower (OpenSim's MuscleDynamicsInfo): the power balance
// OpenSim's testMuscles checks, d/dt(tendon PE + fibre PE - fibre work - boundary work) = 0, i.e.
// FiberActivePower + FiberPassivePower + TendonPower = MuscleActuatorPower, at every frame of a
// moving arm (Millard with fibre damping 0.1, Thelen); the passive power against the classes'
// closed-form elastic curves (Thelen's exponential, Millard's fibre force-length curve) and the
// Millard damping force beta F_max v_N counted in the active power
TEST(MuscleAnalysis, FibrePowersBalanceTheMusculotendonPower) {
  test::TempDir dir;
  dir.write("m.osim", armModel());
  dir.write("q.mot", armMotion());
  AnalyzeToolSettings s;
  const BuildResult b = buildCoreModel(readOsimModel(dir.file("m.osim")));
  const auto* bi = dynamic_cast<const hill::Millard2012EquilibriumMuscle*>(b.model.muscleModels()[0].get());
  ASSERT_NE(bi, nullptr);
  // with equilibrium the tri's fibre is beyond its optimal length (passive power) and the bi's
  // fibre does not move; without, both fibres move at their default lengths (damping power)
  double damping_power = 0.0, thelen_passive = 0.0;
  for (const bool equilibrium : {true, false}) {
    s.setup_file = dir.write("setup.xml", setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>",
                                                   equilibrium));
    const AnalyzeTool tool(s);
    const MuscleAnalysisRun run = tool.runMuscleAnalyses();
    ASSERT_EQ(run.frames.size(), 51u);
    const std::vector<const MuscleFrame*> frames = framesOf(run);
    const auto tables = muscleAnalysisTables(tool.setup().muscle_analysis, run.columns, frames);
    for (int c = 0; c < 2; ++c) {
      const auto fap = column(tables, "FiberActivePower", c), fpp = column(tables, "FiberPassivePower", c);
      const auto tp = column(tables, "TendonPower", c), map = column(tables, "MuscleActuatorPower", c);
      double worst = 0.0, peak = 0.0, worst_passive = 0.0, worst_active = 0.0, peak_passive = 0.0;
      for (size_t r = 0; r < frames.size(); ++r) {
        const hill::MuscleOutput& o = out(*frames[r], run.columns.muscle_index[static_cast<size_t>(c)]);
        peak = std::max(peak, std::abs(map[r]));
        worst = std::max(worst, std::abs(fap[r] + fpp[r] + tp[r] - map[r]));
        // closed forms of the elastic passive force: Millard's fibre force-length curve; Thelen's
        // exponential with OpenSim's defaults KshapePassive 5, FmaxMuscleStrain 0.6
        const double lceN = o.fiber_length / (c == 0 ? 0.14 : 0.1), fmax = c == 0 ? 300.0 : 200.0;
        const double elastic =
            c == 0 ? fmax * bi->fiberForceLengthCurve().value(lceN)
                   : (lceN > 1 ? fmax * (std::exp(5.0 * (lceN - 1) / 0.6) - 1) / (std::exp(5.0) - 1) : 0.0);
        const double damping = c == 0 ? fmax * 0.1 * o.normalized_fiber_velocity : 0.0;  // Millard's beta 0.1
        worst_passive = std::max(worst_passive, std::abs(fpp[r] + elastic * o.fiber_velocity));
        worst_active = std::max(worst_active, std::abs(fap[r] + (o.active_fiber_force + damping) * o.fiber_velocity));
        peak_passive = std::max(peak_passive, std::abs(fpp[r]));
        if (c == 0) damping_power = std::max(damping_power, std::abs(damping * o.fiber_velocity));
      }
      if (c == 1) thelen_passive = std::max(thelen_passive, peak_passive);
      std::printf("[ measured ] %s, equilibrium %d: peak |MuscleActuatorPower| %.3g W, peak |FiberPassivePower| %.3g W, "
                  "max |FAP + FPP + TP - MAP| %.3g W, passive vs closed form %.3g W, active %.3g W\n",
                  run.columns.muscles[static_cast<size_t>(c)].c_str(), equilibrium ? 1 : 0, peak, peak_passive, worst,
                  worst_passive, worst_active);
      EXPECT_GT(peak, 0.1);  // the muscles do work: the balance is not 0 = 0
      // exact where the tendon force equals the fibre's along the tendon (equilibrium: measured
      // 3.3e-16 / 1.8e-16 of the peak); otherwise to the velocity solve's force tolerance
      // (measured: Millard 1.8e-9, Thelen 1.2e-12 of the peak)
      EXPECT_LE(worst, (equilibrium ? 2e-15 : 1e-8) * peak);
      EXPECT_LE(worst_passive, 1e-16 * peak);  // measured 2.8e-18 of the peak (tri), 0 (bi)
      EXPECT_LE(worst_active, 1e-16 * peak);   // measured 0
    }
  }
  std::printf("[ measured ] peak Millard damping power %.3g W, peak Thelen passive power %.3g W\n", damping_power,
              thelen_passive);
  EXPECT_GT(damping_power, 1e-3);   // the damping is in the active power, not the passive one
  EXPECT_GT(thelen_passive, 1e-3);  // the elastic closed form was exercised

  // as Thelen2003Muscle_Deprecated: OpenSim's ActivationFiberLengthMuscle_Deprecated leaves the
  // powers, the fibre force and the pennation angular velocity unset (nan in OpenSim's files)
  s.muscle_class = "Thelen2003Muscle_Deprecated";
  const AnalyzeTool dep(s);
  const MuscleAnalysisRun dr = dep.runMuscleAnalyses();
  const std::vector<const MuscleFrame*> df = framesOf(dr);
  const auto dt = muscleAnalysisTables(dep.setup().muscle_analysis, dr.columns, df);
  for (const char* q : {"FiberActivePower", "FiberPassivePower", "TendonPower", "MuscleActuatorPower", "FiberForce",
                        "PennationAngularVelocity"})
    EXPECT_TRUE(std::isnan(column(dt, q, 1)[5])) << q;
  for (const char* q : {"FiberLength", "TendonForce", "ActiveFiberForce", "PassiveFiberForce", "FiberVelocity"})
    EXPECT_TRUE(std::isfinite(column(dt, q, 1)[5])) << q;
}

// a RigidTendonMuscle across the elbow: no activation state, its activation is its control
const char* kRigid =
    "<RigidTendonMuscle name=\"rt\"><GeometryPath name=\"path\"><PathPointSet><objects>\n"
    "<PathPoint name=\"o\"><socket_parent_frame>/bodyset/upper</socket_parent_frame><location>0.02 -0.1 0</location></PathPoint>\n"
    "<PathPoint name=\"i\"><socket_parent_frame>/bodyset/lower</socket_parent_frame><location>0.02 -0.04 0</location></PathPoint>\n"
    "</objects></PathPointSet></GeometryPath><max_isometric_force>150</max_isometric_force>"
    "<optimal_fiber_length>0.12</optimal_fiber_length><tendon_slack_length>0.1</tendon_slack_length>"
    "</RigidTendonMuscle>\n";

// controls of the AnalyzeTool (AbstractTool's ControllerSet, the tool's own controls_file):
// ControlLinear interpolated (linear, and use_steps: the node that ends the interval), applied as
// the actuators' controls: the CoordinateActuator's Actuation force is control * optimal force,
// the RigidTendonMuscle's activation is its control; a muscle with an activation state keeps it
TEST(MuscleAnalysis, ControlsFileDrivesActuatorsAndExcitations) {
  test::TempDir dir;
  dir.write("m.osim", armModel(kRigid));
  dir.write("q.mot", armMotion());
  dir.write("c.xml", R"(<?xml version="1.0" encoding="UTF-8"?>
<OpenSimDocument Version="40000">
<ControlSet name="c"><objects>
  <ControlLinear name="sh_reserve.excitation">
    <x_nodes>
      <ControlLinearNode><t> 0 </t><value> 0.5 </value></ControlLinearNode>
      <ControlLinearNode><t> 1 </t><value> 1.5 </value></ControlLinearNode>
    </x_nodes>
  </ControlLinear>
  <ControlLinear name="rt.excitation">
    <use_steps> true </use_steps>
    <x_nodes>
      <ControlLinearNode><t> 0 </t><value> 0.1 </value></ControlLinearNode>
      <ControlLinearNode><t> 0.51 </t><value> 0.7 </value></ControlLinearNode>
      <ControlLinearNode><t> 1 </t><value> 0.4 </value></ControlLinearNode>
    </x_nodes>
  </ControlLinear>
  <ControlLinear name="tri.excitation">
    <x_nodes><ControlLinearNode><t> 0 </t><value> 0.9 </value></ControlLinearNode></x_nodes>
  </ControlLinear>
</objects></ControlSet>
</OpenSimDocument>
)");
  const std::string controller =
      "<ControllerSet name=\"Controllers\"><objects><ControlSetController name=\"c\"><controls_file>c.xml"
      "</controls_file></ControlSetController></objects></ControllerSet>";
  AnalyzeToolSettings s;
  s.setup_file = dir.write("setup.xml", setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>" + controller));
  const AnalyzeTool tool(s);
  const MuscleAnalysisRun run = tool.runMuscleAnalyses();
  ASSERT_EQ(run.frames.size(), 51u);
  ASSERT_EQ(run.actuators.size(), 4u);
  ASSERT_EQ(run.actuators[2].name, "sh_reserve");
  ASSERT_EQ(run.actuators[3].name, "rt");
  const std::vector<const MuscleFrame*> frames = framesOf(run);
  const auto act = actuationTables(run.actuators, frames);
  const int rt = 2;  // geometry index of the RigidTendonMuscle
  for (size_t r = 0; r < frames.size(); ++r) {
    const MuscleFrame& f = *frames[r];
    const double t = f.time;
    EXPECT_NEAR(act[0].data(static_cast<Eigen::Index>(r), 2), 10.0 * (0.5 + t), 1e-12) << t;  // optimal force 10
    EXPECT_NEAR(act[2].data(static_cast<Eigen::Index>(r), 2), 10.0 * (0.5 + t) * f.u[0], 1e-12) << t;
    // use_steps: a node holds the value of the interval that ends at it
    const double step = t <= 0.0 ? 0.1 : (t <= 0.51 ? 0.7 : 0.4);
    EXPECT_EQ(out(f, rt).activation, step) << t;
    EXPECT_EQ(out(f, 1).activation, 0.2) << t;  // tri: its activation state, not the control
    // RigidTendonMuscle's powers (OpenSim's calcMuscleDynamicsInfo): -F v with v = ldot, tendon 0
    EXPECT_NEAR(fiberActivePower(out(f, rt)), -out(f, rt).active_fiber_force * f.speed[rt], 1e-12);
    EXPECT_GT(out(f, rt).active_fiber_force, 0.0);
  }
  EXPECT_EQ(column(muscleAnalysisTables(tool.setup().muscle_analysis, run.columns, frames), "TendonPower", 2)[7], 0.0);

  // the same controls as an OpenSim 3 tool-level controls_file in .sto form: linear between rows
  std::ostringstream sto;
  sto << "controls\nversion=1\nnRows=3\nnColumns=3\ninDegrees=no\nendheader\ntime\tsh_reserve\trt.excitation\n"
      << "0\t0.5\t0.1\n0.5\t1.5\t0.7\n1\t0.5\t0.4\n";
  dir.write("c.sto", sto.str());
  // OpenSim reads a tool's own controls_file only in documents older than version 10904
  auto old_document = [](std::string xml) {
    const std::string v = "Version=\"40000\"";
    return xml.replace(xml.find(v), v.size(), "Version=\"10900\"");
  };
  s.setup_file = dir.write("sto.xml", old_document(setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>"
                                                                                  "<controls_file>c.sto</controls_file>")));
  const AnalyzeTool st(s);
  bool warned_tri = false;
  for (const auto& w : st.warnings()) warned_tri = warned_tri || w.find("no control for actuator 'tri'") != std::string::npos;
  EXPECT_TRUE(warned_tri);
  const MuscleAnalysisRun sr = st.runMuscleAnalyses();
  for (const MuscleFrame& f : sr.frames) {
    const double t = f.time;
    const double u = t <= 0.5 ? 0.5 + 2 * t : 1.5 - 2 * (t - 0.5);
    const double a = t <= 0.5 ? 0.1 + 1.2 * t : 0.7 - 0.6 * (t - 0.5);
    EXPECT_NEAR(f.controls[sr.actuators[2].control], u, 1e-12) << t;  // sh_reserve
    EXPECT_NEAR(out(f, rt).activation, a, 1e-12) << t;
  }

  // the same tool-level controls_file in a version-40000 document: ignored, as OpenSim ignores it,
  // and named (the controls are then zero)
  s.setup_file = dir.write("sto40000.xml", setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>"
                                                                         "<controls_file>c.sto</controls_file>"));
  const AnalyzeTool ignored(s);
  bool named = false;
  for (const auto& w : ignored.setup().warnings)
    named = named || (w.find("controls_file 'c.sto' is ignored") != std::string::npos &&
                      w.find("version 40000") != std::string::npos);
  EXPECT_TRUE(named);
  for (const MuscleFrame& f : ignored.runMuscleAnalyses().frames) EXPECT_EQ(f.controls[sr.actuators[2].control], 0.0);

  // malformed input: error at the file and line, nothing run
  dir.write("bad.xml", "<?xml version=\"1.0\"?>\n<ControlSet name=\"c\"><objects>\n<ControlLinear name=\"rt\">\n"
                       "<x_nodes><ControlLinearNode><t> 0 </t><value> x </value></ControlLinearNode></x_nodes>\n"
                       "</ControlLinear></objects></ControlSet>\n");
  s.setup_file = dir.write("bad_setup.xml", old_document(setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>"
                                                                                        "<controls_file>bad.xml</controls_file>")));
  try {
    AnalyzeTool bad(s);
    ADD_FAILURE() << "a malformed controls file was accepted";
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.file(), dir.file("bad.xml"));
    EXPECT_EQ(e.line(), 4) << e.what();
  }
  // a ControlSetController without a controls file: an error at its line of the setup
  s.setup_file = dir.write("nofile.xml", setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>\n"
                                                                       "<ControllerSet><objects>\n<ControlSetController "
                                                                       "name=\"c\"/></objects></ControllerSet>"));
  try {
    AnalyzeTool bad(s);
    ADD_FAILURE() << "a ControlSetController without controls_file was accepted";
  } catch (const ConvertError& e) {
    EXPECT_EQ(e.file(), s.setup_file);
    EXPECT_GT(e.line(), 0);
    EXPECT_NE(std::string(e.what()).find("has no controls_file"), std::string::npos) << e.what();
  }
}

// Actuation speeds of a PointActuator and a TorqueActuator as OpenSim's calcSpeed gives them:
// |v| of the station on the lower arm (closed form of the two-link chain: the station's velocity
// is the sum of the two joints' rotations about z) and the relative angular velocity of the two
// links about the global z axis (the elbow's speed); power = force * speed (ScalarActuator)
TEST(MuscleAnalysis, PointAndTorqueActuatorSpeedsAsOpenSim) {
  test::TempDir dir;
  dir.write("m.osim", armModel(
                          "<PointActuator name=\"px\"><body>lower</body><point>0.05 -0.2 0</point><direction>1 0 0"
                          "</direction><optimal_force>20</optimal_force></PointActuator>\n"
                          "<TorqueActuator name=\"tq\"><bodyA>/bodyset/lower</bodyA><bodyB>/bodyset/upper</bodyB>"
                          "<axis>0 0 2</axis><optimal_force>5</optimal_force></TorqueActuator>\n"));
  dir.write("q.mot", armMotion());
  dir.write("c.sto", "controls\nversion=1\nnRows=2\nnColumns=3\ninDegrees=no\nendheader\ntime\tpx\ttq\n"
                     "0\t1\t-1\n1\t1\t-1\n");
  AnalyzeToolSettings s;
  s.setup_file = dir.write("setup.xml", setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>"
                                                                      "<ControllerSet><objects><ControlSetController "
                                                                      "name=\"c\"><controls_file>c.sto</controls_file>"
                                                                      "</ControlSetController></objects></ControllerSet>"));
  const AnalyzeTool tool(s);
  for (const auto& w : tool.warnings()) EXPECT_EQ(w.find("speed and power nan"), std::string::npos) << w;
  const MuscleAnalysisRun run = tool.runMuscleAnalyses();
  ASSERT_EQ(run.actuators.size(), 5u);
  ASSERT_EQ(run.actuators[3].name, "px");
  ASSERT_EQ(run.actuators[4].name, "tq");
  const std::vector<const MuscleFrame*> frames = framesOf(run);
  const auto act = actuationTables(run.actuators, frames);
  double worst_p = 0.0, worst_t = 0.0;
  for (size_t r = 0; r < frames.size(); ++r) {
    const MuscleFrame& f = *frames[r];
    // planar chain about z: elbow at R(q1) (0, -0.3), the station at R(q1 + q2) (0.05, -0.2) from it
    const double q1 = f.q[0], q2 = f.q[1], w1 = f.u[0], w2 = f.u[1];
    auto perp = [](double a, double x, double y) {  // d/da of R(a) (x, y)
      return Eigen::Vector2d(-std::sin(a) * x - std::cos(a) * y, std::cos(a) * x - std::sin(a) * y);
    };
    const Eigen::Vector2d v = w1 * perp(q1, 0.0, -0.3) + (w1 + w2) * perp(q1 + q2, 0.05, -0.2);
    const Eigen::Index i = static_cast<Eigen::Index>(r);
    worst_p = std::max(worst_p, std::abs(act[1].data(i, 3) - v.norm()));
    worst_t = std::max(worst_t, std::abs(act[1].data(i, 4) - w2));  // (omega_lower - omega_upper) . z
    EXPECT_EQ(act[0].data(i, 3), 20.0);
    EXPECT_EQ(act[0].data(i, 4), -5.0);
    EXPECT_NEAR(act[2].data(i, 3), 20.0 * act[1].data(i, 3), 1e-12);
    EXPECT_NEAR(act[2].data(i, 4), -5.0 * act[1].data(i, 4), 1e-12);
  }
  std::printf("[ measured ] PointActuator speed vs closed form %.3g m/s, TorqueActuator %.3g rad/s\n", worst_p,
              worst_t);
  EXPECT_LE(worst_p, 1e-14);
  EXPECT_LE(worst_t, 1e-14);
}

// MuscleAnalysis's moment arms with a coupler (elbow_q = 0.5 shoulder_q + 0.1), as OpenSim's
// MomentArmSolver computes them: the coupled coordinate moves along, so the moment arm about
// either coordinate is minus the derivative of the path length along the constraint; against
// central differences of the length along the coupler
TEST(MuscleAnalysis, CoupledCoordinatesMomentArmsFollowTheConstraint) {
  test::TempDir dir;
  std::string model = armModel();
  const size_t at = model.find("</Model>");
  ASSERT_NE(at, std::string::npos);
  model.insert(at,
               "<ConstraintSet><objects>\n<CoordinateCouplerConstraint name=\"cc\">\n"
               "<coupled_coordinates_function><LinearFunction><coefficients>0.5 0.1</coefficients>"
               "</LinearFunction></coupled_coordinates_function>\n"
               "<independent_coordinate_names>shoulder_q</independent_coordinate_names>\n"
               "<dependent_coordinate_name>elbow_q</dependent_coordinate_name>\n"
               "</CoordinateCouplerConstraint>\n</objects></ConstraintSet>\n");
  dir.write("m.osim", model);
  std::ostringstream os;
  os.precision(17);
  os << "Coordinates\nversion=1\nnRows=21\nnColumns=3\ninDegrees=no\nendheader\ntime\tshoulder_q\telbow_q\n";
  for (int k = 0; k <= 20; ++k) {
    const double t = 0.05 * k;
    os << t << "\t" << qShoulder(t) << "\t" << 0.5 * qShoulder(t) + 0.1 << "\n";
  }
  dir.write("q.mot", os.str());
  AnalyzeToolSettings s;
  s.setup_file = dir.write("setup.xml", setupXml(muscleAnalysisXml(), "<coordinates_file>q.mot</coordinates_file>"));
  const AnalyzeTool tool(s);
  const MuscleAnalysisRun run = tool.runMuscleAnalyses();
  ASSERT_EQ(run.frames.size(), 21u);
  const std::vector<const MuscleFrame*> frames = framesOf(run);
  const auto tables = muscleAnalysisTables(tool.setup().muscle_analysis, run.columns, frames);

  BuildOptions bo;
  bo.simbody_compat = true;
  bo.constraints = false;
  const BuildResult b = buildCoreModel(readOsimModel(dir.file("m.osim")), bo);
  const MuscleFrameEvaluator eval(b.model.skeleton(), b.model);
  auto length = [&](double qs, double qe, int m) {
    MuscleFrameInput in;
    in.q = VecX(2);
    in.q << qs, qe;
    in.u = VecX::Zero(2);
    return eval.evaluate(in, false).length[m];
  };
  double worst = 0.0, coupling_effect = 0.0;
  const double h = 1e-5;
  for (int c = 0; c < 2; ++c) {
    const auto ms = column(tables, "MomentArm_shoulder_q", c), me = column(tables, "MomentArm_elbow_q", c);
    for (size_t r = 0; r < frames.size(); r += 4) {
      const MuscleFrame& f = *frames[r];
      const double qs = f.q[0], qe = f.q[1];
      // along the coupler: d(shoulder) = 1, d(elbow) = 0.5; per unit elbow: 2 and 1
      const double cs = -(length(qs + h, qe + 0.5 * h, c) - length(qs - h, qe - 0.5 * h, c)) / (2 * h);
      const double ce = -(length(qs + 2 * h, qe + h, c) - length(qs - 2 * h, qe - h, c)) / (2 * h);
      worst = std::max({worst, std::abs(ms[r] - cs), std::abs(me[r] - ce)});
      coupling_effect = std::max(coupling_effect, std::abs(ms[r] + f.dl_dq(c, 0)));
    }
  }
  std::printf("[ measured ] coupled moment arms vs central differences along the coupler %.3g m; "
              "coupling changes the shoulder moment arm by up to %.3g m\n",
              worst, coupling_effect);
  EXPECT_LE(worst, 1e-9);
  EXPECT_GT(coupling_effect, 1e-3);  // the tri spans the elbow only: its shoulder moment arm comes from the coupler
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
