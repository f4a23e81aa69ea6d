#pragma once
// Edits of an OpenSim model file that studies need (e.g. the spline-leg scene's revolute knee,
// validation/forward/spline_leg_scene.hpp): read with the converter's reader, written back as XML.
#include <array>
#include <string>

#include "core/joints/functions.hpp"
#include "core/spatial/types.hpp"

namespace redmax::osim {

/// The translation a CustomJoint's coordinate-dependent translation axes give (joint frame): for a
/// joint whose translation1..3 axes are the frame's x, y, z and each depends on at most one
/// coordinate (a spline knee). Throws ConvertError naming the file (no such joint, not a
/// CustomJoint, an axis that is not the frame's).
class JointTranslation {
 public:
  JointTranslation(const std::string& model_path, const std::string& joint);
  /// the translation at coordinate value q (axes without a coordinate give 0)
  Vec3 at(double q) const;
  /// whether axis i (0..2) depends on the coordinate
  bool depends(int i) const { return static_cast<bool>(f_[i]); }

 private:
  std::array<AxisFunctionPtr, 3> f_;
};

/// The model file's XML with the CustomJoint `joint`'s coordinate-dependent translation functions
/// replaced by Constants equal to their value at `angle` (%.17g; the rotation is untouched): the
/// spline knee made a revolute one. Throws ConvertError naming the file.
std::string freezeJointTranslations(const std::string& model_path, const std::string& joint, double angle);

}  // namespace redmax::osim
