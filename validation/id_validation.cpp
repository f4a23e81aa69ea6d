#include "validation/id_validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include "converter/id/core_id_engine.hpp"
#include "converter/osim_reader.hpp"
#include "converter/storage.hpp"
#include "plugin/simbody/id_engine.hpp"
#include "plugin/simbody/simbody_options.hpp"
#include "validation/report/progress.hpp"
#include "validation/report/trial_view.hpp"
#include "validation/simbody_cross_check.hpp"

namespace redmax::validation {
namespace {

// solve the trial with one engine, timing construction and the frames separately
osim::Storage runEngine(const osim::InverseDynamicsTool& tool, osim::IdEngine& engine, IdEngineRun& run,
                        bool show_progress) {
  ProgressOptions po;
  po.stream = show_progress ? stderr : nullptr;
  Progress progress("validate: " + run.name, tool.numFrames(), po);
  Stopwatch sw;
  osim::Storage s = tool.run(engine, [&](int done, int) { progress.set(done); });
  run.seconds = sw.seconds();
  progress.finish();
  run.frames = s.numRows();
  run.ran = true;
  return s;
}

JsonValue engineJson(const IdEngineRun& e) {
  JsonValue j = JsonValue::object();
  j["ran"] = e.ran;
  if (!e.ran) j["skipped"] = e.skipped;
  j["frames"] = e.frames;
  j["build_seconds"] = e.build_seconds;
  j["seconds"] = e.seconds;
  j["frames_per_second"] = e.framesPerSecond();
  return j;
}

std::string fmt(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

// an engine's result at full precision beside the report
void writeResult(const std::string& dir, const std::string& file, const osim::Storage& s) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  osim::StorageWriteOptions wo;
  wo.scientific = true;
  wo.decimals = 16;
  try {
    osim::writeStorage((std::filesystem::path(dir) / file).string(), s, wo);
  } catch (const osim::ConvertError& e) {
    throw ReportError(dir, e.what());
  }
}

JsonValue jnum(double x) { return std::isfinite(x) ? JsonValue(x) : JsonValue(); }

// the core with muscle mass (a) against the zero-mass core (b), per column, into the report: a
// measurement, so the metrics are written as a table and a section, not as a comparison
void addInertialEffect(InertialEffect& ie, const osim::Storage& mass, const osim::Storage& zero,
                       const osim::Storage* simbody, Report& report) {
  CompareOptions co;
  co.align.grid_table = 1;
  const double inf = std::numeric_limits<double>::infinity();
  co.tolerance = {inf, inf, inf, inf};
  const Comparison c = compareTables("inertial_effect", mass, "core_mass", zero, "core", co);
  ie.metrics = c.metrics;
  ie.largest = -1;
  for (size_t k = 0; k < ie.metrics.size(); ++k)
    if (ie.largest < 0 || ie.metrics[k].max_rel > ie.metrics[static_cast<size_t>(ie.largest)].max_rel)
      ie.largest = static_cast<int>(k);

  CsvTable t;
  t.header = {"column", "peak_zero_mass", "rms", "max_abs", "t_max_abs", "rms_rel", "max_rel", "mean"};
  for (const ColumnMetrics& m : ie.metrics)
    t.addRow(m.name, {m.peak_ref, m.rms, m.max_abs, m.t_max_abs, m.rms_rel, m.max_rel, m.mean});
  report.addTable("inertial_effect", t,
                  "core with muscle mass minus zero-mass core, per column (relative to the zero-mass peak); "
                  "a measurement, not a failure");

  JsonValue& js = report.section("inertial_effect");
  js["source"] = osim::toString(ie.options.source);
  if (ie.options.source == osim::MuscleMassOptions::Source::Transfer) {
    js["transfer_body"] = ie.options.transfer_body;
    js["transfer_fraction"] = ie.options.transfer_fraction;
  }
  js["muscle_mass_kg"] = ie.muscle_mass;
  js["muscles_with_mass"] = ie.muscles_with_mass;
  js["seconds"] = ie.seconds;
  js["note"] = "core with muscle mass vs the zero-mass core (the inertial effect); reported, never a failure. "
               "The engines with muscle mass are cross-checked in simbody_mass_check";
  JsonValue& cols = js["columns"] = JsonValue::object();
  for (const ColumnMetrics& m : ie.metrics) {
    JsonValue& o = cols[m.name] = JsonValue::object();
    o["peak_zero_mass"] = m.peak_ref;
    o["rms"] = m.rms;
    o["max_abs"] = m.max_abs;
    o["t_max_abs"] = m.t_max_abs;
    o["rms_rel"] = jnum(m.rms_rel);
    o["max_rel"] = jnum(m.max_rel);
  }
  if (ie.largest >= 0) js["largest_column"] = ie.metrics[static_cast<size_t>(ie.largest)].name;

  // overlay: with mass, zero mass, Simbody (zero mass)
  std::vector<const Table*> all = {&mass, &zero};
  std::vector<std::string> names = {"core_mass", "core"};
  if (simbody) {
    all.push_back(simbody);
    names.push_back("simbody");
  }
  report.addOverlay("inertial_effect_overlay", alignTables(all, names),
                    "inverse dynamics with and without muscle mass", "generalized force [N m or N]");

  std::ostringstream md;
  md << "The core solved the trial again with " << fmt("%.4g", ie.muscle_mass) << " kg in the mass points of "
     << ie.muscles_with_mass << " muscles (" << osim::toString(ie.options.source);
  if (ie.options.source == osim::MuscleMassOptions::Source::Transfer)
    md << ", " << fmt("%g", 100 * ie.options.transfer_fraction) << "% of " << ie.options.transfer_body;
  md << "). Differences from the zero-mass core are the inertial effect, not failures (the "
        "cross-check of the engines with muscle mass is its own section).\n\n| column | zero-mass peak | max diff | max / peak | "
        "RMS / peak |\n|---|---|---|---|---|\n";
  for (const ColumnMetrics& m : ie.metrics)
    md << "| `" << m.name << "` | " << fmt("%.4g", m.peak_ref) << " | " << fmt("%.4g", m.max_abs) << " | "
       << fmt("%.3g", m.max_rel) << " | " << fmt("%.3g", m.rms_rel) << " |\n";
  if (!ie.description.empty()) md << "\n```\n" << ie.description << "```\n";
  report.addMarkdown("Inertial effect", md.str());
}

}  // namespace

namespace {

// the trial's `redmax view` with the muscle mass of the run (a sweep's largest value)
void addIdTrialView(const IdValidationOptions& opt, const osim::IdToolConfig& config, Report& report) {
  TrialView tv{config.model_file, config.coordinates_file, opt.muscle_mass, "no muscle mass"};
  if (!opt.mass_sweep.empty()) {
    const double largest = *std::max_element(opt.mass_sweep.begin(), opt.mass_sweep.end());
    if (tv.mass.source == osim::MuscleMassOptions::Source::Transfer)
      tv.mass.transfer_fraction = largest;
    else
      tv.mass.density *= largest;
    tv.mass_note = "the sweep's largest value, " + fmt("%g", largest);
  } else if (tv.mass.source != osim::MuscleMassOptions::Source::None) {
    tv.mass_note = std::string("muscle mass ") + osim::toString(tv.mass.source);
  }
  validation::addTrialView(report, opt.report_dir, tv, opt.view);
}

}  // namespace

IdValidationResult runIdValidation(const IdValidationOptions& opt) {
  if (opt.report_dir.empty()) throw osim::ConvertError("", 0, "no report directory given (--report DIR)");
  if (!(opt.engine_rel >= 0) || !(opt.reference_rms_rel >= 0) || !(opt.reference_max_rel >= 0) ||
      !(opt.engine_abs >= 0) || !(opt.reference_abs >= 0))
    throw osim::ConvertError("", 0, "tolerances must be non-negative numbers");
  IdValidationResult r;

  // inputs processed once; both engines see the same processed coordinates and loads
  osim::IdToolConfig config = osim::resolveIdSettings(opt.settings);
  if (!opt.loads_working_dir.empty()) config.loads_working_dir = opt.loads_working_dir;
  const osim::InverseDynamicsTool tool(config);
  r.warnings = tool.warnings();

  // muscle-mass options are checked before any engine runs (bad options are bad input): the
  // engine of the largest mass is built once here
  const bool mass_run = opt.muscle_mass.source != osim::MuscleMassOptions::Source::None;
  if (!opt.mass_sweep.empty() && !mass_run)
    throw std::invalid_argument("--mass-sweep needs --muscle-mass transfer or physiological");
  MassSweepEngineFactory mass_factory;
  MassSweepEngine mass_engine;
  std::vector<double> sweep_values;
  if (mass_run) {
    mass_factory = makeCoreMassEngineFactory(tool);
    if (!opt.mass_sweep.empty()) {
      sweep_values = checkMassSweepValues(opt.muscle_mass, opt.mass_sweep);
      mass_factory(massOptionsForValue(opt.muscle_mass, sweep_values.back()));
    } else {
      mass_engine = mass_factory(opt.muscle_mass);
    }
  }

  // references are read before any engine runs, so a bad file is reported at once
  std::vector<osim::Storage> refs;
  std::vector<std::string> ref_labels;
  std::set<std::string> used = {"core", "simbody"};
  for (size_t i = 0; i < opt.references.size(); ++i) {
    refs.push_back(osim::readStorage(opt.references[i].path));
    checkTable(refs.back(), opt.references[i].path);
    std::string label = opt.references[i].label.empty() ? "reference" : opt.references[i].label;
    // labels name files and legends: keep them unique
    for (int k = 2; used.count(label); ++k) label = opt.references[i].label + "_" + std::to_string(k);
    used.insert(label);
    ref_labels.push_back(label);
  }

  ReportOptions ro;
  ro.title = "redmax validate: inverse dynamics, core vs Simbody vs reference";
  ro.gnuplot = opt.gnuplot;
  Report report(opt.report_dir, ro);
  report.setInput("setup", config.setup_file);
  report.setInput("model", config.model_file);
  report.setInput("coordinates", config.coordinates_file);
  report.setInput("external_loads", config.external_loads_file);
  report.setInput("lowpass_cutoff_hz", config.lowpass_cutoff_hz);
  report.setInput("t0", std::isfinite(config.t0) ? JsonValue(config.t0) : JsonValue());
  report.setInput("t1", std::isfinite(config.t1) ? JsonValue(config.t1) : JsonValue());
  report.setInput("mode", config.opensim_compat ? "opensim-compat" : "exact");
  report.setInput("frames", tool.numFrames());
  JsonValue jrefs = JsonValue::array();
  for (size_t i = 0; i < refs.size(); ++i) {
    JsonValue& j = jrefs.push(JsonValue::object());
    j["label"] = ref_labels[i];
    j["path"] = opt.references[i].path;
  }
  report.setInput("references", jrefs);
  JsonValue tol = JsonValue::object();
  tol["engine_rel"] = opt.engine_rel;
  tol["engine_abs"] = opt.engine_abs;
  tol["reference_rms_rel"] = opt.reference_rms_rel;
  tol["reference_max_rel"] = std::isfinite(opt.reference_max_rel) ? JsonValue(opt.reference_max_rel) : JsonValue("unlimited");
  tol["reference_abs"] = opt.reference_abs;
  report.setInput("tolerances", tol);
  if (mass_run) {
    JsonValue m = JsonValue::object();
    m["source"] = osim::toString(opt.muscle_mass.source);
    m["muscles"] = opt.muscle_mass.muscles;
    m["mass_points"] = opt.muscle_mass.mass_points;
    m["specific_tension_pa"] = opt.muscle_mass.specific_tension;
    m["density_kg_m3"] = opt.muscle_mass.density;
    if (opt.muscle_mass.source == osim::MuscleMassOptions::Source::Transfer) {
      m["transfer_body"] = opt.muscle_mass.transfer_body;
      if (opt.mass_sweep.empty()) m["transfer_fraction"] = opt.muscle_mass.transfer_fraction;
    }
    if (!opt.mass_sweep.empty()) m["sweep_values"] = sweep_values;
    report.setInput("muscle_mass", m);
  }

  // the core engine: a failure here is the run failing (IdEngineError propagates)
  IdEngineRun core_run;
  core_run.name = "core";
  Stopwatch sw;
  osim::CoreIdEngine core(tool.model(), tool.engineOptions());
  core_run.build_seconds = sw.seconds();
  osim::Storage core_result = runEngine(tool, core, core_run, opt.progress);
  core_result.name = "core";
  r.engines.push_back(core_run);

  // the Simbody engine: a model it cannot build is recorded, and the run goes on with core only
  IdEngineRun sb_run;
  sb_run.name = "simbody";
  osim::Storage sb_result;
  // the core result the Simbody engine is compared with: the core's own, unless Simbody needed
  // OpenSim's fallback inertia, in which case the core solves that same model again
  osim::Storage core_for_simbody;
  if (!opt.run_simbody) {
    sb_run.skipped = "disabled (--no-simbody)";
  } else {
    std::unique_ptr<simbody::SimbodyIdEngine> sb;
    try {
      sw.restart();
      // Debian's Simbody checks inertias that OpenSim's release build keeps (gait2392's toes):
      // then both engines are cross-checked on OpenSim's isotropic fallback for those bodies
      SimbodyCrossCheckEngine built = makeSimbodyCrossCheckEngine(makeMusculoskeletalModel(tool.model()), tool.engineOptions());
      sb_run.build_seconds = sw.seconds();
      sb = std::move(built.engine);
      if (built.usedFallback()) {
        osim::CoreIdEngine core_fallback(*built.fallback_model, tool.engineOptions());
        core_for_simbody = tool.run(core_fallback);
        core_for_simbody.name = "core";
        r.warnings.push_back(describeInertiaFallback(built));
      }
    } catch (const std::exception& e) {
      sb_run.skipped = std::string("the Simbody engine cannot build this model: ") + e.what();
    }
    if (sb) {
      try {
        sb_result = runEngine(tool, *sb, sb_run, opt.progress);
        sb_result.name = "simbody";
      } catch (const std::exception& e) {
        // an engine that fails where the core succeeds is a disagreement: it fails validation
        sb_run.ran = false;
        sb_run.skipped = std::string("the Simbody engine failed: ") + e.what();
        report.addCheck("simbody engine solves every frame", false, e.what());
      }
    }
  }
  if (!sb_run.ran) r.warnings.push_back("simbody: " + sb_run.skipped);
  r.engines.push_back(sb_run);

  // speed: frames, seconds, frames per second of each engine
  // (one section at a time: creating a section may move the others)
  for (const auto& e : r.engines)
    report.section("engines")[e.name] = e.ran ? JsonValue("ran") : JsonValue(e.skipped);
  JsonValue& speed = report.section("speed");
  for (const auto& e : r.engines) {
    speed[e.name] = engineJson(e);
    if (e.ran) report.addWallTime(e.name, e.seconds);
  }
  if (r.engines[0].ran && r.engines[1].ran && r.engines[0].seconds > 0)
    speed["simbody_over_core_seconds"] = r.engines[1].seconds / r.engines[0].seconds;

  // core vs simbody on identical frames: round-off agreement, every column and frame
  if (sb_run.ran) {
    CompareOptions co;
    co.tolerance = {opt.engine_abs, opt.engine_rel, opt.engine_abs, opt.engine_rel};
    co.align.grid_table = 0;
    co.missing_columns_fail = true;
    r.comparisons.push_back(compareTables("core_vs_simbody",
                                          core_for_simbody.numRows() > 0 ? core_for_simbody : core_result, "core",
                                          sb_result, "simbody", co));
  }

  // core vs each reference: the reference's rows in the overlap are the grid, core interpolated
  for (size_t i = 0; i < refs.size(); ++i) {
    CompareOptions co;
    co.tolerance = {opt.reference_abs, opt.reference_rms_rel, opt.reference_abs, opt.reference_max_rel};
    co.align.grid_table = 1;
    co.align.interpolation = opt.interpolation;
    try {
      r.comparisons.push_back(
          compareTables("core_vs_" + ref_labels[i], core_result, "core", refs[i], ref_labels[i], co));
    } catch (const CompareError& e) {
      throw CompareError(opt.references[i].path + ": " + e.what());
    }
  }
  for (const auto& c : r.comparisons) {
    report.addComparison(c, "generalized force [N m or N]");
    for (const auto& w : c.warnings) r.warnings.push_back(c.name + ": " + w);
  }

  // every series on one grid: overlaid torques of all engines and references
  std::vector<const Table*> all = {&core_result};
  std::vector<std::string> names = {"core"};
  if (sb_run.ran) {
    all.push_back(&sb_result);
    names.push_back("simbody");
  }
  for (size_t i = 0; i < refs.size(); ++i) {
    all.push_back(&refs[i]);
    names.push_back(ref_labels[i]);
  }
  if (all.size() > 1) {
    try {
      AlignOptions ao;
      ao.interpolation = opt.interpolation;
      report.addOverlay("overlay_all", alignTables(all, names, ao), "inverse dynamics: all engines and references",
                        "generalized force [N m or N]");
    } catch (const CompareError& e) {
      r.warnings.push_back(std::string("overlay of all series skipped: ") + e.what());
    }
  }

  // muscle mass: one extra core run (inertial effect) or a sweep; Simbody stays the zero-mass
  // reference, so nothing here changes the comparisons above
  if (mass_run && opt.mass_sweep.empty()) {
    r.has_inertial_effect = true;
    InertialEffect& ie = r.inertial_effect;
    ie.options = opt.muscle_mass;
    ie.muscle_mass = mass_engine.muscle_mass;
    ie.muscles_with_mass = mass_engine.muscles_with_mass;
    ie.description = mass_engine.description;
    IdEngineRun mass_run_info;
    mass_run_info.name = "core_mass";
    osim::Storage mass_result = runEngine(tool, *mass_engine.engine, mass_run_info, opt.progress);
    ie.seconds = mass_run_info.seconds;
    report.addWallTime("core_mass", ie.seconds);
    addInertialEffect(ie, mass_result, core_result, sb_run.ran ? &sb_result : nullptr, report);
    // Simbody with muscle inertia on the same model and mass points: engines agree to round-off
    if (sb_run.ran && mass_engine.model) {
      IdEngineRun sbm;
      sbm.name = "simbody_mass";
      try {
        SimbodyCrossCheckEngine sb =
            makeSimbodyCrossCheckEngine(*mass_engine.model, tool.engineOptions());
        osim::Storage sbm_result = runEngine(tool, *sb.engine, sbm, opt.progress);
        ie.simbody_ran = true;
        // with the fallback inertia, the core solves that same model and mass points again
        osim::Storage core_mass_same = mass_result;
        if (sb.usedFallback()) {
          osim::CoreIdEngine core_fallback(*sb.fallback_model, tool.engineOptions());
          core_mass_same = tool.run(core_fallback);
          ie.simbody_note = describeInertiaFallback(sb);
          r.warnings.push_back("simbody with muscle inertia: " + ie.simbody_note);
        }
        CompareOptions co;
        co.tolerance = {opt.engine_abs, opt.engine_rel, opt.engine_abs, opt.engine_rel};
        co.align.grid_table = 0;
        co.missing_columns_fail = true;
        ie.simbody_check =
            compareTables("core_mass_vs_simbody_mass", core_mass_same, "core_mass", sbm_result, "simbody_mass", co);
        ie.simbody_not_counted = simbodyMassCheckNotCountedReason(opt.muscle_mass, mass_engine.wrap);
        addSimbodyMassCheck(ie.simbody_check, core_mass_same, sbm_result, report, ie.simbody_not_counted);
      } catch (const std::exception& e) {
        ie.simbody_skipped = e.what();
        r.warnings.push_back(std::string("simbody with muscle inertia: ") + e.what());
      }
    }
    mass_result.name = osim::kIdStorageName;
    writeResult(opt.report_dir, "core_mass_id.sto", mass_result);
  }
  if (!opt.mass_sweep.empty()) {
    r.has_mass_sweep = true;
    MassSweepOptions so;
    so.base = opt.muscle_mass;
    so.values = sweep_values;
    so.main_columns = opt.sweep_columns;
    so.progress = opt.progress;
    so.simbody_check = sb_run.ran;
    so.engine_rel = opt.engine_rel;
    so.engine_abs = opt.engine_abs;
    // the value 0 against the same references as the zero-mass core, at their tolerance
    for (size_t i = 0; i < refs.size(); ++i) so.references.push_back({ref_labels[i], refs[i]});
    so.reference_tolerance = {opt.reference_abs, opt.reference_rms_rel, opt.reference_abs, opt.reference_max_rel};
    so.interpolation = opt.interpolation;
    r.mass_sweep = runMassSweep(tool, core_result, so, mass_factory);
    double secs = 0;
    for (const auto& p : r.mass_sweep.points) secs += p.seconds;
    report.addWallTime("mass_sweep", secs);
    addMassSweepToReport(r.mass_sweep, core_result, report);
    if (!r.mass_sweep.simbody.skipped.empty()) r.warnings.push_back("mass sweep: " + r.mass_sweep.simbody.skipped);
    if (!r.mass_sweep.simbody.note.empty()) r.warnings.push_back("mass sweep, simbody: " + r.mass_sweep.simbody.note);
  }

  // the engines' own results, at full precision, beside the report
  core_result.name = osim::kIdStorageName;
  writeResult(opt.report_dir, "core_id.sto", core_result);
  if (sb_run.ran) {
    sb_result.name = osim::kIdStorageName;
    writeResult(opt.report_dir, "simbody_id.sto", sb_result);
  }

  std::ostringstream md;
  md << "Each engine solved the same processed inputs (" << tool.numFrames() << " frames, "
     << (config.opensim_compat ? "OpenSim-compatible" : "exact") << " mode).\n\n";
  md << "| engine | frames | build [s] | solve [s] | frames/s | note |\n|---|---|---|---|---|---|\n";
  for (const auto& e : r.engines)
    md << "| " << e.name << " | " << e.frames << " | " << fmt("%.4g", e.build_seconds) << " | "
       << fmt("%.4g", e.seconds) << " | " << fmt("%.0f", e.framesPerSecond()) << " | "
       << (e.ran ? "" : e.skipped) << " |\n";
  report.addMarkdown("Engines and speed", md.str());
  if (!r.warnings.empty()) {
    std::ostringstream w;
    for (const auto& s : r.warnings) w << "- " << s << "\n";
    report.addMarkdown("Warnings", w.str());
  }

  if (!opt.view.index_html.empty()) addIdTrialView(opt, config, report);

  r.files = report.write();
  r.passed = report.passed();
  return r;
}

std::string formatIdValidationSummary(const IdValidationResult& r) {
  std::ostringstream os;
  for (const auto& e : r.engines) {
    if (e.ran)
      os << "engine " << e.name << ": " << e.frames << " frames, " << fmt("%.4f", e.seconds) << " s, "
         << fmt("%.0f", e.framesPerSecond()) << " frames/s\n";
    else
      os << "engine " << e.name << ": skipped (" << e.skipped << ")\n";
  }
  for (const auto& c : r.comparisons) {
    os << c.name << ": " << c.metrics.size() << " columns over [" << fmt("%.6g", c.t_begin) << ", "
       << fmt("%.6g", c.t_end) << "] s, " << c.time.size() << " samples";
    if (c.worst >= 0) {
      const ColumnMetrics& m = c.metrics[static_cast<size_t>(c.worst)];
      os << "; worst " << m.name << " rms/peak " << fmt("%.3g", m.rms_rel) << " max/peak "
         << fmt("%.3g", m.max_rel);
    }
    if (!c.only_in_a.empty()) os << "; " << c.only_in_a.size() << " only in " << c.label_a;
    if (!c.only_in_b.empty()) os << "; " << c.only_in_b.size() << " only in " << c.label_b;
    os << " -> " << (c.passed ? "PASS" : "FAIL") << "\n";
  }
  if (r.has_inertial_effect) {
    const InertialEffect& ie = r.inertial_effect;
    os << "inertial effect (" << osim::toString(ie.options.source);
    if (ie.options.source == osim::MuscleMassOptions::Source::Transfer)
      os << " " << fmt("%g", 100 * ie.options.transfer_fraction) << "% of " << ie.options.transfer_body;
    os << ", " << fmt("%.4g", ie.muscle_mass) << " kg in " << ie.muscles_with_mass << " muscles)";
    if (ie.largest >= 0) {
      const ColumnMetrics& m = ie.metrics[static_cast<size_t>(ie.largest)];
      os << ": largest " << m.name << " max/peak " << fmt("%.3g", m.max_rel) << " rms/peak " << fmt("%.3g", m.rms_rel);
    }
    os << " (measured, not pass/fail)\n";
    if (ie.simbody_ran) os << formatSimbodyMassCheck(ie.simbody_check, ie.simbody_not_counted);
  }
  if (r.has_mass_sweep) os << formatMassSweepSummary(r.mass_sweep);
  os << "validate: " << (r.passed ? "PASS" : "FAIL") << "\n";
  return os.str();
}

}  // namespace redmax::validation
