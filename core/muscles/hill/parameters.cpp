#include "core/muscles/hill/parameters.hpp"

namespace redmax::hill {

double MuscleParameters::get(const std::string& key, double fallback) const {
  auto it = values.find(key);
  return it == values.end() ? fallback : it->second;
}

}  // namespace redmax::hill
