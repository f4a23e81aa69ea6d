#include "core/joints/reversed.hpp"

#include "core/joints/joint.hpp"
#include "core/spatial/se3.hpp"

namespace redmax {

Reversed::Reversed() : inner(std::make_shared<const Joint>(Fixed{})) {}

Reversed::Reversed(Joint joint) : inner(std::make_shared<const Joint>(std::move(joint))) {}

int Reversed::nq() const { return inner->nq(); }

void Reversed::calc(const VecJ& q, const VecJ& qdot, JointKinematics& out) const {
  JointKinematics k;
  inner->calc(q, qdot, k);
  const int n = inner->nq();
  out.resize(n);
  out.Q = inverseE(k.Q);
  const Mat6 AdQ = Ad(k.Q);
  // twist of the inner joint, expressed in its M frame
  const Vec6 phi = k.S * qdot.head(n);
  out.S = -AdQ * k.S;
  out.Sdot = -AdQ * (ad(phi) * k.S + k.Sdot);
}

bool Reversed::reparameterize(VecJ& q, VecJ& qdot) const { return inner->reparameterize(q, qdot); }

double Reversed::singularityDistance(const VecJ& q) const { return inner->singularityDistance(q); }

}  // namespace redmax
