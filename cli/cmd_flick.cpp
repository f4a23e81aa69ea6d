// `redmax flick`: the finger-flick stability study of [D Sec. 6.2.5] (validation/simulate/
// finger_flick.hpp): the largest fingertip force the lumped and the inertial finger survive, per
// integrator, found by bisection. Prints a markdown table; --csv writes it atomically.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "converter/atomic_file.hpp"
#include "validation/simulate/finger_flick.hpp"

namespace redmax::cli {
namespace {


int runFlick(const std::vector<std::string>& argv) {
  const Args a(argv, {"model", "integrators", "gravity", "mass", "dt", "dts", "duration", "impulse-time", "target",
                      "energy-growth", "csv"},
               {});
  if (!a.positionals().empty()) throw UsageError{"flick takes no positional arguments"};
  if (!a.has("model")) throw UsageError{"flick needs --model (e.g. osim_models/finger.osim)"};
  validation::FlickOptions o;
  o.model_path = *a.get("model");
  o.dt = a.getDouble("dt", 1e-3);
  o.duration = a.getDouble("duration", 1.0);
  o.impulse_time = a.getDouble("impulse-time", 2e-3);
  o.energy_growth = a.getDouble("energy-growth", 0.5);
  o.target = a.get("target", "fingertip");
  const double mass = a.getDouble("mass", 0.2);
  if (!(o.dt > 0) || !(o.duration > 0) || !(o.impulse_time > 0) || !(o.energy_growth > 0) || !(mass > 0))
    throw UsageError{"--dt, --duration, --impulse-time, --energy-growth and --mass must be positive"};
  std::vector<double> dts;
  if (auto v = a.get("dts")) {
    if (a.has("dt")) throw UsageError{"give --dt or --dts, not both"};
    for (const std::string& t : splitList(*v)) {
      char* end = nullptr;
      const double x = std::strtod(t.c_str(), &end);
      if (end == t.c_str() || *end != '\0' || !(x > 0.0) || !std::isfinite(x))
        throw UsageError{"--dts expects positive step sizes S1,S2,..., got '" + t + "'"};
      dts.push_back(x);
    }
  }
  const std::vector<std::string> integrators = splitList(a.get("integrators", "euler,symplectic"));
  for (const auto& n : integrators)
    if (n != "euler" && n != "symplectic" && n != "bdf1" && n != "sdirk2" && n != "rk45" && n != "cvode")
      throw UsageError{"--integrators: unknown integrator '" + n + "'"};
  const std::string g = a.get("gravity", "on");
  std::vector<bool> gravity;
  if (g == "on") gravity = {true};
  else if (g == "off") gravity = {false};
  else if (g == "both") gravity = {true, false};
  else throw UsageError{"--gravity must be on, off or both"};

  const auto rows = validation::runFlickStudy(o, integrators, gravity, mass, dts);
  std::printf("finger flick: force on '%s' along +y for %g s, then %g s of fixed steps; inertial = %g kg in each of "
              "FDP and FDS\n%s",
              o.target.c_str(), o.impulse_time, o.duration, mass, validation::formatFlickTable(rows).c_str());
  if (auto csv = a.get("csv")) osim::writeFileAtomic(*csv, validation::formatFlickCsv(rows));
  return 0;
}

CommandRegistration reg(
    {"flick", "finger-flick stability study: largest fingertip force survived, lumped vs inertial",
     "usage: redmax flick --model finger.osim [--integrators euler,symplectic] [--gravity on|off|both]\n"
     "                    [--mass KG] [--dt S | --dts S1,S2,...] [--duration S] [--impulse-time S]\n"
     "                    [--target MARKER] [--energy-growth F] [--csv OUT.csv]\n"
     "The study of the dissertation's 6.2.5: a force along +y (ground frame) on the fingertip for the\n"
     "first --impulse-time seconds (default 0.002: two 1 ms steps), then --duration s (1) of fixed steps\n"
     "--dt (0.001; --dts gives a row set per step size, the flick keeping its duration). Variants:\n"
     "lumped (the model as is) and inertial (--mass kg, default 0.2, in each of\n"
     "FDP and FDS, added). A run fails on a NaN/divergence or, for the artifact column, when the total\n"
     "energy rises above its value after the flick by more than F (default 0.5) times the largest\n"
     "kinetic energy seen. Forces: a doubling scan from 0.5 N to 2 kN, then bisection to 1%.\n",
     runFlick});

}  // namespace
}  // namespace redmax::cli
