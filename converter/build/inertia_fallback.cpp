#include "converter/build/inertia_fallback.hpp"

#include <cmath>
#include <limits>

#include "core/spatial/se3.hpp"

namespace redmax::osim {

bool isValidInertia(const Mat3& I) {
  if (!I.allFinite()) return false;
  const double xx = I(0, 0), yy = I(1, 1), zz = I(2, 2);
  if (!(xx >= 0.0 && yy >= 0.0 && zz >= 0.0)) return false;
  // NTraits<double>::getSignificant() = eps^(7/8)
  const double slop =
      std::max(xx + yy + zz, 1.0) * std::pow(std::numeric_limits<double>::epsilon(), 0.875);
  if (!(xx + yy + slop >= zz && xx + zz + slop >= yy && yy + zz + slop >= xx)) return false;
  return xx + slop >= std::abs(2.0 * I(1, 2)) && yy + slop >= std::abs(2.0 * I(0, 2)) &&
         zz + slop >= std::abs(2.0 * I(0, 1));
}

Mat3 openSimFallbackInertia(const Mat3& I) {
  const double diag = I.diagonal().norm() / std::sqrt(3.0);
  return diag * Mat3::Identity();
}

std::vector<std::string> applyOpenSimInertiaFallback(Model& model) {
  std::vector<std::string> changed;
  ModelBuilder edit(model);
  for (int i = 0; i < model.nb(); ++i) {
    const Body& b = model.bodies()[i];
    if (b.mass == 0.0 || isValidInertia(b.inertia_com)) continue;
    edit.setBodyMassProperties(i, b.mass, b.com, openSimFallbackInertia(b.inertia_com));
    changed.push_back(b.name);
  }
  // the builder derives the spatial inertias of the changed bodies
  if (!changed.empty()) model = edit.finalize();
  return changed;
}

std::vector<std::string> applyOpenSimInertiaFallback(MusculoskeletalModel& model) {
  Model skeleton = model.skeleton();
  std::vector<std::string> changed = applyOpenSimInertiaFallback(skeleton);
  if (changed.empty()) return changed;
  MusculoskeletalModelBuilder edit(model);
  edit.setSkeleton(skeleton);
  model = edit.finalize();
  return changed;
}

}  // namespace redmax::osim
