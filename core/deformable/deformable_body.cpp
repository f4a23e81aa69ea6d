#include "core/deformable/deformable_body.hpp"

#include <cmath>
#include <stdexcept>

#include "core/deformable/elements.hpp"

namespace redmax {

DeformableBody makeStrand(const std::vector<Vec3>& points, double mass, double stiffness) {
  if (points.size() < 2) throw std::invalid_argument("makeStrand: a strand needs at least 2 points");
  if (!(mass > 0) || !(stiffness > 0)) throw std::invalid_argument("makeStrand: mass and stiffness must be positive");
  DeformableBody b;
  b.rest = points;
  b.mass.assign(points.size(), 0.0);
  double total = 0;
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    const double L = (points[i + 1] - points[i]).norm();
    if (!(L > 0)) throw std::invalid_argument("makeStrand: zero-length segment " + std::to_string(i));
    b.springs.push_back({static_cast<int>(i), static_cast<int>(i + 1), L, stiffness});
    total += L;
  }
  for (const Spring& s : b.springs) {
    b.mass[s.a] += 0.5 * mass * s.rest_length / total;
    b.mass[s.b] += 0.5 * mass * s.rest_length / total;
  }
  return b;
}

DeformableBody makeFemBody(const TetMesh& mesh, double E, double nu, double rho, MassModel mass_model) {
  if (!(E > 0) || !(rho > 0) || !(nu >= 0 && nu < 0.5))
    throw std::invalid_argument("makeFemBody: need E > 0, rho > 0 and 0 <= nu < 0.5");
  DeformableBody b;
  b.rest = mesh.nodes;
  b.mass.assign(mesh.nodes.size(), 0.0);
  b.mesh = mesh;
  const double mu = lameMu(E, nu), lambda = lameLambda(E, nu);
  std::vector<Eigen::Triplet<double>> consistent;
  for (int t = 0; t < mesh.numTets(); ++t) {
    Tet tet;
    tet.n = mesh.tets[t];
    Mat3 Dm;
    Dm << mesh.nodes[tet.n[1]] - mesh.nodes[tet.n[0]], mesh.nodes[tet.n[2]] - mesh.nodes[tet.n[0]],
        mesh.nodes[tet.n[3]] - mesh.nodes[tet.n[0]];
    tet.volume = std::abs(Dm.determinant()) / 6.0;
    if (!(tet.volume > 0)) throw std::invalid_argument("makeFemBody: degenerate tet " + std::to_string(t));
    tet.Dm_inv = Dm.inverse();
    tet.mu = mu;
    tet.lambda = lambda;
    for (int a = 0; a < 4; ++a) b.mass[tet.n[a]] += 0.25 * rho * tet.volume;
    if (mass_model == MassModel::Consistent)
      for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 4; ++c) consistent.emplace_back(tet.n[a], tet.n[c], rho * tet.volume / (a == c ? 10.0 : 20.0));
    b.tets.push_back(tet);
  }
  if (mass_model == MassModel::Consistent) {
    const int N = static_cast<int>(mesh.nodes.size());
    b.node_mass.resize(N, N);
    b.node_mass.setFromTriplets(consistent.begin(), consistent.end());
  }
  return b;
}

SparseMat nodeMassMatrix(const DeformableBody& body) {
  const int N = body.numNodes();
  SparseMat M(3 * N, 3 * N);
  std::vector<Eigen::Triplet<double>> t;
  if (body.node_mass.nonZeros() > 0) {
    for (int col = 0; col < body.node_mass.outerSize(); ++col)
      for (SparseMat::InnerIterator it(body.node_mass, col); it; ++it)
        for (int c = 0; c < 3; ++c) t.emplace_back(3 * static_cast<int>(it.row()) + c, 3 * col + c, it.value());
  } else {
    for (int n = 0; n < N; ++n)
      for (int c = 0; c < 3; ++c) t.emplace_back(3 * n + c, 3 * n + c, body.mass[n]);
  }
  M.setFromTriplets(t.begin(), t.end());
  return M;
}

VecX restPositions(const DeformableBody& body) {
  VecX x(3 * body.numNodes());
  for (int n = 0; n < body.numNodes(); ++n) x.segment<3>(3 * n) = body.rest[n];
  return x;
}

void evalElastic(const DeformableBody& body, const VecX& x, bool stiffness, ElasticEvaluation& out) {
  const int n3 = 3 * body.numNodes();
  out.energy = 0.0;
  out.f.setZero(n3);
  std::vector<Eigen::Triplet<double>> trip;
  if (stiffness) trip.reserve(36 * body.springs.size() + 144 * body.tets.size());
  for (const Spring& s : body.springs) {
    Vec3 f0;
    Mat3 H;
    out.energy += springEnergyForce(x.segment<3>(3 * s.a), x.segment<3>(3 * s.b), s.rest_length, s.stiffness, &f0,
                                    stiffness ? &H : nullptr);
    out.f.segment<3>(3 * s.a) += f0;
    out.f.segment<3>(3 * s.b) -= f0;
    if (!stiffness) continue;
    const int idx[2] = {s.a, s.b};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) trip.emplace_back(3 * idx[i] + r, 3 * idx[j] + c, (i == j ? 1.0 : -1.0) * H(r, c));
  }
  Eigen::Matrix<double, 12, 1> fe;
  Eigen::Matrix<double, 12, 12> Ke;
  std::array<Vec3, 4> xe;
  for (const Tet& t : body.tets) {
    for (int a = 0; a < 4; ++a) xe[a] = x.segment<3>(3 * t.n[a]);
    out.energy += tetEnergyForce(xe, t.Dm_inv, t.volume, t.mu, t.lambda, &fe, stiffness ? &Ke : nullptr);
    for (int a = 0; a < 4; ++a) out.f.segment<3>(3 * t.n[a]) += fe.segment<3>(3 * a);
    if (!stiffness) continue;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) trip.emplace_back(3 * t.n[a] + r, 3 * t.n[b] + c, Ke(3 * a + r, 3 * b + c));
  }
  if (stiffness) {
    out.K.resize(n3, n3);
    out.K.setFromTriplets(trip.begin(), trip.end());
  }
}

}  // namespace redmax
