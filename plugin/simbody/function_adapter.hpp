#pragma once
// A core AxisFunction seen as a SimTK::Function, for Simbody's FunctionBased mobilizer (the way
// OpenSim hands its CustomJoint functions to Simbody, docs/opensim_compatibility.md §3.3).
// Include through plugin/ only (it pulls in Simbody).
#include "plugin/simbody/simbody_include.hpp"

#include "core/joints/functions.hpp"

namespace redmax::simbody {

/// SimTK::Function wrapping a shared, immutable AxisFunction. Value and derivatives of order 1
/// and 2 come from AxisFunction::evaluate (exact); Simbody asks for nothing higher.
/// Argument count = f->numArgs(). Throws std::invalid_argument for a null function.
class AxisFunctionAdapter : public SimTK::Function {
 public:
  explicit AxisFunctionAdapter(AxisFunctionPtr f);

  SimTK::Real calcValue(const SimTK::Vector& x) const override;
  /// derivComponents: 1 or 2 argument indices (gradient entry or Hessian entry); 0 gives the
  /// value; more than 2 throws std::invalid_argument
  SimTK::Real calcDerivative(const SimTK::Array_<int>& derivComponents,
                             const SimTK::Vector& x) const override;
  int getArgumentSize() const override;
  int getMaxDerivativeOrder() const override { return 2; }
  SimTK::Function* clone() const override { return new AxisFunctionAdapter(f_); }

  const AxisFunctionPtr& function() const { return f_; }

 private:
  VecJ toArgs(const SimTK::Vector& x) const;
  AxisFunctionPtr f_;
};

}  // namespace redmax::simbody
