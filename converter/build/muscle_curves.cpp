#include "converter/build/muscle_curves.hpp"

#include "converter/build/functions_to_core.hpp"

namespace redmax::osim {
namespace {

class FunctionCurve final : public hill::Curve {
 public:
  explicit FunctionCurve(AxisFunctionPtr f) : f_(std::move(f)) {}
  double value(double x) const override { return f_->value(arg(x)); }
  double derivative(double x) const override { return f_->gradient(arg(x))[0]; }
  std::string typeName() const override { return f_->typeName(); }

 private:
  static VecJ arg(double x) {
    VecJ v(1);
    v[0] = x;
    return v;
  }
  AxisFunctionPtr f_;
};

}  // namespace

hill::CurvePtr muscleCurve(AxisFunctionPtr f) { return std::make_shared<const FunctionCurve>(std::move(f)); }

hill::CurvePtr muscleCurve(const FunctionDesc& f, const std::string& file, const std::string& owner) {
  return muscleCurve(makeCoreFunction(f, 1, file, owner));
}

hill::SplineFactory muscleSplineFactory() {
  return [](const std::vector<double>& x, const std::vector<double>& y) {
    return muscleCurve(std::make_shared<const SimmSpline>(x, y));
  };
}

}  // namespace redmax::osim
