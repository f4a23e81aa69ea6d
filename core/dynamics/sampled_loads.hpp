#pragma once
// External loads that change with time, as a ForceTerm (an OpenSim ExternalLoads file in a
// forward run, docs/forward.md §4): at every evaluation the sampler gives the loads at s.t and
// they are applied as OpenSim's ExternalForce applies them (resolveLoads: the force at the body
// station where the point is now, the torque as a pure torque). Explicit, no potential (the
// loads are given functions of time, not of the configuration).
#include <functional>
#include <string>
#include <vector>

#include "core/dynamics/id_engine.hpp"

namespace redmax {

class SampledLoadsTerm final : public ForceTerm {
 public:
  /// fills the loads at time t (cleared first); must be safe to call from several threads
  using Sampler = std::function<void(double t, std::vector<IdLoadSample>& loads)>;
  explicit SampledLoadsTerm(Sampler sampler, std::string name = "external_loads")
      : sampler_(std::move(sampler)), name_(std::move(name)) {}
  std::string name() const override { return name_; }
  bool addsMass() const override { return false; }
  void addForce(const Model& model, const State& s, const TermContext& ctx, VecX& f) const override {
    std::vector<IdLoadSample> samples;
    sampler_(s.t, samples);
    ExternalLoads loads;
    resolveLoads(samples, ctx.sk.E_wi, loads);
    addExternalLoads(model, ctx.sk, loads, f);
  }

 private:
  Sampler sampler_;
  std::string name_;
};

}  // namespace redmax
