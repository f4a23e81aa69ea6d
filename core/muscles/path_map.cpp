#include "core/muscles/path_map.hpp"

#include <stdexcept>

#include "core/muscles/muscle_kinematics.hpp"
#include "core/muscles/path_kinematics.hpp"

namespace redmax {

void calcPathMap(const std::vector<Vec3>& x, const std::vector<Vec3>* xdot, const MassPoints& mp,
                 PathMap& pm, const std::string& muscle_name) {
  const int P = static_cast<int>(x.size());
  if (P < 2) throw std::invalid_argument("calcPathMap: muscle '" + muscle_name + "' needs at least two path points");
  if (xdot && static_cast<int>(xdot->size()) != P)
    throw std::invalid_argument("calcPathMap: muscle '" + muscle_name + "': " + std::to_string(P) +
                                " points but " + std::to_string(xdot->size()) + " velocities");
  if (mp.size() == 0) throw std::invalid_argument("calcPathMap: muscle '" + muscle_name + "' has no mass points");
  const bool velocity = xdot != nullptr;

  // path stage in point coordinates: x_w = x, J_xr = I, Jdot_xr = 0 (the points are the coordinates)
  MuscleKinematics& mk = pm.mk;
  if (static_cast<int>(mk.active.size()) != P) {
    mk.active.resize(P);
    for (int i = 0; i < P; ++i) mk.active[i] = i;
    mk.J_xr.setIdentity(3 * P, 3 * P);
    mk.Jdot_xr.setZero(3 * P, 3 * P);
  }
  mk.x_w = x;
  if (velocity) mk.xdot_w = *xdot;
  mk.velocity = velocity;
  calcPathSegments(mk, velocity);

  // mass points: J_ar of this mk is J_ax, its Jdot_ar is Jdot_ax (Jdot_xr = 0) [D Eq. 5.5]
  calcMassPointStage(mp, mk, muscle_name);
  pm.x_a = mk.x_a;
  pm.J_ax = mk.J_ar;
  pm.velocity = velocity;
  if (!velocity) return;
  pm.Jdot_ax = mk.Jdot_ar;
  pm.Jdot_ax_xdot.noalias() = pm.Jdot_ax * stackPoints(*xdot);
}

VecX calcMassPointAccelerations(const PathMap& pm, const VecX& xddot) {
  if (!pm.velocity) throw std::logic_error("calcMassPointAccelerations: the path map has no velocity stage");
  if (xddot.size() != pm.J_ax.cols())
    throw std::invalid_argument("calcMassPointAccelerations: " + std::to_string(xddot.size()) +
                                " entries for " + std::to_string(pm.J_ax.cols()) + " point coordinates");
  return pm.J_ax * xddot + pm.Jdot_ax_xdot;
}

VecX stackPoints(const std::vector<Vec3>& x) {
  VecX v(3 * static_cast<int>(x.size()));
  for (size_t i = 0; i < x.size(); ++i) v.segment<3>(3 * static_cast<int>(i)) = x[i];
  return v;
}

}  // namespace redmax
