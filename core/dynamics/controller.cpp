#include "core/dynamics/controller.hpp"

#include <algorithm>

namespace redmax {

void PrescribedControls::addControls(const Model&, const State& s, const SkeletonWorkspace&,
                                     Eigen::Ref<VecX> u) const {
  VecJ x(1);
  x[0] = s.t;
  FunctionValue v;
  for (const Entry& e : entries_) {
    if (e.control < 0 || e.control >= u.size() || !e.function) continue;
    e.function->evaluate(x, 0, v);
    u[e.control] += v.value;
  }
}

void ProportionalController::addControls(const Model&, const State& s, const SkeletonWorkspace&,
                                         Eigen::Ref<VecX> u) const {
  for (const Rule& r : rules_) {
    if (r.control < 0 || r.control >= u.size() || r.coordinate < 0 || r.coordinate >= s.q.size()) continue;
    const double e = r.bias + r.kp * (r.target - s.q[r.coordinate]) - r.kd * s.qdot[r.coordinate];
    u[r.control] += std::clamp(e, r.min, r.max);
  }
}

}  // namespace redmax
