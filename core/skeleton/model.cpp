#include "core/skeleton/model.hpp"

#include <algorithm>

namespace redmax {

bool Model::isAncestor(int a, int i) const {
  const auto& an = ancestors_[i];
  return std::find(an.begin(), an.end(), a) != an.end();
}

int Model::findBody(const std::string& n) const {
  for (int i = 0; i < nb(); ++i)
    if (bodies_[i].name == n) return i;
  return -1;
}

int Model::findCoordinate(const std::string& n) const {
  for (int k = 0; k < nr(); ++k)
    if (coordinates_[k].name == n) return k;
  return -1;
}

VecX Model::defaultQ() const {
  VecX q(nr());
  for (int k = 0; k < nr(); ++k) q[k] = coordinates_[k].default_value;
  return q;
}

ModelBuilder::ModelBuilder(std::string name) { m_.name_ = std::move(name); }

ModelBuilder::ModelBuilder(const Model& model) : m_(model) {}

void ModelBuilder::setName(std::string name) { m_.name_ = std::move(name); }

void ModelBuilder::setGravity(const Vec3& g) { m_.gravity_ = g; }

int ModelBuilder::addBody(const std::string& body_name, double mass, const Vec3& com,
                          const Mat3& inertia_com, int parent, const std::string& joint_name,
                          Joint joint, const Mat4& E_pf, const Mat4& E_bm) {
  const int i = m_.nb();
  if (parent < -1 || parent >= i)
    throw ModelError("body '" + body_name + "': parent index " + std::to_string(parent) +
                     " does not name an existing body");
  Body b;
  b.name = body_name;
  b.mass = mass;
  b.com = com;
  b.inertia_com = inertia_com;
  m_.bodies_.push_back(b);
  JointSlot s;
  s.name = joint_name;
  s.parent = parent;
  s.body = i;
  s.E_pf = E_pf;
  s.E_mi = inverseE(E_bm);
  s.nq = joint.nq();
  s.joint = std::move(joint);
  s.q_index = m_.nr_;
  m_.joints_.push_back(s);
  for (int k = 0; k < s.nq; ++k) {
    Coordinate c;
    c.name = joint_name + "_" + std::to_string(k);
    c.joint = i;
    m_.coordinates_.push_back(c);
  }
  m_.nr_ += s.nq;
  return i;
}

void ModelBuilder::setCoordinateNames(int body, const std::vector<std::string>& names) {
  const auto& s = m_.joints_.at(body);
  if (static_cast<int>(names.size()) != s.nq)
    throw ModelError("joint '" + s.name + "' has " + std::to_string(s.nq) + " coordinates, " +
                     std::to_string(names.size()) + " names given");
  for (int k = 0; k < s.nq; ++k) m_.coordinates_[s.q_index + k].name = names[k];
}

void ModelBuilder::setBodyMassProperties(int i, double mass, const Vec3& com, const Mat3& inertia_com) {
  if (i < 0 || i >= m_.nb()) throw ModelError("setBodyMassProperties: no body " + std::to_string(i));
  Body& b = m_.bodies_[i];
  b.mass = mass;
  b.com = com;
  b.inertia_com = inertia_com;
}

Coordinate& ModelBuilder::coordinateAt(int q_index) {
  if (q_index < 0 || q_index >= m_.nr_)
    throw ModelError("model '" + m_.name_ + "': no coordinate " + std::to_string(q_index));
  return m_.coordinates_[q_index];
}

Coordinate& ModelBuilder::coordinate(int body, int k) {
  const auto& s = m_.joints_.at(body);
  if (k < 0 || k >= s.nq) throw ModelError("joint '" + s.name + "': no coordinate " + std::to_string(k));
  return m_.coordinates_[s.q_index + k];
}

Model ModelBuilder::finalize() const {
  Model m = m_;
  m.ancestors_.assign(m.nb(), {});
  for (int i = 0; i < m.nb(); ++i) {
    Body& b = m.bodies_[i];
    if (!(b.mass >= 0.0)) throw ModelError("body '" + b.name + "': negative or NaN mass");
    if (!b.inertia_com.allFinite() || !b.com.allFinite())
      throw ModelError("body '" + b.name + "': non-finite centre of mass or inertia");
    b.M = spatialInertia(b.mass, b.com, b.inertia_com);
    // ancestors root-first: parent's list, then self
    const int p = m.joints_[i].parent;
    if (p >= 0) m.ancestors_[i] = m.ancestors_[p];
    m.ancestors_[i].push_back(i);
  }
  return m;
}

}  // namespace redmax
