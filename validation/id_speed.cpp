#include "validation/id_speed.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <random>
#include <string>

#include "converter/id/core_id_engine.hpp"
#include "converter/storage.hpp"
#include "core/dynamics/skeleton_dynamics.hpp"
#include "plugin/simbody/id_engine.hpp"
#include "plugin/simbody/simbody_options.hpp"
#include "validation/simbody_cross_check.hpp"

namespace redmax::validation {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

struct Frame {
  double t = 0;
  VecX q, v, vdot;
  std::vector<osim::IdLoadSample> loads;
};

// fastest of `batches` solves of every frame, seconds
double timeEngine(osim::IdEngine& engine, const std::vector<Frame>& frames, int batches) {
  VecX tau;
  double best = std::numeric_limits<double>::infinity();
  for (int b = 0; b < batches; ++b) {
    const auto t0 = Clock::now();
    for (const Frame& f : frames) engine.calcGeneralizedForces(f.t, f.q, f.v, f.vdot, f.loads, tau);
    best = std::min(best, since(t0));
  }
  return best;
}

}  // namespace

IdSpeedResult timeIdEngines(const IdSpeedOptions& options) {
  IdSpeedResult r;
  const osim::IdToolConfig config = osim::resolveIdSettings(options.settings);
  r.model = config.model_file;

  // the whole `redmax id` run: read and process, solve with the core, write
  const auto t_setup = Clock::now();
  const osim::InverseDynamicsTool tool(config);
  r.setup_seconds = since(t_setup);
  {
    const auto t0 = Clock::now();
    osim::CoreIdEngine engine(tool.model(), tool.engineOptions());
    const osim::Storage out = tool.run(engine);
    const auto tmp = std::filesystem::temp_directory_path() /
                     ("redmax_id_speed_" + std::to_string(std::random_device{}()) + ".sto");
    osim::writeStorage(tmp.string(), out);
    std::filesystem::remove(tmp);
    r.whole_run_seconds = r.setup_seconds + since(t0);
  }

  r.frames = tool.numFrames();
  r.dofs = static_cast<int>(tool.model().nr());
  std::vector<Frame> frames(static_cast<size_t>(r.frames));
  for (int k = 0; k < r.frames; ++k) {
    Frame& f = frames[static_cast<size_t>(k)];
    f.t = tool.frameTime(k);
    tool.calcInputs(f.t, f.q, f.v, f.vdot, f.loads);
  }
  const int batches = std::max(1, options.batches);

  // both engines on the same model; Debian's Simbody rejects some inertias OpenSim keeps, and
  // then both get OpenSim's isotropic fallback (converter/build/inertia_fallback.hpp)
  Model model = tool.model();
  std::unique_ptr<osim::IdEngine> simbody;
  if (options.simbody) {
    try {
      SimbodyCrossCheckEngine built = makeSimbodyCrossCheckEngine(makeMusculoskeletalModel(model), tool.engineOptions());
      simbody = std::move(built.engine);
      if (built.usedFallback()) {
        model = built.fallback_model->skeleton();
        r.simbody_note = "both engines timed with OpenSim's isotropic fallback inertia on " + built.replacedBodies();
      }
    } catch (const std::exception& e) {
      r.simbody_note = std::string("Simbody cannot build the model: ") + e.what();
    }
  } else {
    r.simbody_note = "not requested";
  }
  osim::CoreIdEngine core(model, tool.engineOptions());
  osim::CoreIdEngine core_m(model, tool.engineOptions());
  core_m.setRoute(osim::CoreIdEngine::Route::MassMatrix);
  const double n = std::max(1, r.frames);
  r.core_us_per_frame = 1e6 * timeEngine(core, frames, batches) / n;
  r.core_mass_matrix_us = 1e6 * timeEngine(core_m, frames, batches) / n;
  if (simbody) r.simbody_us_per_frame = 1e6 * timeEngine(*simbody, frames, batches) / n;
  {
    // the floor: Newton-Euler on the same tree and frames, nothing else
    RecursiveIdWorkspace ws(model);
    State st;
    VecX tau;
    double best = std::numeric_limits<double>::infinity();
    for (int b = 0; b < batches; ++b) {
      const auto t0 = Clock::now();
      for (const Frame& f : frames) {
        st.q = f.q;
        st.qdot = f.v;
        inverseDynamicsRecursive(model, st, f.vdot, ws, tau);
      }
      best = std::min(best, since(t0));
    }
    r.bare_recursive_us = 1e6 * best / n;
  }
  if (options.muscle_mass.source != osim::MuscleMassOptions::Source::None) {
    // the same frames with muscle mass: the tool moves mass from the bones into the muscles
    osim::IdToolSettings s = options.settings;
    s.muscle_mass = options.muscle_mass;
    const osim::InverseDynamicsTool mtool(osim::resolveIdSettings(s));
    osim::CoreIdEngine rec(mtool.musculoskeletalModel(), mtool.engineOptions());
    osim::CoreIdEngine ref(mtool.musculoskeletalModel(), mtool.engineOptions());
    ref.setRoute(osim::CoreIdEngine::Route::MassMatrix);
    r.muscle_mass_kg = rec.muscleMass();
    for (const Muscle& m : mtool.musculoskeletalModel().muscles())
      if (m.mass_points.size() > 0) {
        ++r.mass_muscles;
        r.mass_points += m.mass_points.size();
      }
    r.core_mass_us = 1e6 * timeEngine(rec, frames, batches) / n;
    r.core_mass_matrix_mass_us = 1e6 * timeEngine(ref, frames, batches) / n;
  }
  return r;
}

std::string formatIdSpeed(const IdSpeedResult& r) {
  char buf[1024];
  std::string s;
  std::snprintf(buf, sizeof buf, "inverse dynamics on %s: %d frames, %d DoF\n", r.model.c_str(), r.frames, r.dofs);
  s += buf;
  if (r.simbody_us_per_frame > 0)
    std::snprintf(buf, sizeof buf, "  per frame (fastest batch): core %.2f us, Simbody %.2f us, ratio core/Simbody %.3f\n",
                  r.core_us_per_frame, r.simbody_us_per_frame, r.ratio());
  else
    std::snprintf(buf, sizeof buf, "  per frame (fastest batch): core %.2f us, Simbody -\n", r.core_us_per_frame);
  s += buf;
  if (!r.simbody_note.empty()) s += "  note: " + r.simbody_note + "\n";
  std::snprintf(buf, sizeof buf,
                "  core routes: recursive %.2f us, mass-matrix %.2f us; bare Newton-Euler on the same tree %.2f us "
                "(trial path / bare %.2f)\n",
                r.core_us_per_frame, r.core_mass_matrix_us, r.bare_recursive_us,
                r.bare_recursive_us > 0 ? r.core_us_per_frame / r.bare_recursive_us : 0.0);
  s += buf;
  if (r.core_mass_us > 0) {
    std::snprintf(buf, sizeof buf,
                  "  with muscle mass (%d muscles, %d points, %.3f kg): core recursive %.2f us, mass-matrix %.2f us",
                  r.mass_muscles, r.mass_points, r.muscle_mass_kg, r.core_mass_us, r.core_mass_matrix_mass_us);
    s += buf;
    if (r.simbody_us_per_frame > 0) {
      std::snprintf(buf, sizeof buf, "; recursive / Simbody massless %.3f", r.core_mass_us / r.simbody_us_per_frame);
      s += buf;
    }
    s += "\n";
  }
  std::snprintf(buf, sizeof buf,
                "  whole `redmax id` run (read, process, solve with core, write): %.3f s = %.3f s setup + %.2f ms "
                "for %d frames (%.0f frames/s after setup)\n",
                r.whole_run_seconds, r.setup_seconds, 1e3 * (r.whole_run_seconds - r.setup_seconds), r.frames,
                r.whole_run_seconds > r.setup_seconds ? r.frames / (r.whole_run_seconds - r.setup_seconds) : 0.0);
  s += buf;
  return s;
}

}  // namespace redmax::validation
