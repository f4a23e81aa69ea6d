#include "core/dynamics/unilateral/held_contacts.hpp"

#include <algorithm>
#include <cmath>

#include "core/skeleton/kinematics.hpp"

namespace redmax {

int findCandidate(const UnilateralRows& rows, const ContactKey& key) {
  for (size_t i = 0; i < rows.c.size(); ++i)
    if (ContactKey::of(rows.c[i]) == key) return static_cast<int>(i);
  return -1;
}

HeldContacts::HeldContacts(std::shared_ptr<const UnilateralConstraints> u, std::vector<HeldContact> held,
                           HeldContactOptions opt)
    : u_(std::move(u)), held_(std::move(held)), opt_(opt) {
  if (!u_) throw ModelError("HeldContacts: no unilateral constraints");
  if (!(opt_.omega >= 0.0)) throw ModelError("HeldContacts: negative Baumgarte rate");
  sources_.pairs.assign(u_->pairs().size(), 0);
  sources_.limits.assign(u_->limits().size(), 0);
  for (const HeldContact& h : held_) {
    auto& on = h.key.limit ? sources_.limits : sources_.pairs;
    if (h.key.source < 0 || h.key.source >= static_cast<int>(on.size()))
      throw ModelError("HeldContacts: a held contact names no pair or limit of the constraints");
    on[h.key.source] = 1;
    first_.push_back(rows_);
    rows_ += 1;
    for (int k = 0; k < 2; ++k) {
      if (h.key.limit || h.mu == 0.0) {
        if (h.slide[k] != 0) throw ModelError("HeldContacts: a frictionless contact cannot slide with friction");
        continue;
      }
      if (h.slide[k] == 0) rows_ += 1;
      else sliding_ = true;
    }
  }
}

void HeldContacts::rowsAt(const Model& model, const State& s, const SkeletonWorkspace& sk, MatX& G,
                          VecX& gap) const {
  const int nr = model.nr();
  UnilateralRows rows;
  u_->detect(model, s, sk, nr, 1.0, rows, &sources_);
  G.setZero(rows_, nr);
  gap.setZero(rows_);
  for (size_t i = 0; i < held_.size(); ++i) {
    const HeldContact& h = held_[i];
    const int c = findCandidate(rows, h.key);
    if (c < 0) throw ModelError("HeldContacts: a held contact has no row (its bodies cannot move)");
    int r = first_[i];
    G.row(r) = rows.Jn.row(c).head(nr);
    gap[r] = rows.c[c].gap;
    ++r;
    const int t = rows.c[c].tangent_row;
    for (int k = 0; k < 2; ++k) {
      if (h.key.limit || h.mu == 0.0 || h.slide[k] != 0) continue;
      G.row(r++) = rows.Jt.row(t + k).head(nr);
    }
  }
}

void HeldContacts::calcAcceleration(const Model& model, const State& s, const SkeletonWorkspace& sk,
                                    Eigen::Ref<MatX> G, Eigen::Ref<VecX> rhs) const {
  const int nr = model.nr();
  MatX J;
  VecX gap;
  rowsAt(model, s, sk, J, gap);
  G = J;
  const VecX qdot = s.qdot.head(nr);
  const VecX w = J * qdot;
  // Jdot qdot by a central difference along the motion: q -/+ e qdot (qdot is the exact rate of q)
  VecX bias = VecX::Zero(rows_);
  const double vmax = qdot.lpNorm<Eigen::Infinity>();
  if (vmax > 0.0) {
    const double e = 1e-6 / std::max(vmax, 1e-6);
    SkeletonWorkspace sk2(model);
    State x = s;
    MatX Jp, Jm;
    VecX g2;
    x.q.head(nr) = s.q.head(nr) + e * qdot;
    calcKinematics(model, x, sk2);
    rowsAt(model, x, sk2, Jp, g2);
    x.q.head(nr) = s.q.head(nr) - e * qdot;
    calcKinematics(model, x, sk2);
    rowsAt(model, x, sk2, Jm, g2);
    bias = (Jp - Jm) * qdot / (2.0 * e);
  }
  const double w0 = opt_.omega;
  rhs = -bias - 2.0 * w0 * w - w0 * w0 * gap;
}

void HeldContacts::calcErrors(const Model& model, const State& s, const SkeletonWorkspace& sk,
                              Eigen::Ref<VecX> pos_err, Eigen::Ref<VecX> vel_err) const {
  MatX J;
  VecX gap;
  rowsAt(model, s, sk, J, gap);
  pos_err = gap;
  vel_err = J * s.qdot.head(model.nr());
}

void HeldContacts::calcForceRows(const Model& model, const State& s, const SkeletonWorkspace& sk,
                                 Eigen::Ref<MatX> H) const {
  const int nr = model.nr();
  UnilateralRows rows;
  u_->detect(model, s, sk, nr, 1.0, rows, &sources_);
  for (size_t i = 0; i < held_.size(); ++i) {
    const HeldContact& h = held_[i];
    if (h.slide[0] == 0 && h.slide[1] == 0) continue;
    const int c = findCandidate(rows, h.key);
    if (c < 0) throw ModelError("HeldContacts: a held contact has no row (its bodies cannot move)");
    const int t = rows.c[c].tangent_row;
    for (int k = 0; k < 2; ++k)
      if (h.slide[k] != 0) H.row(first_[i]) -= h.mu * h.slide[k] * rows.Jt.row(t + k).head(nr);
  }
}

}  // namespace redmax
