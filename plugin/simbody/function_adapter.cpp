#include "plugin/simbody/function_adapter.hpp"

#include <stdexcept>
#include <string>

namespace redmax::simbody {

AxisFunctionAdapter::AxisFunctionAdapter(AxisFunctionPtr f) : f_(std::move(f)) {
  if (!f_) throw std::invalid_argument("AxisFunctionAdapter: null function");
}

int AxisFunctionAdapter::getArgumentSize() const { return f_->numArgs(); }

VecJ AxisFunctionAdapter::toArgs(const SimTK::Vector& x) const {
  const int n = f_->numArgs();
  if (x.size() != n)
    throw std::invalid_argument("AxisFunctionAdapter(" + f_->typeName() + "): " +
                                std::to_string(x.size()) + " arguments given, " + std::to_string(n) +
                                " expected");
  VecJ a(n);
  for (int k = 0; k < n; ++k) a[k] = x[k];
  return a;
}

SimTK::Real AxisFunctionAdapter::calcValue(const SimTK::Vector& x) const { return f_->value(toArgs(x)); }

SimTK::Real AxisFunctionAdapter::calcDerivative(const SimTK::Array_<int>& c, const SimTK::Vector& x) const {
  const VecJ a = toArgs(x);
  const int order = static_cast<int>(c.size());
  if (order > 2)
    throw std::invalid_argument("AxisFunctionAdapter(" + f_->typeName() + "): derivative of order " +
                                std::to_string(order) + " requested (at most 2)");
  for (int k = 0; k < order; ++k)
    if (c[k] < 0 || c[k] >= f_->numArgs())
      throw std::invalid_argument("AxisFunctionAdapter(" + f_->typeName() + "): derivative component " +
                                  std::to_string(c[k]) + " out of range");
  FunctionValue fv;
  f_->evaluate(a, order, fv);
  if (order == 0) return fv.value;
  if (order == 1) return fv.gradient[c[0]];
  return fv.hessian(c[0], c[1]);
}

}  // namespace redmax::simbody
