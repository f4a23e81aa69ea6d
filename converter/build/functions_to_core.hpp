#pragma once
// OpenSim functions (plain data, FunctionDesc) -> core functions (AxisFunction: value, exact
// gradient and Hessian), with the evaluation rules of docs/opensim_compatibility.md §4.
//
//   Constant                 c, any number of arguments (the caller's count), derivatives 0
//   LinearFunction           [slopes..., intercept], one argument per slope
//   PolynomialFunction       decreasing powers (Horner)
//   SimmSpline (= NaturalCubicSpline, natCubicSpline)   core SimmSpline
//   GCVSpline                natural interpolating spline of degree 2 half_order - 1 through
//                            (x, y): OpenSim refits with error variance 0, which interpolates to
//                            ~1e-13 (converter/signal/natural_spline.hpp); weights and stored
//                            coefficients are ignored, as OpenSim ignores them
//   MultiplierFunction       scale * inner
//   PiecewiseLinearFunction  OpenSim's segment slopes (1e-7 floor on dx), end slopes outside,
//                            its bisection at interior knots; second derivative 0
//   PiecewiseConstantFunction  left knot's value (OpenSim's bisection), derivatives 0
//   Sine                     A sin(w x + phase) + offset
//   StepFunction             Simbody Step: quintic smoothstep 10t^3 - 15t^4 + 6t^5 between the
//                            transition times
//   MultivariatePolynomialFunction  OpenSim 4.5+ monomial order (powers of argument 0 outermost,
//                            ascending: for 2 arguments of order 2, 1 y y^2 x xy x^2)
//   ExpressionBasedFunction  not evaluable: ConvertError
// Where OpenSim's derivative is not the derivative of its value (the piecewise functions at their
// kinks), ours are OpenSim's.
#include <string>

#include "converter/error.hpp"
#include "converter/model_description.hpp"
#include "core/joints/functions.hpp"

namespace redmax::osim {

/// Build the core function for f. num_args: the number of arguments the caller passes (a
/// CustomJoint axis's coordinate count, 1 for moving path points and time functions); a Constant
/// (or a Multiplier of one) takes that many, every other type must take exactly that many.
/// file and owner (e.g. "CustomJoint 'knee_r' rotation1") name the function in errors.
/// Throws ConvertError ("FILE:LINE: owner: what") for unsupported types (ExpressionBased), an
/// argument-count mismatch, or data the function cannot be built from (too few points,
/// non-increasing x, a zero-length step, GCVSpline smoothing with error_variance != 0).
AxisFunctionPtr makeCoreFunction(const FunctionDesc& f, int num_args, const std::string& file,
                                 const std::string& owner);

}  // namespace redmax::osim
