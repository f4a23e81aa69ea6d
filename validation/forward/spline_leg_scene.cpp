#include "validation/forward/spline_leg_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "converter/atomic_file.hpp"
#include "converter/model_edit.hpp"
#include "converter/osim_reader.hpp"
#include "core/dynamics/muscle_force_term.hpp"
#include "validation/report/plot.hpp"

namespace redmax::validation {
namespace {
namespace fs = std::filesystem;

constexpr const char* kKnee = "knee_r";
constexpr const char* kKneeCoord = "knee_angle_r";
constexpr const char* kAnkleCoord = "ankle_angle_r";

// the hand-set excitations (PrescribedController): gastrocnemii low and constant, the rectus
// femoris ramps up and holds (the knee extends), then lets go while the semimembranosus ramps up
// (the knee flexes)
std::string setupXml(const std::string& name, const std::string& model, double t1, double tol) {
  std::ostringstream f;
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenSimDocument Version=\"40000\">\n"
    << "<ForwardTool name=\"" << name << "\">\n<model_file>" << model << "</model_file>\n"
    << "<initial_time>0</initial_time>\n<final_time>" << t1 << "</final_time>\n"
    << "<solve_for_equilibrium_for_auxiliary_states>true</solve_for_equilibrium_for_auxiliary_states>\n"
    << "<maximum_number_of_integrator_steps>200000</maximum_number_of_integrator_steps>\n"
    << "<integrator_error_tolerance>" << tol << "</integrator_error_tolerance>\n"
    << "<ControllerSet><objects><PrescribedController name=\"by_hand\">\n<FunctionSet><objects>\n"
    << "<Constant name=\"med_gas_r\"><value>0.05</value></Constant>\n"
    << "<Constant name=\"lat_gas_r\"><value>0.05</value></Constant>\n"
    << "<PiecewiseLinearFunction name=\"rect_fem_r\"><x>0 0.1 0.25 0.5 0.6</x>"
    << "<y>0.02 0.02 1 1 0.02</y></PiecewiseLinearFunction>\n"
    << "<PiecewiseLinearFunction name=\"semimem_r\"><x>0 0.6 0.75 10</x>"
    << "<y>0.02 0.02 0.2 0.2</y></PiecewiseLinearFunction>\n"
    << "</objects></FunctionSet>\n</PrescribedController></objects></ControllerSet>\n"
    << "</ForwardTool>\n</OpenSimDocument>\n";
  return f.str();
}

// soleus and tibialis anterior hold the ankle near neutral: each is excited when the ankle
// turns the way it opposes (dorsiflexion positive; the soleus plantarflexes)
std::vector<FeedbackRule> ankleController() {
  FeedbackRule sol{"soleus_r", kAnkleCoord, 0.0, -2.0, -0.05, 0.05, 0.01, 1.0};
  FeedbackRule ta{"tib_ant_r", kAnkleCoord, 0.0, 2.0, 0.05, 0.05, 0.01, 1.0};
  return {sol, ta};
}

const MuscleForceTerm* muscleForceTerm(const System& sys) {
  for (const auto& t : sys.terms())
    if (const auto* m = dynamic_cast<const MuscleForceTerm*>(t.get())) return m;
  return nullptr;
}

double maxAbsDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0.0;
  for (size_t k = 0; k < std::min(a.size(), b.size()); ++k) m = std::max(m, std::abs(a[k] - b[k]));
  return m;
}

SplineLegRun runOne(const std::string& name, bool spline, bool inertial, const std::string& setup,
                    const SplineLegOptions& o) {
  ForwardToolSettings s;
  s.setup_file = setup;
  s.out_dir = o.out_dir;
  s.report_interval = o.report_interval;
  s.feedback = ankleController();
  s.strict = true;  // every force of the model must act
  if (inertial) {
    s.muscle_mass.source = osim::MuscleMassOptions::Source::Physiological;
    s.muscle_mass.placement = osim::MuscleMassOptions::Placement::Fibre;
    s.muscle_mass.wrap_mass = true;  // the Type III rectus femoris and gastrocnemii carry mass too
  }
  const ForwardTool tool(s);
  SplineLegRun r;
  r.name = name;
  r.spline = spline;
  r.inertial = inertial;
  r.muscle_mass = tool.model().muscle_mass;
  r.result = tool.run();
  if (r.result.failed) throw std::runtime_error("spline-leg run " + name + " failed: " + r.result.failure);
  tool.write(r.result);
  const osim::Storage& st = r.result.states;
  const int cq = st.findColumn(std::string("/jointset/") + kKnee + "/" + kKneeCoord + "/value");
  const int ca = st.findColumn(std::string("/jointset/ankle_r/") + kAnkleCoord + "/value");
  if (cq < 0 || ca < 0) throw std::runtime_error("spline-leg: the states lack the knee or ankle angle");
  const System& sys = tool.system();
  const MuscleForceTerm* mft = muscleForceTerm(sys);
  if (!mft) throw std::runtime_error("spline-leg: the model has no Hill-type muscles");
  for (const auto& a : mft->actuated()) r.muscles.push_back(a.muscle.name);
  const size_t nm = r.muscles.size();
  r.tendon_force.assign(nm, {});
  r.fiber_length.assign(nm, {});
  DynamicsWorkspace ws(sys);
  for (int k = 0; k < st.numRows(); ++k) {
    r.knee.push_back(st.data(k, cq));
    r.ankle.push_back(st.data(k, ca));
    State x = forwardInitialState(tool.model(), st, tool.statesPath(), st.time[k]);
    sys.calcMassAndForce(x, ws);  // the paths at x
    for (size_t m = 0; m < nm; ++m) {
      const hill::MuscleOutput out =
          mft->calcOutput(sys.model(), x, TermContext(ws.sk, nullptr, 0), static_cast<int>(m));
      r.tendon_force[m].push_back(out.tendon_force);
      r.fiber_length[m].push_back(out.fiber_length);
    }
  }
  // the muscles' forces and fibre lengths beside the states
  osim::Storage f;
  f.name = name + "_forces";
  f.time = st.time;
  f.data.resize(st.numRows(), 2 * static_cast<int>(nm));
  for (size_t m = 0; m < nm; ++m) {
    f.labels.push_back(r.muscles[m] + "_tendon_force");
    f.labels.push_back(r.muscles[m] + "_fiber_length");
    for (int k = 0; k < st.numRows(); ++k) {
      f.data(k, 2 * static_cast<int>(m)) = r.tendon_force[m][k];
      f.data(k, 2 * static_cast<int>(m) + 1) = r.fiber_length[m][k];
    }
  }
  osim::writeResultStorage((fs::path(o.out_dir) / (name + "_forces.sto")).string(), f, true,
                           "tendon force (N) and fibre length (m) of each muscle along " + name + "_states.sto");
  return r;
}

}  // namespace

std::string revoluteKneeModel(const std::string& model_path, const std::string& joint, double angle) {
  return osim::freezeJointTranslations(model_path, joint, angle);
}

SplineLegResult runSplineLegScene(const SplineLegOptions& o, std::ostream& out) {
  if (o.out_dir.empty()) throw std::invalid_argument("spline-leg: no output folder");
  SplineLegResult res;
  // the default knee angle (both knees start there); a bad model fails before anything is written
  const osim::ModelDescription d = osim::readOsimModel(o.model_path);
  double q0 = 0.0;
  bool found = false;
  for (const auto& c : d.coordinates)
    if (c.name == kKneeCoord) {
      q0 = c.default_value;
      found = true;
    }
  if (!found) throw osim::ConvertError(o.model_path, 0, std::string("no coordinate named '") + kKneeCoord + "'");
  const std::string revolute_xml = revoluteKneeModel(o.model_path, kKnee, q0);
  fs::create_directories(o.out_dir);
  const std::string revolute = (fs::path(o.out_dir) / "spline_leg_revolute_knee.osim").string();
  osim::writeFileAtomic(revolute, revolute_xml);
  res.files.push_back(revolute);
  const std::string model_abs = fs::absolute(o.model_path).string();
  for (const bool spline : {true, false}) {
    const std::string knee = spline ? "spline" : "revolute";
    const std::string setup = (fs::path(o.out_dir) / (knee + "_setup.xml")).string();
    res.files.push_back(setup);
    for (const bool inertial : {false, true}) {
      const std::string name = knee + (inertial ? "_inertial" : "_lumped");
      osim::writeFileAtomic(setup, setupXml(name, spline ? model_abs : fs::absolute(revolute).string(), o.duration, o.tolerance));
      out << "spline-leg: running " << name << " (" << o.duration << " s, rk45 " << o.tolerance << ")\n" << std::flush;
      res.runs.push_back(runOne(name, spline, inertial, setup, o));
      const SplineLegRun& r = res.runs.back();
      out << "  " << r.result.stats.steps << " steps, " << r.result.wall_s << " s wall\n" << std::flush;
      res.files.push_back((fs::path(o.out_dir) / (name + "_states.sto")).string());
      res.files.push_back((fs::path(o.out_dir) / (name + "_forces.sto")).string());
    }
  }
  // how far the revolute knee's fixed centre is from where the spline puts the tibia
  const osim::JointTranslation t(o.model_path, kKnee);
  for (const SplineLegRun& r : res.runs)
    if (r.spline)
      for (double q : r.knee) res.knee_centre_offset = std::max(res.knee_centre_offset, (t.at(q) - t.at(q0)).norm());

  // summary
  std::ostringstream s;
  char line[512];
  s << "spline-leg (dissertation 6.2.10): " << o.model_path << ", " << o.duration << " s, rk45 rtol = atol = "
    << o.tolerance << "\n";
  s << "run                 mass kg  steps  knee start  knee max  knee end  ankle min  ankle max  wall s\n";
  for (const SplineLegRun& r : res.runs) {
    const auto [amin, amax] = std::minmax_element(r.ankle.begin(), r.ankle.end());
    std::snprintf(line, sizeof line, "%-18s  %7.3f  %5ld  %10.4f  %8.4f  %8.4f  %9.4f  %9.4f  %6.2f\n", r.name.c_str(),
                  r.muscle_mass, r.result.stats.steps, r.knee.front(), *std::max_element(r.knee.begin(), r.knee.end()),
                  r.knee.back(), *amin, *amax, r.result.wall_s);
    s << line;
  }
  const SplineLegRun &sl = res.runs[0], &si = res.runs[1], &rl = res.runs[2], &ri = res.runs[3];
  std::snprintf(line, sizeof line,
                "muscle mass (inertial - lumped): knee up to %.4f rad (spline), %.4f rad (revolute); ankle up to "
                "%.4f rad (spline)\n",
                maxAbsDiff(si.knee, sl.knee), maxAbsDiff(ri.knee, rl.knee), maxAbsDiff(si.ankle, sl.ankle));
  s << line;
  std::snprintf(line, sizeof line,
                "knee joint (revolute - spline, lumped): knee up to %.4f rad; the revolute knee's fixed centre is up "
                "to %.2f mm from the spline's tibia origin over the knee angles visited\n",
                maxAbsDiff(rl.knee, sl.knee), 1e3 * res.knee_centre_offset);
  s << line;
  for (size_t m = 0; m < sl.muscles.size(); ++m) {
    const double peak_l = *std::max_element(sl.tendon_force[m].begin(), sl.tendon_force[m].end());
    const double peak_i = *std::max_element(si.tendon_force[m].begin(), si.tendon_force[m].end());
    std::snprintf(line, sizeof line, "  %-10s peak tendon force %8.2f N lumped, %8.2f N inertial (%+.2f%%)\n",
                  sl.muscles[m].c_str(), peak_l, peak_i, 100.0 * (peak_i - peak_l) / std::max(peak_l, 1e-12));
    s << line;
  }
  const std::string summary = (fs::path(o.out_dir) / "summary.txt").string();
  osim::writeFileAtomic(summary, s.str());
  res.files.push_back(summary);
  out << s.str();

  if (o.plots) {
    const GnuplotInfo gp = findGnuplot();
    if (!gp.available) {
      res.plot_notes.push_back("no plots: " + gp.why_not);
    } else {
      auto timeOf = [](const SplineLegRun& r) { return r.result.states.time; };
      auto panel = [&](const std::string& title, const std::string& ylabel, auto value) {
        std::vector<PlotLine> lines;
        for (const SplineLegRun& r : res.runs) {
          PlotLine l = makePlotLine(r.name, timeOf(r), value(r));
          l.dash_type = r.inertial ? 2 : 1;
          lines.push_back(l);
        }
        return makeXYPanel(title, "time (s)", ylabel, lines);
      };
      std::vector<std::pair<std::string, PlotFigure>> figs;
      PlotFigure angles;
      angles.title = "spline-leg: joint angles";
      angles.panels.push_back(panel("knee angle (extension +)", "rad", [](const SplineLegRun& r) { return r.knee; }));
      angles.panels.push_back(panel("ankle angle (dorsiflexion +)", "rad", [](const SplineLegRun& r) { return r.ankle; }));
      figs.emplace_back("joint_angles", angles);
      PlotFigure fibres, forces;
      fibres.title = "spline-leg: fibre lengths";
      forces.title = "spline-leg: tendon forces";
      for (size_t m = 0; m < sl.muscles.size(); ++m) {
        fibres.panels.push_back(panel(sl.muscles[m], "m", [m](const SplineLegRun& r) { return r.fiber_length[m]; }));
        forces.panels.push_back(panel(sl.muscles[m], "N", [m](const SplineLegRun& r) { return r.tendon_force[m]; }));
      }
      fibres.columns = forces.columns = 3;
      figs.emplace_back("fiber_lengths", fibres);
      figs.emplace_back("tendon_forces", forces);
      for (const auto& [stem, fig] : figs) {
        const PlotOutcome p = renderPlot(gp, PlotFormat::Auto, fig, (fs::path(o.out_dir) / stem).string());
        if (p.ok)
          res.files.push_back(p.file);
        else
          res.plot_notes.push_back(stem + ": " + p.error);
      }
    }
  }
  for (const std::string& n : res.plot_notes) out << "spline-leg: " << n << "\n";
  return res;
}

}  // namespace redmax::validation
