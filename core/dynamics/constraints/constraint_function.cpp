#include "core/dynamics/constraints/constraint_function.hpp"

#include <stdexcept>

namespace redmax {
namespace {

class CallableFunction final : public AxisFunction {
 public:
  CallableFunction(int n, std::function<double(const VecX&)> v, std::function<VecX(const VecX&)> g,
                   std::function<MatX(const VecX&)> h)
      : n_(n), v_(std::move(v)), g_(std::move(g)), h_(std::move(h)) {}
  int numArgs() const override { return n_; }
  void evaluate(const VecJ& x, int order, FunctionValue& out) const override {
    const VecX xx = x;
    out.value = v_(xx);
    if (order >= 1) out.gradient = g_(xx);
    if (order >= 2) out.hessian = h_(xx);
  }
  std::string typeName() const override { return "callable"; }

 private:
  int n_;
  std::function<double(const VecX&)> v_;
  std::function<VecX(const VecX&)> g_;
  std::function<MatX(const VecX&)> h_;
};

}  // namespace

bool acceptsArguments(const AxisFunction& f, int n) { return f.numArgs() == n || f.numArgs() == 0; }

void evaluateWithArguments(const AxisFunction& f, const VecJ& x, int order, FunctionValue& out) {
  if (f.numArgs() == x.size()) {
    f.evaluate(x, order, out);
    return;
  }
  // a constant of no arguments: value only, zero derivatives in the caller's arguments
  f.evaluate(VecJ(0), 0, out);
  if (order >= 1) out.gradient.setZero(x.size());
  if (order >= 2) out.hessian.setZero(x.size(), x.size());
}

ConstraintFunctionPtr makeConstraintFunction(int num_args, std::function<double(const VecX&)> value,
                                             std::function<VecX(const VecX&)> gradient,
                                             std::function<MatX(const VecX&)> hessian) {
  if (num_args < 1 || num_args > 6)
    throw std::invalid_argument("constraint function: 1 to 6 arguments, got " + std::to_string(num_args));
  if (!value || !gradient || !hessian)
    throw std::invalid_argument("constraint function: value, gradient and Hessian are all required");
  return std::make_shared<CallableFunction>(num_args, std::move(value), std::move(gradient),
                                            std::move(hessian));
}

ConstraintFunctionPtr makeConstraintFunction1(std::function<double(double)> value,
                                              std::function<double(double)> first,
                                              std::function<double(double)> second) {
  if (!value || !first || !second)
    throw std::invalid_argument("constraint function: value, first and second derivative are all required");
  return makeConstraintFunction(
      1, [v = std::move(value)](const VecX& x) { return v(x[0]); },
      [d = std::move(first)](const VecX& x) { return VecX::Constant(1, d(x[0])); },
      [dd = std::move(second)](const VecX& x) { return MatX::Constant(1, 1, dd(x[0])); });
}

ConstraintFunctionPtr makeConstantFunction(double c, int num_args) {
  return std::make_shared<ConstantFunction>(c, num_args);
}

ConstraintFunctionPtr makeLinearFunction(const std::vector<double>& slopes, double intercept) {
  std::vector<double> coef = slopes;
  coef.push_back(intercept);
  return std::make_shared<LinearFunction>(std::move(coef));
}

}  // namespace redmax
