#include "core/dynamics/constraints/constraint_function.hpp"

#include <stdexcept>

namespace redmax {
namespace {

class CallableFunction final : public ConstraintFunction {
 public:
  CallableFunction(int n, std::function<double(const VecX&)> v, std::function<VecX(const VecX&)> g,
                   std::function<MatX(const VecX&)> h)
      : n_(n), v_(std::move(v)), g_(std::move(g)), h_(std::move(h)) {}
  int numArgs() const override { return n_; }
  double value(const VecX& x) const override { return v_(x); }
  VecX gradient(const VecX& x) const override { return g_(x); }
  MatX hessian(const VecX& x) const override { return h_(x); }

 private:
  int n_;
  std::function<double(const VecX&)> v_;
  std::function<VecX(const VecX&)> g_;
  std::function<MatX(const VecX&)> h_;
};

class LinearFunction final : public ConstraintFunction {
 public:
  LinearFunction(VecX slopes, double intercept) : a_(std::move(slopes)), b_(intercept) {}
  int numArgs() const override { return static_cast<int>(a_.size()); }
  double value(const VecX& x) const override { return a_.dot(x) + b_; }
  VecX gradient(const VecX&) const override { return a_; }
  MatX hessian(const VecX&) const override { return MatX::Zero(a_.size(), a_.size()); }

 private:
  VecX a_;
  double b_;
};

}  // namespace

ConstraintFunctionPtr makeConstraintFunction(int num_args, std::function<double(const VecX&)> value,
                                             std::function<VecX(const VecX&)> gradient,
                                             std::function<MatX(const VecX&)> hessian) {
  if (num_args < 1) throw std::invalid_argument("constraint function: needs at least one argument");
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
  if (num_args < 1) throw std::invalid_argument("constant function: needs at least one argument");
  return std::make_shared<LinearFunction>(VecX::Zero(num_args), c);
}

ConstraintFunctionPtr makeLinearFunction(const std::vector<double>& slopes, double intercept) {
  if (slopes.empty()) throw std::invalid_argument("linear function: needs at least one slope");
  return std::make_shared<LinearFunction>(Eigen::Map<const VecX>(slopes.data(), slopes.size()), intercept);
}

}  // namespace redmax
