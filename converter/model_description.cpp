#include "converter/model_description.hpp"

#include <cmath>

namespace redmax::osim {

Mat3 rotationBodyFixedXYZ(const Vec3& a) {
  // body-fixed (intrinsic) X then Y then Z: R = Rx(a0) Ry(a1) Rz(a2) [semantics §2]
  return (Eigen::AngleAxisd(a[0], Vec3::UnitX()) * Eigen::AngleAxisd(a[1], Vec3::UnitY()) *
          Eigen::AngleAxisd(a[2], Vec3::UnitZ()))
      .toRotationMatrix();
}

Mat4 makePose(const Vec3& translation, const Vec3& orientation) {
  Mat4 E = Mat4::Identity();
  E.topLeftCorner<3, 3>() = rotationBodyFixedXYZ(orientation);
  E.topRightCorner<3, 1>() = translation;
  return E;
}

int FunctionDesc::numArguments() const {
  switch (kind) {
    case FunctionKind::Constant: return 0;
    case FunctionKind::Linear: return static_cast<int>(coefficients.size()) - 1;
    case FunctionKind::MultivariatePolynomial: return dimension;
    case FunctionKind::Multiplier: return inner.empty() ? 0 : inner.front().numArguments();
    default: return 1;
  }
}

bool FunctionDesc::isUnitSlopeLinear() const {
  return kind == FunctionKind::Linear && !coefficients.empty() &&
         (coefficients[0] == 1.0 || coefficients[0] == -1.0);
}

Mat3 BodyDesc::inertiaMatrix() const {
  Mat3 I;
  I << inertia[0], inertia[3], inertia[4],  //
      inertia[3], inertia[1], inertia[5],   //
      inertia[4], inertia[5], inertia[2];
  return I;
}

const char* toString(MotionType m) {
  switch (m) {
    case MotionType::Rotational: return "Rotational";
    case MotionType::Translational: return "Translational";
    case MotionType::Coupled: return "Coupled";
    case MotionType::Undefined: break;
  }
  return "Undefined";
}

const char* toString(PathType t) {
  switch (t) {
    case PathType::I: return "I";
    case PathType::II: return "II";
    case PathType::III: break;
  }
  return "III";
}

namespace {
template <class V>
int findByName(const V& v, const std::string& name) {
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i].name == name) return static_cast<int>(i);
  return -1;
}
}  // namespace

int ModelDescription::findBody(const std::string& n) const { return findByName(bodies, n); }
int ModelDescription::findJoint(const std::string& n) const { return findByName(joints, n); }
int ModelDescription::findCoordinate(const std::string& n) const {
  return findByName(coordinates, n);
}
int ModelDescription::findWrapObject(const std::string& n) const {
  return findByName(wrap_objects, n);
}
int ModelDescription::findContactGeometry(const std::string& n) const {
  return findByName(contact_geometry, n);
}

}  // namespace redmax::osim
