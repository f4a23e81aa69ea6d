#pragma once
// The XML properties of one muscle as plain named numbers, so that a muscle model can be built
// from them by class name (makeMuscleModel) and the same properties can be read as another class
// (OpenSim's Object::renameType). Names are OpenSim 4's property names; a curve sub-object's
// properties are "Curve/property" (e.g. "ActiveForceLengthCurve/min_norm_active_fiber_length");
// booleans are 0 or 1. A model reads the names its class knows, with OpenSim's defaults for the
// absent ones, and ignores the others (as OpenSim ignores unknown properties).
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/muscles/hill/curve.hpp"
#include "core/muscles/hill/muscle_model.hpp"

namespace redmax::hill {

/// A property out of the range the OpenSim class accepts; property() names it (as in
/// MuscleParameters), so that a reader can point at its line.
class MuscleParameterError : public MuscleModelError {
 public:
  MuscleParameterError(std::string property, const std::string& message)
      : MuscleModelError(message), property_(std::move(property)) {}
  const std::string& property() const { return property_; }

 private:
  std::string property_;
};

struct MuscleParameters {
  std::string name;                      ///< the muscle's name, for messages
  std::map<std::string, double> values;  ///< property name -> value
  /// Function-valued properties as written (e.g. "active_force_length_curve"), built by the reader
  std::map<std::string, CurvePtr> curves;
  /// makes a class's default SimmSpline curves (absent function properties); may be empty when no
  /// class that needs one is built
  SplineFactory simm_spline;

  bool has(const std::string& key) const { return values.count(key) > 0; }
  /// the property's value, or `fallback` when absent
  double get(const std::string& key, double fallback) const;
  bool flag(const std::string& key, bool fallback) const { return get(key, fallback ? 1 : 0) != 0; }
  void set(const std::string& key, double v) { values[key] = v; }
  /// the curve written as `key`, else OpenSim's default SimmSpline through (x, y); throws
  /// MuscleParameterError(key) when it is absent and no simm_spline factory is given
  CurvePtr curveOr(const std::string& key, const std::vector<double>& x, const std::vector<double>& y) const;
};

/// A model's parameters as it uses them (after defaults), for reports: (name, value) in a fixed
/// order.
using ParameterList = std::vector<std::pair<std::string, double>>;

}  // namespace redmax::hill
