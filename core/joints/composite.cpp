#include "core/joints/composite.hpp"

#include <algorithm>
#include <string>

#include "core/joints/joint.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

Composite::Composite() = default;

Composite::Composite(std::vector<Joint> p) : parts(std::move(p)) {
  int n = 0;
  for (const Joint& j : parts) n += j.nq();
  if (n > 6)
    throw JointError("composite joint has " + std::to_string(n) +
                     " coordinates; a joint may have at most 6");
}

int Composite::nq() const {
  int n = 0;
  for (const Joint& j : parts) n += j.nq();
  return n;
}

void Composite::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  out.resize(nq());
  out.Q.setIdentity();
  JointKinematics part;
  int off = 0;
  for (const Joint& j : parts) {
    const int n = j.nq();
    const VecJ qk = q.segment(off, n);
    const VecJ qdk = qdot.segment(off, n);
    j.calc(qk, qdk, part);
    if (off > 0) {
      // move the earlier columns into this part's child frame [D Eq. 4.48, 4.50]
      const Mat6 A = AdInv(part.Q);
      const Mat6X AS = A * out.S.leftCols(off);
      const Vec6 psi = part.S * qdk;
      out.Sdot.leftCols(off) = A * out.Sdot.leftCols(off) - ad(psi) * AS;
      out.S.leftCols(off) = AS;
    }
    out.S.middleCols(off, n) = part.S;
    out.Sdot.middleCols(off, n) = part.Sdot;
    out.Q = out.Q * part.Q;
    off += n;
  }
}

double Composite::singularityDistance(const VecJ& q) const {
  double d = 1.0;
  int off = 0;
  for (const Joint& j : parts) {
    const int n = j.nq();
    d = std::min(d, j.singularityDistance(q.segment(off, n)));
    off += n;
  }
  return d;
}

bool Composite::reparameterize(VecJ& q, VecJ& qdot) const {
  bool changed = false;
  int off = 0;
  for (const Joint& j : parts) {
    const int n = j.nq();
    VecJ qk = q.segment(off, n), qdk = qdot.segment(off, n);
    if (j.reparameterize(qk, qdk)) {
      q.segment(off, n) = qk;
      qdot.segment(off, n) = qdk;
      changed = true;
    }
    off += n;
  }
  return changed;
}

}  // namespace redmax
