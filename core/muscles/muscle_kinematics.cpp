#include "core/muscles/muscle_kinematics.hpp"

#include "core/muscles/wrap_muscle.hpp"

namespace redmax {

void calcMuscleKinematics(const Model& model, const State& state, const SkeletonWorkspace& sk,
                          const Muscle& muscle, MuscleKinematics& mk, bool velocity) {
  calcMuscleKinematics(model, state, sk, muscle, mk, velocity, FibreStates{});
}

void calcMuscleKinematics(const Model& model, const State& state, const SkeletonWorkspace& sk,
                          const Muscle& muscle, MuscleKinematics& mk, bool velocity, const FibreStates& fs) {
  const MassPoints& mp = muscle.mass_points;
  if (muscle.fibre.enabled() && mp.size() > 0) {
    // fibre-following placement (Type I/II only, validateMuscle)
    calcPathPoints(model, state, sk, muscle.path, mk, velocity);
    const TendonKinematics tk = calcTendonKinematics(muscle, mk.length, velocity ? mk.lengthening_speed : 0.0, fs, velocity);
    calcFibreMassPoints(muscle.fibre.c, tk, mk, muscle.name);
    return;
  }
  const bool wrapping = mp.size() > 0 && pathType(muscle.path) == PathType::III;
  // Type III with mass: the wrap surface's body joins the columns (core/muscles/wrap_muscle.hpp)
  if (wrapping) initWrapMuscleColumns(model, muscle, mk);
  calcPathPoints(model, state, sk, muscle.path, mk, velocity);
  if (mp.size() == 0) return;
  if (wrapping) {
    calcWrapMassPoints(model, state, sk, muscle, mk);
    return;
  }
  calcMassPointStage(mp, mk, muscle.name);
}

void calcMassPointStage(const MassPoints& mp, MuscleKinematics& mk, const std::string& muscle_name) {
  // two active points: Type I [D Sec. 5.3.1]; more: EOL [D Sec. 5.3.2]
  if (mk.x_w.size() == 2) {
    if (!(mk.length > 0.0))
      throw MuscleError("muscle '" + muscle_name + "': origin and insertion coincide here; mass points need a path of positive length");
    calcStraightMassPoints(mp, mk);
    return;
  }
  calcEulerianCoordinates(mk, muscle_name);
  calcViaPointMassPoints(mp, mk);
}

void calcMuscleKinematics(const Model& model, const State& state, const SkeletonWorkspace& sk,
                          const std::vector<Muscle>& muscles, MuscleWorkspace& ws, bool velocity) {
  if (ws.muscles.size() != muscles.size()) ws = MuscleWorkspace(model, muscles);
  for (size_t m = 0; m < muscles.size(); ++m)
    calcMuscleKinematics(model, state, sk, muscles[m], ws.muscles[m], velocity);
}

double muscleKineticEnergy(const MassPoints& mp, const MuscleKinematics& mk, const VecX& qdot) {
  const VecX qdot_c = gatherColumns(qdot, mk);  // J_ar has the compact columns
  const bool fibre = mk.v_z.size() == 3 * mp.size() && mp.size() > 0;
  double T = 0.0;
  for (int a = 0; a < mp.size(); ++a) {
    Vec3 v = mk.J_ar.middleRows<3>(3 * a) * qdot_c;
    if (fibre) v += mk.v_z.segment<3>(3 * a);
    T += 0.5 * mp.mass[a] * v.squaredNorm();
  }
  return T;
}

double musclePotentialEnergy(const MassPoints& mp, const MuscleKinematics& mk, const Vec3& gravity) {
  double V = 0.0;
  for (int a = 0; a < mp.size(); ++a) V -= mp.mass[a] * gravity.dot(mk.x_a[a]);
  return V;
}

}  // namespace redmax
