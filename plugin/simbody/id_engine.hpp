#pragma once
// The Simbody engine (core/dynamics/id_engine.hpp) of the inverse-dynamics tool
// (converter/id/inverse_dynamics_tool.hpp): the
// core model rebuilt as a Simbody system (model_to_simbody.hpp) and solved as OpenSim's
// InverseDynamicsSolver does, with SimbodyMatterSubsystem::calcResidualForceIgnoringConstraints:
//   tau_u = M udot + c(q, u) - (gravity + external loads as station forces and body torques).
// Joints marked IdEngineOptions::rates_as_u become Ball/Free mobilizers whose u and udot are the
// given rates as they are (what OpenSim does); for the others u = T qdot, udot = T qddot + Tdot
// qdot and tau = T^T tau_u (model_to_simbody.hpp's velocity map), so both engines answer in the
// same convention. With muscles that carry mass points (the MusculoskeletalModel constructor), their generalized
// forces from plugin/simbody/muscle_inertia.hpp (Simbody station kinematics + the core's path
// maps) are added to Simbody's residual in u space before the map back. The header is Simbody-free (pimpl) so that the command line compiles quickly.
#include <memory>
#include <string>
#include <vector>

#include "core/dynamics/id_engine.hpp"
#include "core/model/musculoskeletal_model.hpp"
#include "core/skeleton/model.hpp"

namespace redmax::simbody {

class SimbodyIdEngine final : public IdEngine {
 public:
  /// Builds the Simbody system (Ball mobilizers for spherical joints when any of them is marked,
  /// Gimbal otherwise). Throws SimbodyBuildError (simbody_options.hpp) when the model has a joint
  /// without a Simbody counterpart, or a marked joint whose mobilizer has u = qdot (not Ball/Free).
  explicit SimbodyIdEngine(const Model& model, const IdEngineOptions& options = {});
  /// The model's skeleton, plus the inertia and weight of its muscles' mass points (muscles
  /// without mass points add nothing). Throws ModelError for a muscle that does not fit the model
  /// (validateMuscle); calcGeneralizedForces throws IdEngineError naming the muscle when its path
  /// degenerates at a frame (e.g. coincident consecutive path points).
  explicit SimbodyIdEngine(const MusculoskeletalModel& model, const IdEngineOptions& options = {});
  ~SimbodyIdEngine() override;
  SimbodyIdEngine(const SimbodyIdEngine&) = delete;
  SimbodyIdEngine& operator=(const SimbodyIdEngine&) = delete;

  std::string name() const override { return "simbody"; }
  void calcGeneralizedForces(double t, const VecX& q, const VecX& v, const VecX& vdot,
                             const std::vector<IdLoadSample>& loads, VecX& tau) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace redmax::simbody
