#include "core/integrators/integrator.hpp"

#include <cmath>
#include <sstream>

#include "core/integrators/symplectic_euler.hpp"

namespace redmax {

std::unique_ptr<Integrator> makeIntegrator(const std::string& name, const IntegratorOptions& opt) {
  if (name == "euler") return std::make_unique<SymplecticEuler>(opt);
  throw std::invalid_argument("unknown integrator '" + name +
                              "' (expected euler, bdf1, sdirk2, rk45 or cvode)");
}

void checkFinite(const State& s, double h, const char* where) {
  for (int k = 0; k < s.q.size(); ++k) {
    if (!std::isfinite(s.q[k]) || !std::isfinite(s.qdot[k])) {
      std::ostringstream os;
      os << where << ": non-finite " << (std::isfinite(s.q[k]) ? "qdot" : "q") << "[" << k
         << "] at t = " << s.t << " with step h = " << h;
      throw SimulationError(os.str(), s.t, h);
    }
  }
}

}  // namespace redmax
