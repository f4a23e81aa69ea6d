#pragma once
// Smooth scalar functions used by the constraints of this folder: the coupling function f of a
// CoordinateCoupler / CoordinateMap (q_dep = scale * f(q_indep...)) and the time function q_p(t)
// of a PrescribedCoordinate. Each gives its value, gradient and Hessian exactly, because the
// acceleration-level constraints need second derivatives [D Eq. 4.99, 4.103].
//
// TODO(constraints): core/joints/functions.hpp (AxisFunction, written by the joints helper) has the
// same contract; once it lands, wrap it here (makeConstraintFunction(std::shared_ptr<const
// AxisFunction>)) so that OpenSim functions reach couplers and prescribed coordinates unchanged.
#include <functional>
#include <memory>
#include <vector>

#include "core/spatial/types.hpp"

namespace redmax {

/// f: R^n -> R with exact first and second derivatives. Immutable; shared through
/// std::shared_ptr<const ConstraintFunction> so models and systems stay copyable.
class ConstraintFunction {
 public:
  virtual ~ConstraintFunction() = default;
  /// number of arguments n (>= 1)
  virtual int numArgs() const = 0;
  virtual double value(const VecX& x) const = 0;
  /// df/dx (n)
  virtual VecX gradient(const VecX& x) const = 0;
  /// d2f/dx2 (n x n, symmetric)
  virtual MatX hessian(const VecX& x) const = 0;
};

using ConstraintFunctionPtr = std::shared_ptr<const ConstraintFunction>;

/// adapter from three callables; throws std::invalid_argument if n < 1 or a callable is empty
ConstraintFunctionPtr makeConstraintFunction(int num_args, std::function<double(const VecX&)> value,
                                             std::function<VecX(const VecX&)> gradient,
                                             std::function<MatX(const VecX&)> hessian);

/// one-argument adapter (e.g. a prescribed trajectory q(t), qdot(t), qddot(t))
ConstraintFunctionPtr makeConstraintFunction1(std::function<double(double)> value,
                                              std::function<double(double)> first,
                                              std::function<double(double)> second);

/// f(x) = c for a function of num_args arguments (locked coordinates)
ConstraintFunctionPtr makeConstantFunction(double c, int num_args = 1);

/// f(x) = slopes . x + intercept (OpenSim LinearFunction; the dissertation's "all angles equal")
ConstraintFunctionPtr makeLinearFunction(const std::vector<double>& slopes, double intercept = 0.0);

}  // namespace redmax
