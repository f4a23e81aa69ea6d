#pragma once
// Musculotendon path lengths along a coordinates file, as OpenSim's GeometryPath::getLength gives
// them (`redmax lengths`; docs/commands.md §1; docs/opensim_compatibility.md §1.5, §6). Exact wrapping over
// cylinders, spheres, ellipsoids and tori (core/muscles/wrap/). Coordinates absent from the file
// keep their defaults; columns are matched and Rotational columns of a degrees file converted by
// converter/coordinates_file.hpp; constraints are not enforced (the file's coupled coordinates are
// used as written).
// Wrap smooth|neural: the length with the wrap model that mass points use (issue 7): straight
// segments between active points plus, on the segment each wrap object acts on
// (calcSegmentWraps, core/muscles/wrap_muscle.hpp), the model's length of that wrapped segment:
// the smooth model's (calcWrapModelLength), or the polyline through the network's points
// (calcNetworkWrapPathLength), with the smooth model where the network falls back. Paths the model
// refuses (wrapMassPointsUnsupportedReason: unsupported surfaces, for the network two wraps on one
// segment; several on one segment go through the smooth composition, wrap_composite.hpp) keep
// OpenSim's exact length and are named once.
#include <string>
#include <vector>

#include "converter/build/build_core_model.hpp"
#include "converter/model_description.hpp"
#include "converter/storage.hpp"
#include "core/muscles/wrap/network_model.hpp"
#include "core/muscles/wrap_muscle.hpp"

namespace redmax::validation {

/// The wrap model's length of muscle's path at q (m), see the file header. A wrapped segment whose
/// end lies inside its surface (origin -> surface -> insertion only; calcSegmentWraps skips such
/// segments elsewhere) is straight, as OpenSim's InsideRadius leaves it. `E_wi` are the body poses
/// at q; ws, active and x_w are scratch.
/// `monitor` (Neural; may be null) counts every wrapped-segment evaluation.
double calcModelPathLength(const Model& model, const Muscle& muscle, const VecX& q, const std::vector<Mat4>& E_wi,
                           NetworkWrapWorkspace& ws, std::vector<int>& active, std::vector<Vec3>& x_w,
                           WrapFallbackMonitor* monitor = nullptr);

enum class LengthWrap { Exact, None, Smooth, Neural };

struct PathLengthOptions {
  LengthWrap wrap = LengthWrap::Exact;  ///< None: straight segments, no wraps
  WrapMassOptions wrap_model;           ///< Smooth, Neural: the model's settings (width, network)
  WrapFallbackMonitor* monitor = nullptr;  ///< Neural: receives the fallback counts (may be null)
  bool all_paths = false;               ///< every force with a path, not only muscles
  bool wrap_lengths = false;            ///< also the surface length of every wrap object
};

struct PathLengthResult {
  osim::Storage lengths;       ///< "MuscleTendonLengths": time, one column per reported path (m)
  osim::Storage wrap_lengths;  ///< "WrapSurfaceLengths": MUSCLE/WRAP columns (0 = not wrapping)
  int missing_coordinates = 0;  ///< coordinates not in the file (held at their defaults)
  int wrapping = 0;             ///< reported paths with a wrap object
  int exact_fallbacks = 0;      ///< Smooth/Neural: wrapping paths the model refuses (exact length)
  std::string refused;          ///< "  NAME: why\n" per such path
  bool failed = false;          ///< a non-finite length; failure says where
  std::string failure;
};

/// The lengths of `build`'s paths (built from `d` without constraints) at every row of `coords`
/// (read from `coords_file`, named in messages). Throws osim::ConvertError when no path is reported
/// or no column names a coordinate, std::invalid_argument for wrap_lengths without a wrap object.
PathLengthResult calcPathLengths(const osim::ModelDescription& d, const osim::BuildResult& build,
                                 const osim::Storage& coords, const std::string& model_file,
                                 const std::string& coords_file, const PathLengthOptions& o);

}  // namespace redmax::validation
