#include "core/dynamics/coordinate_map.hpp"

#include <algorithm>
#include <cmath>

#include "core/skeleton/model.hpp"

namespace redmax {

CoordinateMap::CoordinateMap(const Model& model) : nr_(model.nr()) {
  for (const Coordinate& c : model.coordinates()) names_.push_back(c.name);
  rebuild();
}

void CoordinateMap::addDependent(int dependent, std::vector<int> args, ConstraintFunctionPtr f, double scale) {
  auto name = [&](int i) { return i >= 0 && i < nr_ ? "'" + names_[i] + "'" : std::to_string(i); };
  const std::string what = "coordinate map: dependent coordinate " + name(dependent);
  if (dependent < 0 || dependent >= nr_) throw ModelError(what + " out of range");
  if (args.empty()) throw ModelError(what + " has no argument");
  if (args.size() > 6) throw ModelError(what + ": at most 6 arguments, got " + std::to_string(args.size()));
  for (size_t k = 0; k < args.size(); ++k) {
    if (args[k] < 0 || args[k] >= nr_) throw ModelError(what + ": argument " + name(args[k]) + " out of range");
    if (args[k] == dependent) throw ModelError(what + " depends on itself");
    if (std::count(args.begin(), args.end(), args[k]) > 1)
      throw ModelError(what + ": argument " + name(args[k]) + " given twice");
  }
  if (!f) throw ModelError(what + ": no function");
  if (!acceptsArguments(*f, static_cast<int>(args.size())))
    throw ModelError(what + ": function takes " + std::to_string(f->numArgs()) + " arguments, " +
                     std::to_string(args.size()) + " given");
  if (!std::isfinite(scale)) throw ModelError(what + ": non-finite scale");
  for (const Dependent& d : deps_)
    if (d.index == dependent) throw ModelError(what + " is already dependent");
  const auto saved = deps_;
  deps_.push_back({dependent, std::move(args), std::move(f), scale});
  try {
    rebuild();
  } catch (...) {
    deps_ = saved;
    rebuild();
    throw;
  }
}

void CoordinateMap::rebuild() {
  // independent coordinates in skeleton order
  std::vector<int> dep_of(nr_, -1);
  for (size_t k = 0; k < deps_.size(); ++k) dep_of[deps_[k].index] = static_cast<int>(k);
  independent_.clear();
  r_to_R_.assign(nr_, -1);
  is_arg_.assign(nr_, 0);
  for (const Dependent& d : deps_)
    for (int a : d.args) is_arg_[a] = 1;
  for (int r = 0; r < nr_; ++r) {
    if (dep_of[r] >= 0) continue;
    r_to_R_[r] = static_cast<int>(independent_.size());
    independent_.push_back(r);
  }
  // dependency order (Kahn): a dependent is ready when all its arguments are known
  std::vector<char> known(nr_, 0);
  for (int r : independent_) known[r] = 1;
  std::vector<Dependent> ordered;
  std::vector<char> placed(deps_.size(), 0);
  bool progress = true;
  while (ordered.size() < deps_.size() && progress) {
    progress = false;
    for (size_t k = 0; k < deps_.size(); ++k) {
      if (placed[k]) continue;
      const bool ready = std::all_of(deps_[k].args.begin(), deps_[k].args.end(), [&](int a) { return known[a] != 0; });
      if (!ready) continue;
      ordered.push_back(deps_[k]);
      placed[k] = 1;
      known[deps_[k].index] = 1;
      progress = true;
    }
  }
  if (ordered.size() < deps_.size()) {
    std::string cyc;
    for (size_t k = 0; k < deps_.size(); ++k)
      if (!placed[k]) cyc += (cyc.empty() ? "'" : ", '") + names_[deps_[k].index] + "'";
    throw ModelError("coordinate map: dependency cycle among " + cyc);
  }
  deps_ = std::move(ordered);
}

void CoordinateMap::calcPosition(const VecX& q_R, VecX& q_r) const {
  if (q_R.size() != nR())
    throw ModelError("coordinate map: expected " + std::to_string(nR()) + " independent coordinates, got " +
                     std::to_string(q_R.size()));
  q_r.resize(nr_);
  for (int j = 0; j < nR(); ++j) q_r[independent_[j]] = q_R[j];
  VecJ x;
  FunctionValue fv;
  for (const Dependent& d : deps_) {
    x.resize(static_cast<long>(d.args.size()));
    for (size_t k = 0; k < d.args.size(); ++k) x[static_cast<long>(k)] = q_r[d.args[k]];
    evaluateWithArguments(*d.f, x, 0, fv);
    q_r[d.index] = d.scale * fv.value;
  }
}

void CoordinateMap::calc(const VecX& q_R, const VecX& qdot_R, VecX& q_r, VecX& qdot_r, MatX& J_rR,
                         MatX& Jdot_rR) const {
  if (q_R.size() != nR() || qdot_R.size() != nR())
    throw ModelError("coordinate map: expected " + std::to_string(nR()) + " independent coordinates, got " +
                     std::to_string(q_R.size()) + " and " + std::to_string(qdot_R.size()) + " velocities");
  const int nR_ = nR();
  q_r.resize(nr_);
  qdot_r.resize(nr_);
  J_rR.setZero(nr_, nR_);
  Jdot_rR.setZero(nr_, nR_);
  // identity rows [D Eq. 4.84]
  for (int j = 0; j < nR_; ++j) {
    const int r = independent_[j];
    q_r[r] = q_R[j];
    qdot_r[r] = qdot_R[j];
    J_rR(r, j) = 1.0;
  }
  // dependent rows in dependency order (chain rule through earlier rows):
  //   J_d    = s sum_k g_k J_ak
  //   Jdot_d = s sum_k (g_k Jdot_ak + sum_l H_kl qdot_al J_ak)
  VecJ x, xdot;
  FunctionValue fv;
  for (const Dependent& d : deps_) {
    const long n = static_cast<long>(d.args.size());
    x.resize(n);
    xdot.resize(n);
    for (long k = 0; k < n; ++k) {
      x[k] = q_r[d.args[k]];
      xdot[k] = qdot_r[d.args[k]];
    }
    evaluateWithArguments(*d.f, x, 2, fv);
    const VecJ& g = fv.gradient;
    const VecJ Hxdot = fv.hessian * xdot;
    q_r[d.index] = d.scale * fv.value;
    for (long k = 0; k < n; ++k) {
      const int a = d.args[k];
      J_rR.row(d.index) += (d.scale * g[k]) * J_rR.row(a);
      Jdot_rR.row(d.index) += (d.scale * g[k]) * Jdot_rR.row(a) + (d.scale * Hxdot[k]) * J_rR.row(a);
    }
    qdot_r[d.index] = J_rR.row(d.index).dot(qdot_R);
  }
}

VecX CoordinateMap::reduce(const VecX& v_r) const {
  if (v_r.size() != nr_)
    throw ModelError("coordinate map: expected " + std::to_string(nr_) + " skeleton coordinates, got " +
                     std::to_string(v_r.size()));
  VecX v(nR());
  for (int j = 0; j < nR(); ++j) v[j] = v_r[independent_[j]];
  return v;
}

}  // namespace redmax
