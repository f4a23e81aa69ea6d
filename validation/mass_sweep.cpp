#include "validation/mass_sweep.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "converter/error.hpp"
#include "converter/id/core_id_engine.hpp"
#include "plugin/simbody/id_engine.hpp"
#include "validation/report/progress.hpp"
#include "validation/simbody_cross_check.hpp"

namespace redmax::validation {
namespace {

using Source = osim::MuscleMassOptions::Source;

std::string fmtG(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

bool isTransfer(const osim::MuscleMassOptions& o) { return o.source == Source::Transfer; }

// legend text and file tag of one value: "20%" / "F0.2" (transfer), "x0.25" / "s0.25" (physiological)
std::string valueLabel(const osim::MuscleMassOptions& o, double v) {
  return isTransfer(o) ? fmtG("%g%%", 100 * v) : "x" + fmtG("%g", v);
}
std::string valueTag(const osim::MuscleMassOptions& o, double v) {
  return (isTransfer(o) ? "F" : "s") + fmtG("%g", v);
}

// JSON number or null (NaN and infinities are not JSON)
JsonValue num(double x) { return std::isfinite(x) ? JsonValue(x) : JsonValue(); }

JsonValue numbers(const std::vector<double>& v) {
  JsonValue a = JsonValue::array();
  for (double x : v) a.push(num(x));
  return a;
}

std::vector<double> column(const MatX& m, int c) {
  std::vector<double> v(static_cast<size_t>(m.rows()));
  for (int k = 0; k < m.rows(); ++k) v[static_cast<size_t>(k)] = m(k, c);
  return v;
}

std::string sideOf(const std::string& body) {
  auto ends = [&](const std::string& s) {
    return body.size() > s.size() && body.compare(body.size() - s.size(), s.size(), s) == 0;
  };
  if (ends("_r")) return "_r";
  if (ends("_l")) return "_l";
  return "";
}

}  // namespace

MassSweepEngineFactory makeCoreMassEngineFactory(const osim::InverseDynamicsTool& tool) {
  // the tool's build options (inverse dynamics: no constraints) and, for top:K, the trial's poses
  osim::BuildOptions bo;
  bo.simbody_compat = tool.config().opensim_compat;
  bo.constraints = false;
  const osim::InverseDynamicsTool* t = &tool;
  return [t, bo](const osim::MuscleMassOptions& o) {
    std::vector<VecX> samples;
    if (o.muscles.rfind("top:", 0) == 0) {
      VecX q, v, vdot;
      std::vector<osim::IdLoadSample> loads;
      const int n = t->numFrames();
      for (int k = 0; k < n; k += std::max(1, n / 100)) {
        t->calcInputs(t->frameTime(k), q, v, vdot, loads);
        samples.push_back(q);
      }
    }
    MassSweepEngine e;
    osim::MuscleMassModel mm;
    if (hasZeroMuscleMass(o)) {
      // zero mass still runs the mass-point code: the points a small positive value places (their
      // fractions of the path do not depend on the mass), each massless, on the unchanged bodies
      osim::MuscleMassOptions layout = o;
      if (isTransfer(o)) layout.transfer_fraction = 1e-6;
      else layout.density = 1e-6 * osim::kDefaultMuscleDensity;
      const osim::MuscleMassModel points = osim::applyMuscleMass(t->description(), bo, layout, samples);
      osim::MuscleMassOptions none = layout;  // the options are checked whatever the source
      none.source = Source::None;
      mm = osim::applyMuscleMass(t->description(), bo, none);
      MusculoskeletalModelBuilder zero(mm.build.model);
      int n_points = 0;
      for (int k = 0; k < zero.numMuscles(); ++k) {
        Muscle& mu = zero.muscle(k);
        mu = points.build.model.muscles()[k];
        for (double& m_a : mu.mass_points.mass) m_a = 0.0;
        e.muscles_with_mass += mu.mass_points.size() > 0;
        n_points += mu.mass_points.size();
      }
      mm.build.model = zero.finalize();
      e.wrap = osim::countWrapMass(points.plan);
      e.description = "muscle mass 0: " + std::to_string(e.muscles_with_mass) + " muscles carry " +
                      std::to_string(n_points) + " mass points of zero mass; every body keeps its mass\n";
    } else {
      mm = osim::applyMuscleMass(t->description(), bo, o, samples);
      for (const auto& me : mm.plan.muscles) e.muscles_with_mass += me.mass > 0.0;
      e.description = osim::describeMuscleMass(mm.plan);
      e.wrap = osim::countWrapMass(mm.plan);
    }
    if (mm.build.model.nr() != t->model().nr())
      throw osim::ConvertError(t->config().model_file, 0, "the model with muscle mass has other coordinates");
    e.muscle_mass = mm.plan.total_muscle_mass;
    e.model = std::make_shared<const MusculoskeletalModel>(mm.build.model);
    // the core with the muscles' mass points as a MuscleTerm (core_id_engine.hpp)
    e.engine = std::make_unique<osim::CoreIdEngine>(*e.model, t->engineOptions());
    return e;
  };
}

osim::MuscleMassOptions massOptionsForValue(const osim::MuscleMassOptions& base, double value) {
  osim::MuscleMassOptions o = base;
  if (isTransfer(base)) o.transfer_fraction = value;
  else o.density = base.density * value;  // every physiological mass scales with the density (0 at 0)
  return o;
}

bool hasZeroMuscleMass(const osim::MuscleMassOptions& o) {
  return (o.source == Source::Physiological && o.density == 0.0) ||
         (o.source == Source::Transfer && o.transfer_fraction == 0.0);
}

std::vector<double> checkMassSweepValues(const osim::MuscleMassOptions& base, std::vector<double> values) {
  if (base.source == Source::None)
    throw std::invalid_argument("--mass-sweep needs --muscle-mass transfer or physiological");
  if (values.empty()) throw std::invalid_argument("--mass-sweep needs at least one value");
  for (double v : values) {
    if (!std::isfinite(v)) throw std::invalid_argument("--mass-sweep: value " + fmtG("%g", v) + " is not finite");
    if (isTransfer(base) && !(v >= 0 && v < 1))
      throw std::invalid_argument("--mass-sweep: transfer fraction " + fmtG("%g", v) + " is outside [0, 1)");
    if (!isTransfer(base) && v < 0)
      throw std::invalid_argument("--mass-sweep: mass scale " + fmtG("%g", v) + " is negative");
  }
  std::sort(values.begin(), values.end());
  for (size_t i = 1; i < values.size(); ++i)
    if (values[i] == values[i - 1])
      throw std::invalid_argument("--mass-sweep: value " + fmtG("%g", values[i]) + " is given twice");
  // the zero point anchors the zero check
  if (values.front() != 0.0) values.insert(values.begin(), 0.0);
  if (values.size() < 2) throw std::invalid_argument("--mass-sweep needs a nonzero value");
  return values;
}

std::vector<double> parseMassSweepValues(const std::string& text) {
  std::vector<double> out;
  std::string cur;
  auto flush = [&] {
    if (cur.empty()) return;
    size_t used = 0;
    double x = 0;
    try {
      x = std::stod(cur, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != cur.size()) throw std::invalid_argument("--mass-sweep: '" + cur + "' is not a number");
    out.push_back(x);
    cur.clear();
  };
  for (char c : text) {
    if (c == ',' || c == ' ' || c == '\t') flush();
    else cur += c;
  }
  flush();
  if (out.empty()) throw std::invalid_argument("--mass-sweep needs a list of values (e.g. 0,0.2,0.4)");
  return out;
}

std::vector<std::string> chooseMainColumns(const std::vector<std::string>& labels, const std::string& transfer_body) {
  const std::string side = sideOf(transfer_body);
  std::vector<std::string> out;
  for (const std::string word : {"ankle", "knee", "hip"}) {
    for (const std::string& l : labels) {
      if (l.find(word) == std::string::npos) continue;
      // the side: "<coord>_r_moment" or a coordinate ending in the side ("..._r")
      if (!side.empty() && l.find(side + "_") == std::string::npos &&
          !(l.size() >= side.size() && l.compare(l.size() - side.size(), side.size(), side) == 0))
        continue;
      if (std::find(out.begin(), out.end(), l) == out.end()) out.push_back(l);
    }
  }
  return out.empty() ? labels : out;
}

MassSweepAnalysis analyzeMassSweep(const std::vector<double>& values, const std::vector<MatX>& tau, const MatX& tau0,
                                   double zero_tolerance) {
  const size_t n = values.size();
  if (tau.size() != n) throw std::invalid_argument("analyzeMassSweep: one torque table per value");
  for (const MatX& t : tau)
    if (t.rows() != tau0.rows() || t.cols() != tau0.cols())
      throw std::invalid_argument("analyzeMassSweep: torque tables differ in shape");
  double ss = 0;
  for (double s : values) ss += s * s;
  if (!(ss > 0)) throw std::invalid_argument("analyzeMassSweep: needs a nonzero value");

  MassSweepAnalysis a;
  for (size_t j = 0; j < n; ++j)
    if (values[j] == 0.0) a.zero_index = static_cast<int>(j);
  const int frames = static_cast<int>(tau0.rows());
  for (int c = 0; c < tau0.cols(); ++c) {
    MassSweepColumn col;
    col.peak_zero = frames ? tau0.col(c).cwiseAbs().maxCoeff() : 0.0;
    const double inv_peak = col.peak_zero > 0 ? 1.0 / col.peak_zero : std::numeric_limits<double>::infinity();
    auto rel = [&](double x) { return x == 0 ? 0.0 : x * inv_peak; };
    double max_y = 0;
    for (size_t j = 0; j < n; ++j) {
      const double peak = frames ? tau[j].col(c).cwiseAbs().maxCoeff() : 0.0;
      const double dmax = frames ? (tau[j].col(c) - tau0.col(c)).cwiseAbs().maxCoeff() : 0.0;
      col.peak.push_back(peak);
      col.peak_change_rel.push_back(rel(peak - col.peak_zero));
      col.max_diff_rel.push_back(rel(dmax));
      max_y = std::max(max_y, dmax);
    }
    // per frame: slope through the origin, residuals pooled over frames and values
    double ss_res = 0, ss_tot = 0, res_max = 0, slope_max = 0;
    for (int k = 0; k < frames; ++k) {
      double sy = 0, mean = 0;
      for (size_t j = 0; j < n; ++j) {
        const double y = tau[j](k, c) - tau0(k, c);
        sy += values[j] * y;
        mean += y;
      }
      const double b = sy / ss;
      mean /= static_cast<double>(n);
      slope_max = std::max(slope_max, std::abs(b));
      for (size_t j = 0; j < n; ++j) {
        const double y = tau[j](k, c) - tau0(k, c);
        const double r = y - b * values[j];
        ss_res += r * r;
        ss_tot += (y - mean) * (y - mean);
        res_max = std::max(res_max, std::abs(r));
      }
    }
    col.has_effect = max_y > 1e-12 * col.peak_zero + 1e-12;
    col.r2 = col.has_effect && ss_tot > 0 ? 1.0 - ss_res / ss_tot : std::numeric_limits<double>::quiet_NaN();
    col.nonlinearity_rel = rel(res_max);
    col.slope_max_rel = rel(slope_max);
    if (col.has_effect && (std::isnan(a.r2_min_observed) || col.r2 < a.r2_min_observed)) a.r2_min_observed = col.r2;
    a.nonlinearity_max = std::max(a.nonlinearity_max, col.nonlinearity_rel);
    if (a.zero_index >= 0) a.zero_max_rel = std::max(a.zero_max_rel, col.max_diff_rel[static_cast<size_t>(a.zero_index)]);
    a.columns.push_back(std::move(col));
  }
  // NaN (a non-finite torque) fails as well
  a.zero_passed = a.zero_index < 0 || a.zero_max_rel <= zero_tolerance;
  return a;
}

MassSweepResult runMassSweep(const osim::InverseDynamicsTool& tool, const osim::Storage& zero_mass,
                             const MassSweepOptions& options, const MassSweepEngineFactory& factory_in) {
  MassSweepResult r;
  r.options = options;
  r.options.values = checkMassSweepValues(options.base, options.values);
  const MassSweepEngineFactory factory = factory_in ? factory_in : makeCoreMassEngineFactory(tool);
  const std::vector<std::string> labels = tool.outputLabels();
  if (zero_mass.labels != labels || zero_mass.numRows() != tool.numFrames())
    throw std::invalid_argument("runMassSweep: the zero-mass result is not this tool's output");
  if (!options.main_columns.empty()) {
    for (const std::string& c : options.main_columns)
      if (std::find(labels.begin(), labels.end(), c) == labels.end())
        throw std::invalid_argument("mass sweep: no output column '" + c + "'");
    r.main_columns = options.main_columns;
  } else {
    r.main_columns = chooseMainColumns(labels, isTransfer(options.base) ? options.base.transfer_body : "");
  }

  // every value: the engine of its options over the same processed inputs
  std::vector<MatX> tau;
  for (double v : r.options.values) {
    MassSweepEngine e = factory(massOptionsForValue(options.base, v));
    // Simbody with muscle inertia at every value: the same model and mass points
    if (options.simbody_check) {
      MassSweepSimbodyCheck c;
      c.value = v;
      if (!e.model) {
        c.skipped = "the engine factory gave no model";
      } else {
        SimbodyCrossCheckEngine sb;
        try {
          sb = makeSimbodyCrossCheckEngine(*e.model, tool.engineOptions());
        } catch (const std::exception& ex) {
          c.skipped = std::string("the Simbody engine cannot build this model: ") + ex.what();
        }
        if (sb.engine) {
          try {
            c.result = tool.run(*sb.engine);
            c.result.name = osim::kIdStorageName;
            c.ran = true;
            if (sb.usedFallback()) {
              // the same model for both: the core again, with the fallback inertia
              osim::CoreIdEngine core_fallback(*sb.fallback_model, tool.engineOptions());
              c.core_result = tool.run(core_fallback);
              c.core_result.name = osim::kIdStorageName;
              c.note = describeInertiaFallback(sb);
            }
          } catch (const std::exception& ex) {
            // an engine that fails where the core succeeds is a disagreement
            c.failed = true;
            c.skipped = std::string("the Simbody engine failed: ") + ex.what();
          }
        }
      }
      r.simbody_values.push_back(std::move(c));
    }
    if (!e.engine) throw std::invalid_argument("mass sweep: the engine factory made no engine");
    ProgressOptions po;
    po.stream = options.progress ? stderr : nullptr;
    Progress progress("mass sweep " + valueLabel(options.base, v), tool.numFrames(), po);
    Stopwatch sw;
    osim::Storage s = tool.run(*e.engine, [&](int done, int) { progress.set(done); });
    MassSweepPoint p;
    p.seconds = sw.seconds();
    progress.finish();
    p.value = v;
    p.muscle_mass = e.muscle_mass;
    p.muscles_with_mass = e.muscles_with_mass;
    p.description = e.description;
    p.wrap = e.wrap;
    r.points.push_back(p);
    s.name = osim::kIdStorageName;
    tau.push_back(s.data);
    r.torques.push_back(std::move(s));
  }
  if (options.simbody_check) {
    CompareOptions co;
    co.tolerance = {options.engine_abs, options.engine_rel, options.engine_abs, options.engine_rel};
    co.align.grid_table = 0;
    co.missing_columns_fail = true;
    const size_t z = 0;  // checkMassSweepValues puts 0 first
    MassSweepSimbodyCheck& c0 = r.simbody_values[z];
    for (size_t j = 0; j < r.simbody_values.size(); ++j) {
      MassSweepSimbodyCheck& c = r.simbody_values[j];
      if (!c.ran) continue;
      const osim::Storage& core_j = c.coreTorques(r.torques[j]);
      c.comparison = compareTables("core_mass_vs_simbody_mass", core_j, "core_mass", c.result, "simbody_mass", co);
      c.not_counted = simbodyMassCheckNotCountedReason(massOptionsForValue(options.base, c.value), r.points[j].wrap);
      // the inertial effect of each engine against its own value 0 (same model pair at both ends:
      // the fallback inertia, when used, is the same at every value)
      if (!c0.ran) continue;
      const osim::Storage& core_0 = c0.coreTorques(r.torques[z]);
      if (core_j.data.rows() != core_0.data.rows() || c.result.data.rows() != c0.result.data.rows() ||
          core_j.data.cols() != c.result.data.cols() || core_j.data.rows() != c.result.data.rows())
        continue;
      const MatX eff_core = core_j.data - core_0.data, eff_sb = c.result.data - c0.result.data;
      double worst_peak = 0, worst_eff = 0;
      bool any_effect = false;
      for (int col = 0; col < eff_core.cols(); ++col) {
        const double d = (eff_core.col(col) - eff_sb.col(col)).cwiseAbs().maxCoeff();
        const double peak = core_0.data.col(col).cwiseAbs().maxCoeff();
        const double eff = eff_core.col(col).cwiseAbs().maxCoeff();
        worst_peak = std::max(worst_peak, peak > 0 ? d / peak : d);
        if (eff > 1e-12 * peak) {
          any_effect = true;
          worst_eff = std::max(worst_eff, d / eff);
        }
      }
      c.effect_max_rel = worst_peak;
      if (any_effect) c.effect_rel_to_effect = worst_eff;
    }
    r.simbody = r.simbody_values.back();
  }
  // the value 0 (massless points) against results computed elsewhere (OpenSim's own ID)
  for (const MassSweepOptions::Reference& ref : options.references) {
    CompareOptions co;
    co.tolerance = options.reference_tolerance;
    co.align.grid_table = 1;
    co.align.interpolation = options.interpolation;
    try {
      r.zero_vs_references.push_back(compareTables("mass_sweep_zero_vs_" + ref.label, r.torques.front(), "core_zero_points",
                                                   ref.table, ref.label, co));
    } catch (const CompareError& ex) {
      throw CompareError(ref.label + ": " + ex.what());
    }
  }
  r.analysis = analyzeMassSweep(r.options.values, tau, zero_mass.data, options.zero_tolerance);
  for (size_t c = 0; c < r.analysis.columns.size(); ++c) r.analysis.columns[c].name = labels[c];
  return r;
}

void addMassSweepToReport(const MassSweepResult& r, const osim::Storage& zero_mass, Report& report) {
  const osim::MuscleMassOptions& base = r.options.base;
  const std::vector<double>& values = r.options.values;
  const MassSweepAnalysis& an = r.analysis;
  const std::vector<std::string>& labels = zero_mass.labels;
  const size_t n = values.size();
  const std::string what = isTransfer(base) ? "fraction of " + base.transfer_body + " mass in the muscles [%]"
                                            : "scale of the physiological muscle mass";
  auto xOf = [&](double v) { return isTransfer(base) ? 100 * v : v; };

  // per value: the torques, every column
  for (size_t j = 0; j < n; ++j) {
    CsvTable t;
    t.header.push_back("time");
    t.header.insert(t.header.end(), labels.begin(), labels.end());
    const osim::Storage& s = r.torques[j];
    for (int k = 0; k < s.numRows(); ++k) {
      std::vector<double> row = {s.time[static_cast<size_t>(k)]};
      for (int c = 0; c < s.data.cols(); ++c) row.push_back(s.data(k, c));
      t.addRow(row);
    }
    report.addTable("mass_sweep_tau_" + valueTag(base, values[j]), t,
                    "inverse dynamics with " + valueLabel(base, values[j]) +
                        (isTransfer(base) ? " of " + base.transfer_body + "'s mass in the muscles"
                                          : " of the physiological muscle mass") +
                        fmtG(" (%.4g kg in mass points)", r.points[j].muscle_mass));
  }

  // peaks and changes, long form
  CsvTable peaks;
  peaks.header = {"column", "value", "muscle_mass_kg", "peak", "peak_change_rel", "max_diff_rel"};
  for (size_t c = 0; c < an.columns.size(); ++c) {
    const MassSweepColumn& col = an.columns[c];
    for (size_t j = 0; j < n; ++j)
      peaks.addRow(col.name, {values[j], r.points[j].muscle_mass, col.peak[j], col.peak_change_rel[j], col.max_diff_rel[j]});
  }
  report.addTable("mass_sweep_peaks", peaks,
                  "per column and value: peak |tau|, its change relative to the zero-mass peak, and the "
                  "largest |tau(s) - tau(0)| relative to that peak");

  // the linear fit
  CsvTable fit;
  fit.header = {"column", "peak_zero", "has_effect", "r2", "nonlinearity_rel", "slope_max_rel"};
  for (const MassSweepColumn& col : an.columns)
    fit.addRow({col.name, formatNumber(col.peak_zero), col.has_effect ? "1" : "0", formatNumber(col.r2),
                formatNumber(col.nonlinearity_rel), formatNumber(col.slope_max_rel)});
  report.addTable("mass_sweep_fit", fit,
                  "tau(s) - tau(0) = b_k s fitted per frame through the origin; R^2 pooled over frames and values");

  // figures: the main columns' torque curves, one line per value (Fig. 6.17), and the peak
  // changes against the swept mass (Fig. 6.16's 0% vs 80%, for every value)
  std::vector<int> main_idx;
  for (const std::string& m : r.main_columns)
    for (size_t c = 0; c < labels.size(); ++c)
      if (labels[c] == m) main_idx.push_back(static_cast<int>(c));
  PlotFigure curves;
  curves.title = "inverse dynamics, muscle-mass sweep (" + what + ")";
  for (int c : main_idx) {
    PlotPanel p;
    p.title = labels[static_cast<size_t>(c)];
    p.xlabel = "time [s]";
    p.ylabel = "generalized force [N m or N]";
    for (size_t j = 0; j < n; ++j)
      p.lines.push_back(makePlotLine(valueLabel(base, values[j]), r.torques[j].time, column(r.torques[j].data, c)));
    curves.panels.push_back(std::move(p));
  }
  if (!curves.panels.empty())
    report.addPlot("mass_sweep_torques", curves, "torque curves of the main columns, one line per sweep value");
  PlotFigure change;
  change.title = "change of the inverse-dynamics torques with muscle mass";
  PlotPanel pk = makeXYPanel("peak |tau| change", what, "(peak(s) - peak(0)) / peak(0) [%]", {});
  PlotPanel md = makeXYPanel("largest change at any frame", what, "max |tau(s) - tau(0)| / peak(0) [%]", {});
  pk.key = md.key = "top left";
  for (int c : main_idx) {
    const MassSweepColumn& col = an.columns[static_cast<size_t>(c)];
    std::vector<double> x, y1, y2;
    for (size_t j = 0; j < n; ++j) {
      x.push_back(xOf(values[j]));
      y1.push_back(100 * col.peak_change_rel[j]);
      y2.push_back(100 * col.max_diff_rel[j]);
    }
    pk.lines.push_back(makePlotLine(col.name, x, y1, "linespoints"));
    md.lines.push_back(makePlotLine(col.name, x, y2, "linespoints"));
  }
  change.panels = {pk, md};
  if (!main_idx.empty())
    report.addPlot("mass_sweep_peak_change", change, "peak change and largest change against the swept muscle mass");

  // Simbody with muscle inertia at the largest value: engines agree to round-off
  if (r.simbody.ran)
    addSimbodyMassCheck(r.simbody.comparison, r.simbody.coreTorques(r.torques.back()), r.simbody.result, report,
                        r.simbody.not_counted);

  // Simbody at every value: engines and their inertial effects, the degradation toward s = 0
  if (!r.simbody_values.empty()) {
    CsvTable t;
    t.header = {"value", "ran", "worst_column", "max_rel", "agrees", "effect_max_rel", "effect_rel_to_effect", "counted"};
    bool all_agree = true, any_counted = false;
    std::string worst_detail;
    double worst = -1;
    for (const MassSweepSimbodyCheck& c : r.simbody_values) {
      const bool counted = c.not_counted.empty();
      std::string col;
      double max_rel = std::numeric_limits<double>::quiet_NaN();
      if (c.ran && c.comparison.worst >= 0) {
        const ColumnMetrics& w = c.comparison.metrics[static_cast<size_t>(c.comparison.worst)];
        col = w.name;
        max_rel = w.max_rel;
      }
      t.addRow({formatNumber(c.value), c.ran ? "1" : "0", col, formatNumber(max_rel),
                c.ran ? (c.comparison.passed ? "PASS" : "DIFFERS") : (c.failed ? "FAILED" : "skipped"),
                formatNumber(c.effect_max_rel), formatNumber(c.effect_rel_to_effect), counted ? "1" : "0"});
      if (!counted) continue;
      if (c.failed || (c.ran && !c.comparison.passed)) all_agree = false;
      if (c.ran || c.failed) any_counted = true;
      if (c.ran && max_rel > worst) {
        worst = max_rel;
        worst_detail = "worst at " + valueLabel(base, c.value) + ": `" + col + "` max/peak " + fmtG("%.3g", max_rel);
      }
    }
    report.addTable("mass_sweep_simbody", t,
                    "per sweep value: core vs Simbody with muscle inertia (max |d| / column peak), and the two "
                    "engines' inertial effects tau(s) - tau(0) against each other (relative to the zero-mass peak "
                    "and to the core's largest effect)");
    if (any_counted)
      report.addCheck("mass sweep: core equals Simbody with muscle inertia at every value", all_agree, worst_detail);
  }
  // the value 0 against OpenSim's own result (and any other reference)
  for (const Comparison& c : r.zero_vs_references) report.addComparison(c, "generalized force [N m or N]");

  // the zero check: the value 0 (massless points) against the plain zero-mass run
  if (an.zero_index >= 0)
    report.addCheck("mass sweep: the zero value reproduces the zero-mass result", an.zero_passed,
                    "max |tau(0) - tau_zero_mass| / peak = " + fmtG("%.3g", an.zero_max_rel) + " (tolerance " +
                        fmtG("%.3g", r.options.zero_tolerance) + ")");

  // summary.json
  JsonValue& js = report.section("mass_sweep");
  js["mode"] = osim::toString(base.source);
  if (isTransfer(base)) js["transfer_body"] = base.transfer_body;
  js["value_meaning"] = isTransfer(base) ? "fraction of the transfer body's mass moved into the muscles"
                                         : "scale of every muscle's physiological mass (density * value)";
  js["muscles"] = base.muscles;
  js["mass_points"] = base.mass_points;
  js["values"] = values;
  JsonValue mm = JsonValue::array(), nm = JsonValue::array(), secs = JsonValue::array();
  for (const MassSweepPoint& p : r.points) {
    mm.push(p.muscle_mass);
    nm.push(p.muscles_with_mass);
    secs.push(p.seconds);
  }
  js["muscle_mass_kg"] = mm;
  js["muscles_with_mass"] = nm;
  js["seconds"] = secs;
  js["main_columns"] = r.main_columns;
  // wrapping muscles at the largest value: how many carry mass, and why the others stay lumped
  if (!r.points.empty()) {
    const osim::WrapMassCount& wc = r.points.back().wrap;
    JsonValue wj = JsonValue::object();
    wj["wrap_mass"] = base.wrap_mass;
    wj["wrap_model"] = osim::toString(base.wrap.model);
    wj["wrapping_muscles"] = wc.wrapping;
    wj["with_mass"] = wc.with_mass;
    JsonValue lumped = JsonValue::array();
    for (const auto& [name, why] : wc.lumped) {
      JsonValue l = JsonValue::object();
      l["muscle"] = name;
      l["why"] = why;
      lumped.push(l);
    }
    wj["lumped"] = lumped;
    js["wrapping"] = wj;
  }
  JsonValue sbj = JsonValue::object();
  sbj["ran"] = r.simbody.ran;
  if (!r.simbody.ran) sbj["skipped"] = r.simbody.skipped.empty() ? "not requested" : r.simbody.skipped;
  sbj["value"] = r.simbody.value;
  if (!r.simbody.note.empty()) sbj["inertia_fallback"] = r.simbody.note;
  js["simbody_check"] = sbj;
  JsonValue sbv = JsonValue::array();
  for (const MassSweepSimbodyCheck& c : r.simbody_values) {
    JsonValue o = JsonValue::object();
    o["value"] = c.value;
    o["ran"] = c.ran;
    if (!c.skipped.empty()) o["skipped"] = c.skipped;
    if (c.ran) {
      o["agrees"] = c.comparison.passed;
      if (c.comparison.worst >= 0) o["worst_max_rel"] = num(c.comparison.metrics[static_cast<size_t>(c.comparison.worst)].max_rel);
    }
    o["effect_max_rel"] = num(c.effect_max_rel);
    o["effect_rel_to_effect"] = num(c.effect_rel_to_effect);
    o["counted_in_verdict"] = c.not_counted.empty();
    sbv.push(o);
  }
  js["simbody_values"] = sbv;
  JsonValue zr = JsonValue::array();
  for (const Comparison& c : r.zero_vs_references) {
    JsonValue o = JsonValue::object();
    o["name"] = c.name;
    o["reference"] = c.label_b;
    o["passed"] = c.passed;
    if (c.worst >= 0) {
      o["worst_column"] = c.metrics[static_cast<size_t>(c.worst)].name;
      o["worst_rms_rel"] = num(c.metrics[static_cast<size_t>(c.worst)].rms_rel);
      o["worst_max_rel"] = num(c.metrics[static_cast<size_t>(c.worst)].max_rel);
    }
    zr.push(o);
  }
  js["zero_vs_references"] = zr;
  JsonValue zc = JsonValue::object();
  zc["present"] = an.zero_index >= 0;
  zc["max_rel"] = num(an.zero_max_rel);
  zc["tolerance"] = r.options.zero_tolerance;
  zc["passed"] = an.zero_passed;
  js["zero_check"] = zc;
  js["r2_min"] = r.options.r2_min;
  js["r2_min_observed"] = num(an.r2_min_observed);
  js["r2_meets_min"] = std::isnan(an.r2_min_observed) || an.r2_min_observed >= r.options.r2_min;
  js["nonlinearity_max_rel"] = num(an.nonlinearity_max);
  js["linear_by_construction"] =
      "tau = M qddot - f is linear in the body inertias and mass-point masses, which are affine in the "
      "sweep value; tau(s) - tau(0) is exactly s times a per-frame vector, so R^2 = 1 and the "
      "nonlinearity are round-off";
  JsonValue& cols = js["columns"] = JsonValue::object();
  for (const MassSweepColumn& col : an.columns) {
    JsonValue& o = cols[col.name] = JsonValue::object();
    o["peak_zero"] = col.peak_zero;
    o["peak"] = numbers(col.peak);
    o["peak_change_rel"] = numbers(col.peak_change_rel);
    o["max_diff_rel"] = numbers(col.max_diff_rel);
    o["has_effect"] = col.has_effect;
    o["r2"] = num(col.r2);
    o["nonlinearity_rel"] = num(col.nonlinearity_rel);
    o["slope_max_rel"] = num(col.slope_max_rel);
  }

  // report.md
  std::ostringstream md_text;
  md_text << "Swept: " << what << ", values";
  for (double v : values) md_text << " " << valueLabel(base, v);
  md_text << ". Muscle mass in mass points:";
  for (const MassSweepPoint& p : r.points) md_text << " " << fmtG("%.4g", p.muscle_mass);
  md_text << " kg. The torque difference from the zero-mass result is fitted as b_k s per frame "
             "(through the origin); R^2 is pooled over every frame and value.\n\n";
  const size_t last = n - 1;
  md_text << "| column | zero-mass peak | peak change at " << valueLabel(base, values[last])
          << " | max change at " << valueLabel(base, values[last]) << " | R^2 | nonlinearity / peak |\n"
          << "|---|---|---|---|---|---|\n";
  for (const MassSweepColumn& col : an.columns)
    md_text << "| `" << col.name << "` | " << fmtG("%.4g", col.peak_zero) << " | "
            << fmtG("%+.2f%%", 100 * col.peak_change_rel[last]) << " | " << fmtG("%.2f%%", 100 * col.max_diff_rel[last])
            << " | " << (col.has_effect ? fmtG("%.12f", col.r2) : std::string("no effect")) << " | "
            << fmtG("%.2g", col.nonlinearity_rel) << " |\n";
  if (!r.simbody_values.empty()) {
    md_text << "\nSimbody with muscle inertia (plugin/simbody's own mass-point kinematics) at every value; the "
               "inertial effect tau(s) - tau(0) of each engine against the other's:\n\n| value | core vs Simbody "
               "max / peak | effect difference / peak | effect difference / effect |\n|---|---|---|---|\n";
    for (const MassSweepSimbodyCheck& c : r.simbody_values) {
      const double mr = c.ran && c.comparison.worst >= 0
                            ? c.comparison.metrics[static_cast<size_t>(c.comparison.worst)].max_rel
                            : std::numeric_limits<double>::quiet_NaN();
      md_text << "| " << valueLabel(base, c.value) << " | "
              << (c.ran ? fmtG("%.3g", mr) : std::string(c.failed ? "failed" : "skipped")) << " | "
              << fmtG("%.3g", c.effect_max_rel) << " | " << fmtG("%.3g", c.effect_rel_to_effect) << " |\n";
    }
  }
  for (const Comparison& c : r.zero_vs_references)
    if (c.worst >= 0)
      md_text << "\nThe value 0 (massless points) against " << c.label_b << ": worst `"
              << c.metrics[static_cast<size_t>(c.worst)].name << "` RMS / peak "
              << fmtG("%.3g", c.metrics[static_cast<size_t>(c.worst)].rms_rel) << " -> "
              << (c.passed ? "PASS" : "FAIL") << ".\n";
  md_text << "\nZero check (the value 0, massless points, against the plain zero-mass run): max |diff| / peak = "
          << fmtG("%.3g", an.zero_max_rel) << " -> " << (an.zero_passed ? "PASS" : "FAIL") << ".\n\n"
          << "Linear by construction: inverse dynamics is linear in the body inertias and the mass-point "
             "masses at fixed (q, qdot, qddot), and the sweep changes those affinely while the mass points "
             "keep their path fractions, so R^2 differs from 1 only by round-off (lowest R^2 "
          << fmtG("%.15g", an.r2_min_observed) << ", largest nonlinearity " << fmtG("%.2g", an.nonlinearity_max)
          << " of the peak).\n";
  if (!r.points.empty() && r.points.back().wrap.wrapping > 0)
    md_text << "\nWrapping muscles (wrap mass " << (base.wrap_mass ? "on, model " : "off, model ")
            << osim::toString(base.wrap.model) << "), at " << valueLabel(base, values[last]) << ":\n\n```\n"
            << formatWrapMassCount(r.points.back().wrap) << "```\n";
  report.addMarkdown("Muscle-mass sweep", md_text.str());
  if (!r.points.empty() && !r.points.back().description.empty())
    report.addMarkdown("Muscle mass at " + valueLabel(base, values[last]), "```\n" + r.points.back().description + "```\n");
}

std::string simbodyMassCheckNotCountedReason(const osim::MuscleMassOptions& options, const osim::WrapMassCount& wrap) {
  if (options.wrap.model == WrapModel::Exact && wrap.with_mass > 0)
    return "wrapping muscles carry mass over the exact wrap model, whose Jacobians both engines take by finite "
           "differences in different variables: they agree to the differences' truncation error, not to round-off";
  return "";
}

void addSimbodyMassCheck(const Comparison& c, const osim::Storage& core_mass, const osim::Storage& simbody_mass,
                         Report& report, const std::string& not_counted) {
  const bool counted = not_counted.empty();
  CsvTable t;
  t.header = {"column", "peak_ref", "rms", "max_abs", "t_max_abs", "rms_rel", "max_rel", "agrees"};
  for (const ColumnMetrics& m : c.metrics)
    t.addRow({m.name, formatNumber(m.peak_ref), formatNumber(m.rms), formatNumber(m.max_abs), formatNumber(m.t_max_abs),
              formatNumber(m.rms_rel), formatNumber(m.max_rel), m.passed ? "PASS" : "DIFFERS"});
  report.addTable(c.name + "_metrics", t,
                  std::string("core with muscle mass vs Simbody with muscle inertia (plugin/simbody), same model and "
                              "mass points") +
                      (counted ? "" : "; recorded, not counted in the verdict"));
  report.addOverlay(c.name + "_overlay", alignTables({&core_mass, &simbody_mass}, {c.label_a, c.label_b}),
                    "inverse dynamics with muscle mass: core vs Simbody", "generalized force [N m or N]");
  std::string worst;
  if (c.worst >= 0) {
    const ColumnMetrics& w = c.metrics[static_cast<size_t>(c.worst)];
    worst = "worst `" + w.name + "` max/peak " + fmtG("%.3g", w.max_rel) + ", RMS/peak " + fmtG("%.3g", w.rms_rel);
  }
  if (counted)
    report.addCheck("core with muscle mass equals Simbody with muscle inertia (" + c.name + ")", c.passed, worst);
  JsonValue& js = report.section("simbody_mass_check");
  js["name"] = c.name;
  js["agrees"] = c.passed;
  js["counted_in_verdict"] = counted;
  if (!counted) js["not_counted_because"] = not_counted;
  js["tolerance_max_rel"] = c.tolerance.max_rel;
  if (c.worst >= 0) {
    const ColumnMetrics& w = c.metrics[static_cast<size_t>(c.worst)];
    js["worst_column"] = w.name;
    js["worst_max_rel"] = num(w.max_rel);
    js["worst_rms_rel"] = num(w.rms_rel);
  }
  std::ostringstream md;
  md << "Simbody with muscle inertia (plugin/simbody: Simbody station kinematics and the core's path maps) "
        "solved the muscle-mass trial on the same model and mass points. "
     << (c.passed ? "It agrees with the core" : "It DIFFERS from the core") << " (tolerance "
     << fmtG("%.3g", c.tolerance.max_rel) << " of the column peak)";
  if (!worst.empty()) md << "; " << worst;
  if (counted)
    md << ". This check counts in the verdict.\n";
  else
    md << ". Recorded, not counted in the verdict: " << not_counted << ".\n";
  report.addMarkdown("Simbody with muscle inertia (cross-check)", md.str());
}

std::string formatSimbodyMassCheck(const Comparison& c, const std::string& not_counted) {
  std::ostringstream os;
  os << c.name << ": " << c.metrics.size() << " columns";
  if (c.worst >= 0) {
    const ColumnMetrics& w = c.metrics[static_cast<size_t>(c.worst)];
    os << "; worst " << w.name << " rms/peak " << fmtG("%.3g", w.rms_rel) << " max/peak " << fmtG("%.3g", w.max_rel);
  }
  os << " -> " << (c.passed ? (not_counted.empty() ? "PASS" : "agrees") : (not_counted.empty() ? "FAIL" : "DIFFERS"));
  if (!not_counted.empty()) os << " (not counted: exact wrap model, finite-difference Jacobians)";
  os << "\n";
  return os.str();
}

std::string formatWrapMassCount(const osim::WrapMassCount& c) {
  if (c.wrapping == 0) return "";
  std::ostringstream os;
  os << "wrapping (Type III): " << c.with_mass << " of " << c.wrapping << " carry mass\n";
  // one line per reason, in order of first appearance
  std::vector<std::pair<std::string, std::vector<std::string>>> by_why;
  for (const auto& [name, why] : c.lumped) {
    auto it = std::find_if(by_why.begin(), by_why.end(), [&](const auto& g) { return g.first == why; });
    if (it == by_why.end()) by_why.push_back({why, {name}});
    else it->second.push_back(name);
  }
  for (const auto& [why, names] : by_why) {
    os << "  lumped " << names.size() << ": " << why << " (";
    for (size_t j = 0; j < names.size() && j < 6; ++j) os << (j ? ", " : "") << names[j];
    if (names.size() > 6) os << ", ...";
    os << ")\n";
  }
  return os.str();
}

std::string formatMassSweepSummary(const MassSweepResult& r) {
  const osim::MuscleMassOptions& base = r.options.base;
  std::ostringstream os;
  os << "mass sweep (" << osim::toString(base.source) << (isTransfer(base) ? " " + base.transfer_body : "") << "):";
  for (const MassSweepPoint& p : r.points)
    os << " " << valueLabel(base, p.value) << " " << fmtG("%.4g", p.muscle_mass) << " kg;";
  os << "\n";
  const size_t last = r.options.values.size() - 1;
  for (const std::string& m : r.main_columns)
    for (const MassSweepColumn& col : r.analysis.columns)
      if (col.name == m)
        os << "  " << col.name << ": peak " << fmtG("%.4g", col.peak_zero) << " -> " << fmtG("%.4g", col.peak[last])
           << " (" << fmtG("%+.2f%%", 100 * col.peak_change_rel[last]) << "), max change "
           << fmtG("%.2f%%", 100 * col.max_diff_rel[last]) << " of the peak, R^2 "
           << (col.has_effect ? fmtG("%.12f", col.r2) : std::string("n/a (no effect)")) << "\n";
  if (!r.points.empty()) {
    std::istringstream wl(formatWrapMassCount(r.points.back().wrap));
    for (std::string line; std::getline(wl, line);) os << "  " << line << "\n";
  }
  if (r.simbody_values.size() > 1) {
    os << "  simbody with muscle inertia per value (max/peak; effect difference / effect):";
    for (const MassSweepSimbodyCheck& c : r.simbody_values) {
      os << " " << valueLabel(base, c.value) << " ";
      if (!c.ran) os << (c.failed ? "failed" : "skipped");
      else if (c.comparison.worst >= 0)
        os << fmtG("%.2g", c.comparison.metrics[static_cast<size_t>(c.comparison.worst)].max_rel) << "; "
           << fmtG("%.2g", c.effect_rel_to_effect);
      os << ",";
    }
    os << "\n";
  }
  for (const Comparison& c : r.zero_vs_references)
    if (c.worst >= 0)
      os << "  value 0 vs " << c.label_b << ": worst " << c.metrics[static_cast<size_t>(c.worst)].name << " rms/peak "
         << fmtG("%.3g", c.metrics[static_cast<size_t>(c.worst)].rms_rel) << " -> " << (c.passed ? "PASS" : "FAIL")
         << "\n";
  if (r.simbody.ran) os << "  " << formatSimbodyMassCheck(r.simbody.comparison, r.simbody.not_counted);
  else if (!r.simbody.skipped.empty()) os << "  simbody with muscle inertia: " << r.simbody.skipped << "\n";
  os << "  zero check: max |diff| / peak " << fmtG("%.3g", r.analysis.zero_max_rel) << " -> "
     << (r.analysis.zero_passed ? "PASS" : "FAIL") << "\n";
  return os.str();
}

}  // namespace redmax::validation
