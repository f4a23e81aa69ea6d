#pragma once
// A curve given as an OpenSim Function property (RigidTendonMuscle's and
// Schutte1993Muscle_Deprecated's active_force_length_curve, passive_force_length_curve,
// force_velocity_curve, tendon_force_length_curve: SimmSpline, PiecewiseLinearFunction, ...).
// The Hill library has no function machinery of its own: whoever reads the model builds the
// functions (converter: core/joints/functions.hpp through converter/muscle_curves.hpp) and passes
// them in MuscleParameters, behind this interface. docs/muscle_dynamics.md §2.5.
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace redmax::hill {

class Curve {
 public:
  virtual ~Curve() = default;
  virtual double value(double x) const = 0;
  /// df/dx, the function's own derivative (exact, not differenced)
  virtual double derivative(double x) const = 0;
  /// the OpenSim class ("SimmSpline", ...), for reports
  virtual std::string typeName() const = 0;
};

using CurvePtr = std::shared_ptr<const Curve>;

/// builds OpenSim's SimmSpline through (x, y): a class's default curves are SimmSplines
/// (OpenSim's constructProperties), made by the reader's spline code, not a copy of it here
using SplineFactory = std::function<CurvePtr(const std::vector<double>& x, const std::vector<double>& y)>;

}  // namespace redmax::hill
