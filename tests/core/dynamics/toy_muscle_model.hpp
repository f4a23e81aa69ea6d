#pragma once
// A test-only hill::MuscleModel with the shape of a Hill model but trivial equations, for the
// forward-simulation tests before and beside the real models (docs/forward.md):
//   states    activation a, fiber_length lf
//   adot    = (clamp(u, 0, 1) - a) / tau                          (first-order activation)
//   tendon    F_t = k (l - lf - l_ts)                            (linear tendon)
//   fibre     F_t = a F0 + b lfdot   =>   lfdot = (F_t - a F0) / b (linear damper in parallel)
// equilibrate: lfdot = 0 and speed shared by fibre and tendon, i.e. lf with F_t = a F0.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/muscles/hill/muscle_model.hpp"

namespace redmax::test {

class ToyMuscleModel final : public hill::MuscleModel {
 public:
  double tau = 0.02, k = 2e4, F0 = 200.0, b = 500.0, l_ts = 0.2;
  double a0 = 0.05, lf0 = 0.1;
  bool with_fiber = true;  // false: activation only (a rigid tendon at the fibre's default length)
  bool nan_rate = false;   // the activation's rate is NaN (the integrators must name the state)

  std::string className() const override { return "ToyMuscle"; }
  const std::vector<std::string>& stateNames() const override {
    static const std::vector<std::string> both = {"activation", "fiber_length"}, act = {"activation"};
    return with_fiber ? both : act;
  }
  void defaultState(double* z) const override {
    z[0] = a0;
    if (with_fiber) z[1] = lf0;
  }
  void calc(const double* z, const hill::MusculotendonInput& in, hill::MuscleOutput& out,
            double* zdot) const override {
    const double a = z[0];
    const double lf = with_fiber ? z[1] : lf0;
    out.activation = a;
    out.fiber_length = lf;
    out.tendon_length = in.length - lf;
    out.tendon_force = k * (out.tendon_length - l_ts);
    out.fiber_velocity = with_fiber ? (out.tendon_force - a * F0) / b : 0.0;
    zdot[0] = nan_rate ? std::nan("") : (std::clamp(in.excitation, 0.0, 1.0) - a) / tau;
    if (with_fiber) zdot[1] = out.fiber_velocity;
  }
  void equilibrate(const hill::MusculotendonInput& in, double* z) const override {
    if (!with_fiber) return;
    z[1] = in.length - l_ts - z[0] * F0 / k;
  }
};

}  // namespace redmax::test
