#pragma once
// Smooth scalar functions used by the constraints of this folder: the coupling function f of a
// CoordinateCoupler / CoordinateMap (q_dep = scale * f(q_indep...)) and the time function q_p(t)
// of a PrescribedCoordinate. They are the joints' AxisFunction (core/joints/functions.hpp: value,
// exact gradient and Hessian, at most 6 arguments), so the functions the converter builds for
// OpenSim (LinearFunction, SimmSpline, PolynomialFunction, MultiplierFunction, ...) reach
// couplers and prescribed coordinates unchanged. The acceleration-level rows need the Hessian
// [D Eq. 4.99, 4.103].
#include <functional>
#include <memory>
#include <vector>

#include "core/joints/functions.hpp"

namespace redmax {

using ConstraintFunction = AxisFunction;
using ConstraintFunctionPtr = AxisFunctionPtr;

/// true if f can be called with n arguments: numArgs() == n, or a function of no arguments
/// (OpenSim's Constant), which ignores them
bool acceptsArguments(const AxisFunction& f, int n);

/// f at x to the given order (0 value, 1 + gradient, 2 + Hessian); gradient and Hessian are
/// sized x.size() also for a function of no arguments (zero derivatives)
void evaluateWithArguments(const AxisFunction& f, const VecJ& x, int order, FunctionValue& out);

/// adapter from three callables on VecX (1..6 arguments); throws std::invalid_argument if a
/// callable is empty or the argument count is out of range
ConstraintFunctionPtr makeConstraintFunction(int num_args, std::function<double(const VecX&)> value,
                                             std::function<VecX(const VecX&)> gradient,
                                             std::function<MatX(const VecX&)> hessian);

/// one-argument adapter (e.g. a prescribed trajectory q(t), qdot(t), qddot(t))
ConstraintFunctionPtr makeConstraintFunction1(std::function<double(double)> value,
                                              std::function<double(double)> first,
                                              std::function<double(double)> second);

/// f(x) = c for a function of num_args arguments (locked coordinates): a ConstantFunction
ConstraintFunctionPtr makeConstantFunction(double c, int num_args = 1);

/// f(x) = slopes . x + intercept: a LinearFunction (the dissertation's "all angles equal")
ConstraintFunctionPtr makeLinearFunction(const std::vector<double>& slopes, double intercept = 0.0);

}  // namespace redmax
