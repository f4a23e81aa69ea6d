#pragma once
// Where muscle mass comes from (docs/muscle_mass.md, MUSCLE-MASS OPTIONS; [D Sec. 6.2.8-6.2.9]). No body mass
// is created or lost: every kilogram given to a muscle's mass points is taken from a body.
//
//   none           the model as OpenSim sees it (muscles lumped into the bones).
//   physiological  m = density * (max_isometric_force / specific_tension) * optimal_fiber_length
//                  (PCSA * l_opt * rho). Each mass point's mass is removed from the body it was
//                  lumped into: among the bodies with mass on the tree path between the bodies of
//                  the muscle's path points (its span, ground excluded), the one whose bone is
//                  nearest to the point at the default pose, a body's bone being the segments from
//                  its origin to its centre of mass and to its child bodies' origins. (Segment
//                  masses such as de Leva's count all tissue inside the segment: a point of the
//                  vasti beside the femur belongs to the femur although the vasti have no path
//                  point on it. The nearest path point along the path would hand half of a
//                  straight soleus to the foot.) The point's default-pose position, expressed in
//                  that body, is subtracted exactly (mass, centre of mass, inertia by the
//                  parallel-axis theorem), so total mass and whole-body centre of mass at the
//                  default pose are unchanged to round-off, and so is the inertia of any rigid
//                  motion of the whole model there.
//   transfer       fraction F of one body's mass moves into the muscles that span it (those with
//                  a path point on it, narrowed by `muscles`), split in proportion to their
//                  physiological masses; the body's mass and its inertia about its centre of mass
//                  scale by (1 - F) and its centre of mass stays (the dissertation's tibia sweep).
//
// Only muscles (PathForceDesc::is_muscle) get mass. A muscle stays lumped when it is not selected,
// when its path wraps (Type III; with `wrap_mass`, only when its shape is one that
// core/muscles/wrap_muscle.hpp cannot move mass over) or when its physiological mass is zero; the
// plan says which and why.
#include <string>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/model_description.hpp"
#include "core/muscles/mass_points.hpp"

namespace redmax::osim {

/// Rajagopal et al. 2016 (60 N/cm^2) and Ward & Lieber 2005 (1059.7 kg/m^3); see docs/muscle_mass.md
inline constexpr double kDefaultSpecificTension = 0.6e6;  // Pa
inline constexpr double kDefaultMuscleDensity = 1059.7;   // kg/m^3

struct MuscleMassOptions {
  enum class Source { None, Physiological, Transfer };
  Source source = Source::None;
  /// "all", "top:K" (the K muscles with the largest inertia contribution, ranked over samples),
  /// or an ECMAScript regular expression matched against the whole muscle name
  std::string muscles = "all";
  int mass_points = 20;                       ///< per muscle, >= 1
  MassPointOptions::Region region = MassPointOptions::Region::Fibre;
  /// where the points sit as the muscle moves: Uniform, at fixed arc fractions of the whole path
  /// (equal strain over fibre and tendon, [D]); Fibre, spread over the fibre with the tendon at
  /// its own length (core/muscles/fibre_placement.hpp; Type I/II muscles with a Hill model whose
  /// state is a fibre length or none, the others stay uniform and the plan says why)
  enum class Placement { Uniform, Fibre };
  Placement placement = Placement::Uniform;
  double specific_tension = kDefaultSpecificTension;  ///< Pa, > 0
  double density = kDefaultMuscleDensity;             ///< kg/m^3, > 0
  std::string transfer_body;                  ///< Transfer only: a body name of the model
  double transfer_fraction = 0.0;             ///< Transfer only: in [0, 1)
  /// Type III muscles of the shape core/muscles/wrap_muscle.hpp supports (origin, one wrap surface,
  /// insertion) take mass too (smooth wrap model). Off by default: the Simbody side cannot move
  /// mass points over wrap surfaces yet, so engine comparisons keep them lumped.
  bool wrap_mass = false;
  /// wrap model of every Type III muscle that takes mass (copied to Muscle::wrap before the
  /// shape check, so the model decides which surfaces are supported); used only with wrap_mass
  WrapMassOptions wrap;
};

/// "uniform" | "fibre"; throws std::invalid_argument otherwise
MuscleMassOptions::Placement parseMassPlacement(const std::string& text);
const char* toString(MuscleMassOptions::Placement placement);

/// Fibre-following placement of `mu`'s mass points with its force model `mm` when `options` ask
/// for it (setFibrePlacement at `model`'s default pose). Returns "" when the points follow the
/// fibre or uniform placement was asked for, else why they stay uniform.
std::string placeMassPoints(const Model& model, const MuscleMassOptions& options,
                            const std::shared_ptr<const hill::MuscleModel>& mm, Muscle& mu);

/// "none" | "physiological" | "transfer"; throws std::invalid_argument otherwise
MuscleMassOptions::Source parseMuscleMassSource(const std::string& text);
const char* toString(MuscleMassOptions::Source source);

/// density * (F_max / specific_tension) * optimal_fiber_length, kg
double physiologicalMass(const PathForceDesc& muscle, const MuscleMassOptions& options);

/// one built path force (BuildResult::muscles order)
struct MuscleMassEntry {
  std::string name;
  double mass = 0.0;        ///< kg given to its mass points (0 = lumped)
  int points = 0;           ///< mass points (0 = lumped)
  std::string lumped_why;   ///< "" when it carries mass, else e.g. "not selected", "Type III path"
  bool wraps = false;       ///< its path has wrap objects (Type III)
  /// with Placement::Fibre and mass: "" when its points follow the fibre, else why they are uniform
  std::string uniform_why;
};

/// a body whose mass changed; inertia about its own centre of mass, body axes
struct BodyMassChange {
  std::string name;
  double mass_before = 0.0, mass_after = 0.0;
  Vec3 com_before = Vec3::Zero(), com_after = Vec3::Zero();
  Mat3 inertia_before = Mat3::Zero(), inertia_after = Mat3::Zero();
};

struct MuscleMassPlan {
  MuscleMassOptions options;
  std::vector<MuscleMassEntry> muscles;
  std::vector<BodyMassChange> bodies;
  /// top:K only: every candidate muscle and its inertia contribution (largest first), e.g. the
  /// largest ||M_muscle(q)|| / ||M_skeleton(q)|| over the samples
  std::vector<std::pair<std::string, double>> ranking;
  double total_muscle_mass = 0.0;  ///< kg
};

/// The model with its muscle mass: the description with the bodies' mass reduced (for engines
/// that build from a description, such as Simbody's), the core model edited to match it (bodies'
/// mass properties, muscles carrying mass points; built once, edited through its builder), and
/// the plan that says what moved where.
struct MuscleMassModel {
  ModelDescription description;
  BuildResult build;
  MuscleMassPlan plan;
};

/// Apply the options to a description. `samples` are coordinate vectors in the core's q order
/// (e.g. frames of the trial) over which top:K ranks muscles (at most 100 of them, evenly spaced,
/// are used); top:K without samples ranks at the default pose. The result's build always has the
/// muscles built (whatever build_options.muscles says): they carry the mass. Throws ConvertError (FILE:LINE of the offending element) for a body that would
/// become non-physical (negative or zero mass with inertia left, inertia not positive
/// semi-definite, triangle inequality broken), an unknown transfer body, a transfer body no
/// selected muscle spans, and std::invalid_argument for bad options (regex, counts, ranges).
MuscleMassModel applyMuscleMass(const ModelDescription& d, const BuildOptions& build_options,
                                const MuscleMassOptions& options,
                                const std::vector<VecX>& samples = {});

/// The same on a model already built from `d` with its muscles (BuildOptions::muscles; throws
/// std::invalid_argument otherwise): the built model is edited once through a
/// MusculoskeletalModelBuilder, not rebuilt. Same numbers as applyMuscleMass.
MuscleMassModel addMuscleMass(const ModelDescription& d, BuildResult built,
                              const MuscleMassOptions& options,
                              const std::vector<VecX>& samples = {});

/// The wrapping (Type III) muscles of a plan: how many there are, how many carry mass, and the
/// others with the reason each stays lumped (MuscleMassEntry::lumped_why), in plan order.
struct WrapMassCount {
  int wrapping = 0;
  int with_mass = 0;
  std::vector<std::pair<std::string, std::string>> lumped;  ///< (muscle, why)
};
WrapMassCount countWrapMass(const MuscleMassPlan& plan);

/// "smooth" | "exact" | "neural"; for summaries
const char* toString(WrapModel model);

/// Multi-line human-readable summary: each affected body's mass before and after, each muscle's
/// mass and point count, the lumped muscles and why, and the top:K ranking.
std::string describeMuscleMass(const MuscleMassPlan& plan);

}  // namespace redmax::osim
