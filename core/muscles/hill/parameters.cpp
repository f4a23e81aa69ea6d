#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill {

double MuscleParameters::get(const std::string& key, double fallback) const {
  auto it = values.find(key);
  return it == values.end() ? fallback : it->second;
}

CurvePtr MuscleParameters::curveOr(const std::string& key, const std::vector<double>& x,
                                   const std::vector<double>& y) const {
  if (auto it = curves.find(key); it != curves.end() && it->second) return it->second;
  if (!simm_spline)
    throw MuscleParameterError(key, "muscle '" + name + "': " + key +
                                        " is absent and no spline factory was given for its default");
  return simm_spline(x, y);
}

}  // namespace redmax::hill
