// `redmax demo`: the built-in double pendulum, integrated and reported with its energy.
// (Replaced by a bundled OpenSim model once the converter lands.)
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/flags.hpp"
#include "core/integrators/integrator.hpp"
#include "validation/scenes/scenes.hpp"

namespace redmax::cli {
namespace {

struct DemoFlags {
  std::string integrator = "euler";
  double dt = 1e-3, duration = 5.0, rtol = 1e-8, atol = 1e-10;
};

int runDemo(const DemoFlags& f) {
  IntegratorOptions opt;
  opt.dt = f.dt;
  opt.rtol = f.rtol;
  opt.atol = f.atol;
  const double T = f.duration;
  const std::string& name = f.integrator;

  System sys(scenes::doublePendulum());
  State s = sys.defaultState();
  s.q << 1.0, 0.5;  // released from rest
  auto integ = makeIntegrator(name, opt);
  DynamicsWorkspace ws(sys.model());
  const double E0 = sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
  std::printf("double pendulum, %s integrator, dt %g s, %g s simulated\n", name.c_str(), opt.dt, T);
  std::printf("%8s %12s %12s %14s %14s %14s\n", "t", "q1", "q2", "kinetic", "potential", "total");
  const int n_out = 10;
  for (int k = 0; k <= n_out; ++k) {
    if (k > 0) integ->advance(sys, s, T * k / n_out);
    const double K = sys.kineticEnergy(s, ws), V = sys.potentialEnergy(s, ws);
    std::printf("%8.3f %12.6f %12.6f %14.8f %14.8f %14.8f\n", s.t, s.q[0], s.q[1], K, V, K + V);
  }
  const double E1 = sys.kineticEnergy(s, ws) + sys.potentialEnergy(s, ws);
  std::printf("relative energy change over %g s: %.3e (%ld steps, %ld force evaluations)\n", T,
              (E1 - E0) / std::abs(E0), integ->stats().steps, integ->stats().rhs_evals);
  return 0;
}

CommandRegistration reg({"demo", "run the built-in double pendulum and print its energy", [](CLI::App& app) {
                           auto f = std::make_shared<DemoFlags>();
                           app.add_option("--integrator", f->integrator, "integrator (default euler)")
                               ->type_name("euler|symplectic|bdf1|sdirk2|rk45|cvode")
                               ->check(oneOf({"euler", "symplectic", "bdf1", "sdirk2", "rk45", "cvode"}));
                           app.add_option("--dt", f->dt, "step in seconds (default 0.001)")
                               ->type_name("S")
                               ->check(positive());
                           app.add_option("--duration", f->duration, "simulated seconds (default 5)")
                               ->type_name("S")
                               ->check(positive());
                           app.add_option("--rtol", f->rtol, "relative tolerance of rk45/cvode (default 1e-8)")
                               ->type_name("R")
                               ->check(number());
                           app.add_option("--atol", f->atol, "absolute tolerance of rk45/cvode (default 1e-10)")
                               ->type_name("A")
                               ->check(number());
                           app.footer(
                               "Integrates a double pendulum released from rest at q = (1, 0.5) rad and prints q and the\n"
                               "kinetic, potential and total energy at 10 instants.");
                           return [f] { return runDemo(*f); };
                         }});

}  // namespace
}  // namespace redmax::cli
