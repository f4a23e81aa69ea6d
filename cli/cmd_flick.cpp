// `redmax flick`: the finger-flick stability study of [D Sec. 6.2.5] (validation/simulate/
// finger_flick.hpp): the largest fingertip force the lumped and the inertial finger survive, per
// integrator, found by bisection. Prints a markdown table; --csv writes it atomically.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "cli/flags.hpp"
#include "converter/atomic_file.hpp"
#include "validation/simulate/finger_flick.hpp"

namespace redmax::cli {
namespace {


struct FlickFlags {
  validation::FlickOptions o;
  std::string integrators = "euler,symplectic", gravity = "on", dts, csv;
  double mass = 0.2;
};

int runFlick(FlickFlags& f, const CLI::App& app) {
  if (!given(app, "--model")) throw UsageError{"flick needs --model (e.g. osim_models/finger.osim)"};
  validation::FlickOptions& o = f.o;
  std::vector<double> dts;
  if (given(app, "--dts")) {
    if (given(app, "--dt")) throw UsageError{"give --dt or --dts, not both"};
    for (const std::string& t : splitList(f.dts)) {
      char* end = nullptr;
      const double x = std::strtod(t.c_str(), &end);
      if (end == t.c_str() || *end != '\0' || !(x > 0.0) || !std::isfinite(x))
        throw UsageError{"--dts expects positive step sizes S1,S2,..., got '" + t + "'"};
      dts.push_back(x);
    }
  }
  const std::vector<std::string> integrators = splitList(f.integrators);
  for (const auto& n : integrators)
    if (n != "euler" && n != "symplectic" && n != "bdf1" && n != "sdirk2" && n != "rk45" && n != "cvode")
      throw UsageError{"--integrators: unknown integrator '" + n + "'"};
  if (!o.joint_limits.empty())
    for (const auto& n : integrators)
      if (n != "bdf1") throw UsageError{"--joint-limits needs --integrators bdf1 (the step with the contact QP), got '" + n + "'"};
  if (given(app, "--limit-restitution") && o.joint_limits.empty()) throw UsageError{"--limit-restitution needs --joint-limits"};
  std::vector<bool> gravity;
  if (f.gravity == "on") gravity = {true};
  else if (f.gravity == "off") gravity = {false};
  else gravity = {true, false};

  const auto rows = validation::runFlickStudy(o, integrators, gravity, f.mass, dts);
  std::printf("finger flick: force on '%s' along +y for %g s, then %g s of fixed steps; inertial = %g kg in each of "
              "FDP and FDS; joint ranges %s\n%s",
              o.target.c_str(), o.impulse_time, o.duration, f.mass,
              o.joint_limits.empty() ? "free (not enforced)" : ("enforced (--joint-limits " + o.joint_limits + ")").c_str(),
              validation::formatFlickTable(rows).c_str());
  if (given(app, "--csv")) osim::writeFileAtomic(f.csv, validation::formatFlickCsv(rows));
  return 0;
}

CommandRegistration reg(
    {"flick", "finger-flick stability study: largest fingertip force survived, lumped vs inertial",
     [](CLI::App& app) {
       auto f = std::make_shared<FlickFlags>();
       f->o.dt = 1e-3;
       f->o.duration = 1.0;
       f->o.impulse_time = 2e-3;
       f->o.energy_growth = 0.5;
       f->o.target = "fingertip";
       app.add_option("--model", f->o.model_path, "the finger model (e.g. osim_models/finger.osim); required")
           ->type_name("FILE");
       app.add_option("--integrators", f->integrators,
                      "comma-separated subset of euler,symplectic,bdf1,sdirk2,rk45,cvode\n(default euler,symplectic)")
           ->type_name("LIST");
       app.add_option("--gravity", f->gravity, "on (default), off or both (a row set each)")
           ->type_name("on|off|both")
           ->check(oneOf({"on", "off", "both"}));
       app.add_option("--mass", f->mass, "kg in each of FDP and FDS for the inertial variant (default 0.2)")
           ->type_name("KG")
           ->check(positive());
       app.add_option("--dt", f->o.dt, "fixed step in seconds (default 0.001)")->type_name("S")->check(positive());
       app.add_option("--dts", f->dts, "a row set per step size (excludes --dt), the flick keeping its duration")
           ->type_name("S1,S2,...");
       app.add_option("--duration", f->o.duration, "seconds of fixed steps after the flick (default 1)")
           ->type_name("S")
           ->check(positive());
       app.add_option("--impulse-time", f->o.impulse_time,
                      "seconds the force acts (default 0.002: two 1 ms steps)")
           ->type_name("S")
           ->check(positive());
       app.add_option("--target", f->o.target, "the marker the force acts on (default fingertip)")->type_name("MARKER");
       app.add_option("--energy-growth", f->o.energy_growth,
                      "artifact column: a run fails when the total energy rises above its value\n"
                      "after the flick by more than F times the largest kinetic energy (default 0.5)")
           ->type_name("F")
           ->check(positive());
       app.add_option("--csv", f->csv, "also write the table as CSV (atomically)")->type_name("OUT.csv");
       app.add_option("--joint-limits", f->o.joint_limits,
                      "hard: every coordinate's range, clamped: the clamped ones, as hard limits (bdf1 only)")
           ->type_name("hard|clamped")
           ->check(oneOf({"hard", "clamped"}));
       app.add_option("--limit-restitution", f->o.limit_restitution, "restitution at the limits (default 0)")
           ->type_name("E")
           ->check(CLI::Range(0.0, 1.0));
       app.footer(
           "usage: redmax flick --model finger.osim [--integrators euler,symplectic] [--gravity on|off|both]\n"
           "                    [--mass KG] [--dt S | --dts S1,S2,...] [--duration S] [--impulse-time S]\n"
           "                    [--target MARKER] [--energy-growth F] [--csv OUT.csv]\n"
           "                    [--joint-limits hard|clamped [--limit-restitution E]]\n"
           "The study of the dissertation's 6.2.5: a force along +y (ground frame) on the fingertip for the\n"
           "first --impulse-time seconds, then --duration s of fixed steps --dt. Variants: lumped (the model\n"
           "as is) and inertial (--mass kg in each of FDP and FDS, added). A run fails on a NaN/divergence\n"
           "or, for the artifact column, on the energy growth above. Forces: a doubling scan from 0.5 N to\n"
           "2 kN, then bisection to 1%.");
       return [f, &app] { return runFlick(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
