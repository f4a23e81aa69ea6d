#pragma once
// `redmax view` (docs/view.md): a self-contained folder that shows a model in a browser opened
// from disk (file://, no server, no network): bodies (the model's meshes, or ellipsoids of their
// inertia), joint frames, muscle paths with their path and wrap points, wrap surfaces and mass
// points, along a motion. Layout of the folder:
//   index.html   the page (copied from view/web/)
//   view.js      the page's own script, view.css its style (copied from view/web/)
//   three.min.js the 3-D library (npm `three`, pinned in view/web/package.json)
//   data.js      `window.REDMAX_VIEW = {...}`: everything drawn (a script, not JSON, because a
//                page opened from disk may not fetch files beside it)
// The data are computed here with the engine's own code: body poses from the kinematics, the
// muscle path as OpenSim wraps it (core/muscles/wrap/wrap_path.hpp), mass points as the engine
// places them (calcMuscleKinematics), muscle lengths as OpenSim's GeometryPath gives them.
#include <cstdint>
#include <string>
#include <vector>

#include "converter/build/muscle_mass.hpp"
#include "converter/model_description.hpp"
#include "converter/storage.hpp"

namespace redmax::view {

/// The page's files: index.html, view.js, view.css and three.min.js.
struct ViewAssets {
  std::string index_html, view_js, view_css, three_js;
};

/// The first folder of `folders` holding index.html, view.js and view.css, with three.min.js in it
/// or in its node_modules/three/build/ (the source tree after `npm ci` in view/web). Throws
/// std::runtime_error naming the folders searched.
ViewAssets findViewAssets(const std::vector<std::string>& folders);

struct ViewInput {
  osim::ModelDescription description;  ///< read from its source_file
  std::string motion_file;             ///< "" = one frame at the default pose
  osim::Storage motion;                ///< read from motion_file (coordinates or states)
  osim::MuscleMassOptions mass;        ///< the MUSCLE-MASS OPTIONS (none: no mass points)
};

struct ViewSummary {
  int frames = 0, bodies = 0, meshes = 0, muscles = 0, mass_points = 0;
  double muscle_mass = 0.0;                 ///< kg on the mass points drawn
  std::vector<std::string> messages;        ///< what the page says above the view
  std::string mass_plan;                    ///< describeMuscleMass (empty without muscle mass)
  std::uintmax_t bytes = 0;                 ///< size of the folder written
};

/// Writes the folder `out_dir` (created; replaced when it holds an earlier view, refused when it
/// holds anything else): built in a temporary folder beside it, then renamed, so a failure leaves
/// nothing half-written. Throws osim::ConvertError for bad input (a motion without coordinate
/// columns, a model the core cannot build, muscle-mass options the model refuses),
/// std::runtime_error for a path that cannot be evaluated at a frame (naming the time) or a
/// folder that cannot be written.
ViewSummary writeView(const ViewInput& in, const ViewAssets& assets, const std::string& out_dir);

/// The semi-axes (m) and axes (columns) of the uniform-density ellipsoid with `mass` and inertia
/// `I_com` about its centre: a^2 = 5 (I_b + I_c - I_a) / (2 m) along principal axis a. Flat
/// directions (a negative or zero square, e.g. a rod) get 2% of the largest semi-axis so that the
/// shape stays visible; zero mass gives zero axes.
void inertiaEllipsoid(double mass, const Mat3& I_com, Vec3& radii, Mat3& axes);

}  // namespace redmax::view
