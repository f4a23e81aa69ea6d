#include "validation/work_precision/id_studies.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "converter/id/core_id_engine.hpp"
#include "validation/mass_sweep.hpp"

namespace redmax::validation {

namespace {

namespace fs = std::filesystem;
using Eigen::Index;

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string fmt(double x, const char* f = "%.3g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

// one output frame's inputs, computed once so that the timings see the engine only
struct Frame {
  double t = 0.0;
  VecX q, v, vdot;
  std::vector<osim::IdLoadSample> loads;
};

// every frame solved by the engine (tau, frames x columns) and the fastest repeat's CPU time per frame
double solveFrames(osim::IdEngine& engine, const std::vector<Frame>& frames, int ncol, double min_timing_s, MatX& tau) {
  tau.resize(static_cast<Index>(frames.size()), ncol);
  VecX row;
  double best = 1e300, total = 0.0;
  for (int rep = 0; rep < 5 && (rep == 0 || total < min_timing_s); ++rep) {
    const double c0 = threadCpuSeconds();
    for (size_t k = 0; k < frames.size(); ++k) {
      const Frame& f = frames[k];
      engine.calcGeneralizedForces(f.t, f.q, f.v, f.vdot, f.loads, row);
      if (rep == 0) tau.row(static_cast<Index>(k)) = row.transpose();
    }
    const double dt = threadCpuSeconds() - c0;
    best = std::min(best, dt);
    total += dt;
  }
  for (Index k = 0; k < tau.rows(); ++k)
    for (Index c = 0; c < tau.cols(); ++c)
      if (!std::isfinite(tau(k, c)))
        throw osim::IdEngineError("id study: non-finite generalized force at t = " + fmt(frames[k].t) + " s");
  return best / std::max<double>(1.0, static_cast<double>(frames.size()));
}

IdStudyRow solveRow(const MassSweepEngineFactory& factory, const osim::MuscleMassOptions& o, const std::string& label,
                    int value, const std::vector<Frame>& frames, int ncol, double min_timing_s) {
  IdStudyRow r;
  r.label = label;
  r.value = value;
  MassSweepEngine e = factory(o);
  r.muscle_mass = e.muscle_mass;
  r.muscles_with_mass = e.muscles_with_mass;
  if (e.model)
    for (const auto& m : e.model->muscles()) r.points_total += m.mass_points.size();
  r.cpu_per_frame_s = solveFrames(*e.engine, frames, ncol, min_timing_s, r.tau);
  return r;
}

bool hasStudy(const std::vector<std::string>& studies, const std::string& s) {
  return studies.empty() || std::find(studies.begin(), studies.end(), s) != studies.end();
}

}  // namespace

IdStudyTrial chooseIdStudyTrial(const IdStudyOptions& options) {
  IdStudyTrial t;
  const fs::path base = fs::path(options.shared_dir) / "opensim";
  const fs::path setup = base / "opensim-models/Pipelines/Gait10dof18musc/OutputReference/ID/walk_Setup_ID.xml";
  const fs::path model = base / "opensim-models@a26e12c/Pipelines/Gait10dof18musc/OutputReference/subject01.osim";
  const bool have_f = !options.shared_dir.empty() && fs::is_regular_file(setup) && fs::is_regular_file(model);
  if (have_f && !options.quick) {
    t.name = "set F";
    t.description = "set F of the shared OpenSim data: gait10dof18musc (subject01.osim @a26e12c, planar 10 DoF, 18 "
                    "Millard muscles), walking 0-2.5 s with ground reaction forces, 6 Hz lowpass (walk_Setup_ID.xml)";
    t.settings.setup_file = setup.string();
    t.settings.model_file = model.string();
    return t;
  }
  const fs::path leg = fs::path(options.models_dir) / "running_leg.osim";
  const fs::path mot = fs::path(options.models_dir) / "running_leg_swing.mot";
  if (!fs::is_regular_file(leg) || !fs::is_regular_file(mot))
    throw std::invalid_argument("id studies: " + options.models_dir + " has no running_leg.osim and running_leg_swing.mot");
  t.name = "running leg";
  t.description = "the project's running leg (osim_models/running_leg.osim, 11 DoF, free pelvis) over its synthetic "
                  "swing (running_leg_swing.mot), no external loads, no filter";
  t.fallback = !options.quick;
  t.note = options.quick ? "quick mode uses the running leg"
                         : "the shared data (" + setup.string() + ") was not found, so the running leg stands in for set F";
  t.settings.model_file = leg.string();
  t.settings.coordinates_file = mot.string();
  return t;
}

IdStudyError calcIdStudyError(const MatX& tau, const MatX& tau_ref, const MatX& tau_0,
                              const std::vector<std::string>& labels) {
  if (tau.rows() != tau_ref.rows() || tau.cols() != tau_ref.cols() || tau_0.rows() != tau_ref.rows() ||
      tau_0.cols() != tau_ref.cols() || static_cast<Index>(labels.size()) != tau_ref.cols())
    throw std::invalid_argument("calcIdStudyError: tables of different shapes");
  IdStudyError e;
  for (Index c = 0; c < tau_ref.cols(); ++c) {
    const double diff = (tau.col(c) - tau_ref.col(c)).cwiseAbs().maxCoeff();
    const double peak = tau_ref.col(c).cwiseAbs().maxCoeff();
    const double effect = (tau_ref.col(c) - tau_0.col(c)).cwiseAbs().maxCoeff();
    if (peak > 0.0) e.err_peak = std::max(e.err_peak, diff / peak);
    else if (diff > 0.0) e.err_peak = std::max(e.err_peak, diff);
    // a column without an inertial effect has nothing to be relative to
    if (effect > 1e-12 * (peak + 1.0) && diff / effect >= e.err_effect) {
      e.err_effect = diff / effect;
      e.worst_column = labels[static_cast<size_t>(c)];
    }
  }
  return e;
}

IdStudiesResult runIdStudies(const IdStudyOptions& options, const std::vector<std::string>& studies,
                             std::ostream* progress) {
  for (const auto& s : studies)
    if (s != "masspoints" && s != "reduction")
      throw std::invalid_argument("unknown id study '" + s + "' (expected masspoints, reduction)");
  IdStudiesResult r;
  r.trial = chooseIdStudyTrial(options);
  r.target = options.target;

  // the trial processed once (splines, filter, loads); every run solves the same frames
  const osim::InverseDynamicsTool tool(osim::resolveIdSettings(r.trial.settings));
  r.labels = tool.outputLabels();
  r.frames = tool.numFrames();
  r.ndof = static_cast<int>(tool.model().nr());
  const int ncol = static_cast<int>(r.labels.size());
  std::vector<Frame> frames(static_cast<size_t>(r.frames));
  for (int k = 0; k < r.frames; ++k) {
    Frame& f = frames[static_cast<size_t>(k)];
    f.t = tool.frameTime(k);
    tool.calcInputs(f.t, f.q, f.v, f.vdot, f.loads);
  }
  {
    osim::CoreIdEngine zero(tool.model(), tool.engineOptions());
    r.cpu_per_frame_zero_s = solveFrames(zero, frames, ncol, options.min_timing_s, r.tau_0);
  }
  if (progress)
    *progress << "id studies: " << r.trial.name << " (" << r.frames << " frames, " << r.ndof << " DoF)"
              << (r.trial.note.empty() ? "" : "; " + r.trial.note) << std::endl;

  const MassSweepEngineFactory factory = makeCoreMassEngineFactory(tool);
  osim::MuscleMassOptions base;
  base.source = osim::MuscleMassOptions::Source::Physiological;

  if (hasStudy(studies, "masspoints")) {
    r.has_masspoints = true;
    std::vector<int> ns = options.mass_points;
    if (options.quick && ns == IdStudyOptions{}.mass_points) ns = {2, 5, 10, 20, 50};
    osim::MuscleMassOptions o = base;
    o.mass_points = options.reference_points;
    r.reference = solveRow(factory, o, std::to_string(options.reference_points), options.reference_points, frames, ncol,
                           options.min_timing_s);
    r.reference.error = calcIdStudyError(r.reference.tau, r.reference.tau, r.tau_0, r.labels);
    for (int n : ns) {
      o.mass_points = n;
      IdStudyRow row = solveRow(factory, o, std::to_string(n), n, frames, ncol, options.min_timing_s);
      row.error = calcIdStudyError(row.tau, r.reference.tau, r.tau_0, r.labels);
      if (progress)
        *progress << "  mass points N = " << n << ": error " << fmt(row.error.err_effect, "%.2e")
                  << " of the inertial effect, " << fmt(1e6 * row.cpu_per_frame_s) << " us/frame" << std::endl;
      if (r.recommended_points < 0 && row.error.err_effect < options.target) r.recommended_points = n;
      r.masspoints.push_back(std::move(row));
    }
  }

  if (hasStudy(studies, "reduction")) {
    r.has_reduction = true;
    // the ranking: every candidate muscle by its inertia share over the trial's poses
    std::vector<VecX> samples;
    for (int k = 0; k < r.frames; k += std::max(1, r.frames / 100)) samples.push_back(frames[static_cast<size_t>(k)].q);
    osim::BuildOptions bo;
    bo.simbody_compat = tool.config().opensim_compat;
    bo.constraints = false;
    osim::MuscleMassOptions o = base;
    o.muscles = "top:1";
    r.ranking = osim::applyMuscleMass(tool.description(), bo, o, samples).plan.ranking;
    const int ncand = static_cast<int>(r.ranking.size());

    o.muscles = "all";
    r.all_muscles = solveRow(factory, o, "all", ncand, frames, ncol, options.min_timing_s);
    r.all_muscles.error = calcIdStudyError(r.all_muscles.tau, r.all_muscles.tau, r.tau_0, r.labels);
    std::vector<int> ks;
    for (int k : options.top_k)
      if (k >= 0 && k < ncand && std::find(ks.begin(), ks.end(), k) == ks.end()) ks.push_back(k);
    std::sort(ks.begin(), ks.end());
    ks.push_back(ncand);
    for (int k : ks) {
      // K = 0 is the model without muscle mass (top:K needs K >= 1)
      osim::MuscleMassOptions ok = base;
      if (k == 0) ok.source = osim::MuscleMassOptions::Source::None;
      else ok.muscles = "top:" + std::to_string(k);
      IdStudyRow row = solveRow(factory, ok, k == ncand ? "all" : std::to_string(k), k, frames, ncol,
                                options.min_timing_s);
      row.error = calcIdStudyError(row.tau, r.all_muscles.tau, r.tau_0, r.labels);
      if (progress)
        *progress << "  top " << row.label << " muscles with mass: error " << fmt(row.error.err_effect, "%.2e")
                  << " of the inertial effect, " << fmt(1e6 * row.cpu_per_frame_s) << " us/frame" << std::endl;
      r.reduction.push_back(std::move(row));
    }
  }
  return r;
}

void addIdStudiesToReport(const IdStudiesResult& r, Report& report) {
  JsonValue& js = report.section("id_studies");
  js["trial"] = JsonValue(r.trial.name);
  js["trial_description"] = JsonValue(r.trial.description);
  if (!r.trial.note.empty()) js["trial_note"] = JsonValue(r.trial.note);
  js["frames"] = JsonValue(r.frames);
  js["ndof"] = JsonValue(r.ndof);
  js["cpu_per_frame_zero_mass_s"] = JsonValue(r.cpu_per_frame_zero_s);
  const std::string trial_md = "Trial: " + r.trial.description + "; " + std::to_string(r.frames) + " frames, " +
                               std::to_string(r.ndof) + " DoF" + (r.trial.note.empty() ? "" : " (" + r.trial.note + ")") +
                               ". Physiological muscle mass (60 N/cm^2, 1059.7 kg/m^3) taken from the bones. Error "
                               "relative to the inertial effect: max over columns of max_k |tau - tau_ref| / "
                               "max_k |tau_ref - tau_0| (tau_0 without muscle mass); relative to the peak: max over "
                               "columns of max_k |tau - tau_ref| / max_k |tau_ref|. CPU time per frame of the core "
                               "engine alone (inputs precomputed), fastest repeat; without muscle mass " +
                               fmt(1e6 * r.cpu_per_frame_zero_s) + " us/frame.";

  auto rowJson = [](const IdStudyRow& row) {
    JsonValue o = JsonValue::object();
    o["label"] = JsonValue(row.label);
    o["value"] = JsonValue(row.value);
    o["muscles_with_mass"] = JsonValue(row.muscles_with_mass);
    o["mass_points_total"] = JsonValue(row.points_total);
    o["muscle_mass_kg"] = JsonValue(row.muscle_mass);
    o["error_rel_effect"] = JsonValue(row.error.err_effect);
    o["error_rel_peak"] = JsonValue(row.error.err_peak);
    o["worst_column"] = JsonValue(row.error.worst_column);
    o["cpu_per_frame_s"] = JsonValue(row.cpu_per_frame_s);
    return o;
  };
  auto csvRow = [](const IdStudyRow& row) -> std::vector<std::string> {
    return {row.label, std::to_string(row.muscles_with_mass), std::to_string(row.points_total),
            formatNumber(row.muscle_mass), formatNumber(row.error.err_effect), formatNumber(row.error.err_peak),
            row.error.worst_column, formatNumber(row.cpu_per_frame_s)};
  };
  const std::vector<std::string> tail = {"muscles_with_mass", "mass_points_total", "muscle_mass_kg",
                                         "error_rel_effect", "error_rel_peak", "worst_column", "cpu_per_frame_s"};

  if (r.has_masspoints) {
    CsvTable t;
    t.header = {"points_per_muscle"};
    t.header.insert(t.header.end(), tail.begin(), tail.end());
    for (const auto& row : r.masspoints) t.addRow(csvRow(row));
    t.addRow(csvRow(r.reference));
    report.addTable("id_masspoints", t, "ID torque error against " + r.reference.label + " points per muscle, per N");

    std::vector<double> x, ye, yp, yc;
    for (const auto& row : r.masspoints) {
      x.push_back(row.value);
      ye.push_back(std::max(row.error.err_effect, 1e-16));
      yp.push_back(std::max(row.error.err_peak, 1e-16));
      yc.push_back(std::max(row.cpu_per_frame_s, 1e-9));
    }
    PlotFigure fig;
    fig.title = "id_masspoints";
    fig.panel_width = 560;
    fig.panel_height = 420;
    fig.panels.push_back(makeLogLogPanel(r.trial.name + ": ID error vs mass points per muscle", "points per muscle N",
                                         "error vs " + r.reference.label + " points",
                                         {makePlotLine("rel. to inertial effect", x, ye, "linespoints"),
                                          makePlotLine("rel. to torque peak", x, yp, "linespoints")}));
    fig.panels.push_back(makeLogLogPanel(r.trial.name + ": CPU time per frame", "points per muscle N", "CPU s / frame",
                                         {makePlotLine("core engine", x, yc, "linespoints")}));
    report.addPlot("id_masspoints", fig, "error and cost against mass points per muscle");

    std::ostringstream md;
    md << trial_md << "\n\nReference: " << r.reference.label << " points per muscle (" << r.reference.muscles_with_mass
       << " muscles, " << fmt(r.reference.muscle_mass, "%.3f") << " kg, " << fmt(1e6 * r.reference.cpu_per_frame_s)
       << " us/frame).\n\n";
    md << "- **Recommended points per muscle**: ";
    if (r.recommended_points < 0) {
      md << "none of the tried N reaches an error below " << fmt(100 * r.target) << "% of the inertial effect.\n";
    } else {
      for (const auto& row : r.masspoints)
        if (row.value == r.recommended_points)
          md << "N = " << row.value << ", the smallest tried N whose error is below " << fmt(100 * r.target)
             << "% of the inertial effect: " << fmt(100 * row.error.err_effect, "%.3g") << "% of the effect ("
             << row.error.worst_column << "), " << fmt(row.error.err_peak, "%.2e") << " of the torque peak, "
             << fmt(1e6 * row.cpu_per_frame_s) << " us/frame (" << fmt(row.cpu_per_frame_s / r.cpu_per_frame_zero_s, "%.2f")
             << "x the zero-mass engine).\n";
    }
    for (size_t i = 1; i < r.masspoints.size(); ++i) {
      const auto& a = r.masspoints[i - 1];
      const auto& b = r.masspoints[i];
      if (a.error.err_effect > 0 && b.error.err_effect > 0)
        md << (i == 1 ? "- Observed order (log error ratio / log N ratio): " : ", ") << a.value << "->" << b.value
           << " " << fmt(std::log(a.error.err_effect / b.error.err_effect) / std::log(double(b.value) / a.value), "%.2f");
    }
    md << "\n\n| N | muscles | points | error / inertial effect | worst column | error / peak | CPU us/frame |\n"
       << "|---|---|---|---|---|---|---|\n";
    for (const auto& row : r.masspoints)
      md << "| " << row.label << " | " << row.muscles_with_mass << " | " << row.points_total << " | "
         << fmt(row.error.err_effect, "%.2e") << " | " << row.error.worst_column << " | "
         << fmt(row.error.err_peak, "%.2e") << " | " << fmt(1e6 * row.cpu_per_frame_s) << " |\n";
    report.addMarkdown("ID study: mass points per muscle", md.str());

    JsonValue mp = JsonValue::object();
    mp["reference"] = rowJson(r.reference);
    JsonValue rows = JsonValue::array();
    for (const auto& row : r.masspoints) rows.push(rowJson(row));
    mp["runs"] = std::move(rows);
    mp["target_rel_effect"] = JsonValue(r.target);
    mp["recommended_points"] = JsonValue(r.recommended_points);
    js["masspoints"] = std::move(mp);
  }

  if (r.has_reduction) {
    CsvTable t;
    t.header = {"top_k"};
    t.header.insert(t.header.end(), tail.begin(), tail.end());
    for (const auto& row : r.reduction) t.addRow(csvRow(row));
    report.addTable("id_reduction", t, "ID torque error against all muscles with mass, per K");
    CsvTable rk;
    rk.header = {"rank", "muscle", "inertia_share"};
    for (size_t i = 0; i < r.ranking.size(); ++i)
      rk.addRow({std::to_string(i + 1), r.ranking[i].first, formatNumber(r.ranking[i].second)});
    report.addTable("id_reduction_ranking", rk, "muscles by inertia contribution (the order top:K takes them in)");

    std::vector<double> x, ye, yp;
    for (const auto& row : r.reduction) {
      x.push_back(std::max(row.cpu_per_frame_s, 1e-9));
      ye.push_back(std::max(row.error.err_effect, 1e-16));
      yp.push_back(std::max(row.error.err_peak, 1e-16));
    }
    PlotFigure fig;
    fig.title = "id_reduction";
    fig.panel_width = 640;
    fig.panel_height = 440;
    fig.panels.push_back(makeLogLogPanel(r.trial.name + ": top-K muscles with mass, K = 0.." +
                                             std::to_string(r.ranking.size()) + " (error 0 at K = all drawn at 1e-16)",
                                         "CPU s / frame", "error vs all muscles with mass",
                                         {makePlotLine("rel. to inertial effect", x, ye, "linespoints"),
                                          makePlotLine("rel. to torque peak", x, yp, "linespoints")}));
    report.addPlot("id_reduction", fig, "error against cost when only the top-K muscles carry mass");

    std::ostringstream md;
    md << trial_md << "\n\nReference: every candidate muscle with mass (" << r.all_muscles.muscles_with_mass
       << " muscles, " << fmt(r.all_muscles.muscle_mass, "%.3f") << " kg, " << r.all_muscles.points_total
       << " points, " << fmt(1e6 * r.all_muscles.cpu_per_frame_s) << " us/frame). K = 0 is the model without muscle "
       << "mass, so its error is 100% of the inertial effect by definition.\n\n";
    int smallest = -1;
    for (const auto& row : r.reduction)
      if (smallest < 0 && row.error.err_effect < r.target) smallest = row.value;
    md << "- **Smallest K below " << fmt(100 * r.target) << "% of the inertial effect**: ";
    if (smallest < 0) md << "none.\n";
    for (const auto& row : r.reduction)
      if (row.value == smallest)
        md << "K = " << row.label << " (" << fmt(100 * row.error.err_effect, "%.3g") << "%, "
           << fmt(1e6 * row.cpu_per_frame_s) << " us/frame against " << fmt(1e6 * r.all_muscles.cpu_per_frame_s)
           << " with every muscle).\n";
    md << "\nRanking (inertia share: the largest ||M_muscle(q)|| / ||M_skeleton(q)|| over the trial's poses): ";
    for (size_t i = 0; i < r.ranking.size(); ++i)
      md << (i ? ", " : "") << (i + 1) << ". " << r.ranking[i].first << " " << fmt(r.ranking[i].second, "%.2e");
    md << ".\n\n| K | muscles | mass kg | error / inertial effect | worst column | error / peak | CPU us/frame |\n"
       << "|---|---|---|---|---|---|---|\n";
    for (const auto& row : r.reduction)
      md << "| " << row.label << " | " << row.muscles_with_mass << " | " << fmt(row.muscle_mass, "%.3f") << " | "
         << fmt(row.error.err_effect, "%.2e") << " | " << row.error.worst_column << " | "
         << fmt(row.error.err_peak, "%.2e") << " | " << fmt(1e6 * row.cpu_per_frame_s) << " |\n";
    report.addMarkdown("ID study: model reduction (top-K muscles with mass)", md.str());

    JsonValue red = JsonValue::object();
    red["reference"] = rowJson(r.all_muscles);
    JsonValue rows = JsonValue::array();
    for (const auto& row : r.reduction) rows.push(rowJson(row));
    red["runs"] = std::move(rows);
    JsonValue rank = JsonValue::array();
    for (const auto& [name, share] : r.ranking) {
      JsonValue o = JsonValue::object();
      o["muscle"] = JsonValue(name);
      o["inertia_share"] = JsonValue(share);
      rank.push(std::move(o));
    }
    red["ranking"] = std::move(rank);
    js["reduction"] = std::move(red);
  }
}

}  // namespace redmax::validation
