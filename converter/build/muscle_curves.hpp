#pragma once
// OpenSim Function properties of muscles (RigidTendonMuscle, Schutte1993Muscle_Deprecated) as the
// Hill library's curves: the converter's function reader and core functions behind hill::Curve
// (docs/muscle_dynamics.md §2.5), so the Hill library needs no spline code of its own.
#include <string>

#include "converter/model_description.hpp"
#include "core/joints/functions.hpp"
#include "core/muscles/hill/curve.hpp"

namespace redmax::osim {

/// a core function of one argument as a muscle curve (value, exact derivative)
hill::CurvePtr muscleCurve(AxisFunctionPtr f);

/// a function read from a file as a muscle curve; ConvertError ("FILE:LINE: owner: ...") for a
/// function that cannot be built or takes other than one argument
hill::CurvePtr muscleCurve(const FunctionDesc& f, const std::string& file, const std::string& owner);

/// OpenSim's SimmSpline through (x, y) as a muscle curve (a class's default curves)
hill::SplineFactory muscleSplineFactory();

}  // namespace redmax::osim
