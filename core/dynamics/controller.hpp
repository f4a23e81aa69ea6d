#pragma once
// Controls of a System (docs/forward.md): a Controller computes excitations u(t, state) of the
// System's actuators (System::controlNames(), the ForceTerms' numControls() in term order) at every
// evaluation, into DynamicsWorkspace::controls, before the terms are evaluated. As in OpenSim's
// ControllerSet, every controller adds its share to u, which starts at zero; a System without
// controllers leaves ws.controls as the caller set them (zero when their size is wrong).
// Controllers are immutable model-side objects shared by threads; what they compute goes to the
// workspace.
#include <memory>
#include <string>
#include <vector>

#include "core/joints/functions.hpp"
#include "core/skeleton/state.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax {

class Controller {
 public:
  virtual ~Controller() = default;
  virtual std::string name() const = 0;
  /// Add this controller's controls at skeleton state s (time s.t) to u (System::numControls());
  /// sk holds the kinematics at s (Stage::Velocity).
  virtual void addControls(const Model& model, const State& s, const SkeletonWorkspace& sk,
                           Eigen::Ref<VecX> u) const = 0;
};

/// Controls as functions of time alone: u[control] += f(t) for each entry. OpenSim's
/// ControlSetController (each ControlLinear as a function of time, converter/controls.hpp) and
/// PrescribedController (its FunctionSet) both become one.
class PrescribedControls final : public Controller {
 public:
  struct Entry {
    int control = -1;           ///< index into the System's controls
    AxisFunctionPtr function;   ///< one argument: time (s)
  };
  PrescribedControls(std::string name, std::vector<Entry> entries)
      : name_(std::move(name)), entries_(std::move(entries)) {}
  std::string name() const override { return name_; }
  void addControls(const Model& model, const State& s, const SkeletonWorkspace& sk,
                   Eigen::Ref<VecX> u) const override;
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::string name_;
  std::vector<Entry> entries_;
};

/// A proportional-derivative controller for scenes: for each rule,
///   u[control] += bias + kp (target - q[coordinate]) + kd (0 - qdot[coordinate])
/// (kp, kd may be negative: an antagonist is excited when the angle goes the other way), then
/// clamped to [min, max].
class ProportionalController final : public Controller {
 public:
  struct Rule {
    int control = -1;     ///< index into the System's controls
    int coordinate = -1;  ///< index into the skeleton's q
    double target = 0.0;  ///< rad or m
    double kp = 0.0;      ///< per rad (or m)
    double kd = 0.0;      ///< per rad/s (or m/s)
    double bias = 0.0;
    double min = 0.0, max = 1.0;
  };
  explicit ProportionalController(std::vector<Rule> rules) : rules_(std::move(rules)) {}
  std::string name() const override { return "proportional"; }
  void addControls(const Model& model, const State& s, const SkeletonWorkspace& sk,
                   Eigen::Ref<VecX> u) const override;
  const std::vector<Rule>& rules() const { return rules_; }

 private:
  std::vector<Rule> rules_;
};

}  // namespace redmax
