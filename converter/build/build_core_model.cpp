#include "converter/build/build_core_model.hpp"

#include <cmath>
#include <map>
#include <numbers>

#include "converter/build/functions_to_core.hpp"
#include "core/dynamics/constraints/coordinate_coupler.hpp"
#include "core/dynamics/constraints/point_constraint.hpp"
#include "core/dynamics/constraints/prescribed_coordinate.hpp"
#include "core/dynamics/constraints/weld_constraint.hpp"
#include "core/spatial/se3.hpp"

namespace redmax::osim {

namespace {

constexpr double kPi = std::numbers::pi;

std::string quoted(const std::string& s) { return "'" + s + "'"; }

// a function of one argument: sum_j w_j f_j(x) + c (moving-point locations given in an offset
// frame, moved into the body frame: x_b = R_bf f(q) + p_bf)
class LinearCombination final : public AxisFunction {
 public:
  LinearCombination(std::vector<AxisFunctionPtr> f, std::vector<double> w, double c)
      : f_(std::move(f)), w_(std::move(w)), c_(c) {}
  int numArgs() const override { return 1; }
  std::string typeName() const override { return "LinearCombination"; }
  void evaluate(const VecJ& x, int order, FunctionValue& out) const override {
    out.value = c_;
    if (order >= 1) out.gradient.setZero(1);
    if (order >= 2) out.hessian.setZero(1, 1);
    FunctionValue v;
    for (size_t j = 0; j < f_.size(); ++j) {
      if (w_[j] == 0.0) continue;
      f_[j]->evaluate(x, order, v);
      out.value += w_[j] * v.value;
      if (order >= 1) out.gradient[0] += w_[j] * v.gradient[0];
      if (order >= 2) out.hessian(0, 0) += w_[j] * v.hessian(0, 0);
    }
  }

 private:
  std::vector<AxisFunctionPtr> f_;
  std::vector<double> w_;
  double c_;
};

// a constant rigid transform as a joint of no coordinates: FunctionBased with constant body-fixed
// rotations about the given axes and constant translations along F's x, y, z
Joint constantTransform(const std::array<Vec3, 3>& rot_axes, const Vec3& angles, const Vec3& p) {
  std::array<TransformAxis, 6> axes;
  for (int k = 0; k < 3; ++k) {
    axes[k].axis = rot_axes[k];
    axes[k].function = std::make_shared<const ConstantFunction>(angles[k]);
    axes[k + 3].axis = Vec3::Unit(k);
    axes[k + 3].function = std::make_shared<const ConstantFunction>(p[k]);
  }
  return FunctionBased(0, std::move(axes), false);
}

void checkCoordinateCount(const ModelDescription& d, const JointDesc& j, int n) {
  if (static_cast<int>(j.coordinates.size()) != n)
    throw ConvertError(d.source_file, j.line,
                       j.type + " " + quoted(j.name) + " has " +
                           std::to_string(j.coordinates.size()) + " coordinates; the core joint has " +
                           std::to_string(n));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
CoreJoint makeCoreJoint(const ModelDescription& d, const JointDesc& j, bool simbody_compat) {
  CoreJoint out;
  const std::string& file = d.source_file;
  try {
    switch (j.kind) {
      case JointKind::Weld: out.joint = Fixed{}; break;
      case JointKind::Pin: out.joint = Revolute{Vec3::UnitZ()}; break;
      case JointKind::Slider: out.joint = Prismatic{Vec3::UnitX()}; break;
      case JointKind::Universal: out.joint = Universal{}; break;
      // Ball and Gimbal both have q = body-fixed XYZ angles (setUseEulerAngles, 3.2)
      case JointKind::Ball:
      case JointKind::Gimbal: out.joint = SphericalEuler{EulerSequence::XYZ}; break;
      case JointKind::Free: out.joint = Free3D::opensim(); break;
      case JointKind::Planar: {
        // q = (rz, tx, ty), X_FM = (Rz(rz), (tx, ty, 0) in F): rotation3 about z driven by q0,
        // translations along F's x and y by q1, q2 (null functions: identity or zero)
        std::array<TransformAxis, 6> axes;
        for (int k = 0; k < 3; ++k) axes[k].axis = axes[k + 3].axis = Vec3::Unit(k);
        axes[2].coordinates = {0};
        axes[3].coordinates = {1};
        axes[4].coordinates = {2};
        out.joint = FunctionBased(3, std::move(axes), false);
        break;
      }
      case JointKind::Ellipsoid: out.joint = Ellipsoid{j.radii}; break;
      case JointKind::Scapulothoracic: {
        // Simbody chain (OpenSim ScapulothoracicJoint::extendAddToSystem):
        //   F_e = X_PF C, Ellipsoid (radii y, x, z), M_e = C in massless body 1, C = Rz(pi/2);
        //   Pin with F = M = W = (R_w, o) (R_w's z axis = the winging direction), massless 2;
        //   Weld to the scapula's child frame.
        // X_FM = C X_e(q) C^-1 W Rz(q3) W^-1, a composite Ellipsoid, K = C^-1 W, Rz with
        // F' = F C and M' = M W. Any R_w with that z axis gives the same W Rz W^-1; we take
        // R_w = Rz(dir) Rx(-pi/2), so C^-1 R_w = Rz(dir - pi/2) Rx(-pi/2).
        const Vec3 radii(j.radii.y(), j.radii.x(), j.radii.z());
        const double dir = j.winging_direction;
        const Vec3 o(j.winging_origin.x(), j.winging_origin.y(), 0.0);
        const Mat3 C = rotationAboutAxis(2, kPi / 2);
        const Mat3 R_w = rotationAboutAxis(2, dir) * rotationAboutAxis(0, -kPi / 2);
        const Joint K = constantTransform({Vec3::UnitZ(), Vec3::UnitX(), Vec3::UnitY()},
                                          Vec3(dir - kPi / 2, -kPi / 2, 0.0), C.transpose() * o);
        out.joint = Composite({Joint(Ellipsoid{radii}), K, Joint(Revolute{Vec3::UnitZ()})});
        out.F_post = makeE(C, Vec3::Zero());
        out.M_post = makeE(R_w, o);
        break;
      }
      case JointKind::Custom: {
        const int nq = static_cast<int>(j.coordinates.size());
        std::array<TransformAxis, 6> axes;
        for (int k = 0; k < 6; ++k) {
          const TransformAxisDesc& a = j.spatial_transform[k];
          axes[k].axis = a.axis;
          axes[k].coordinates = a.mobilities;
          axes[k].function =
              makeCoreFunction(a.function, static_cast<int>(a.mobilities.size()), file,
                               "CustomJoint " + quoted(j.name) + " " + a.name);
        }
        out.joint = FunctionBased(nq, std::move(axes), simbody_compat);
        break;
      }
      case JointKind::Unsupported:
        throw ConvertError(file, j.line, j.type + " " + quoted(j.name) + " is not supported");
    }
  } catch (const JointError& e) {
    throw ConvertError(file, j.line, j.type + " " + quoted(j.name) + ": " + e.what());
  }
  checkCoordinateCount(d, j, out.joint.nq());
  return out;
}

// ---------------------------------------------------------------------------------------------
namespace {

class Builder {
 public:
  Builder(const ModelDescription& d, const BuildOptions& opt) : d_(d), opt_(opt), mb_(d.name) {}

  BuildResult build() {
    r_.options = opt_;
    r_.body_index.assign(d_.bodies.size(), -1);
    r_.coordinate_index.assign(d_.coordinates.size(), -1);
    mb_.setGravity(d_.gravity);
    countSlaves();
    for (const MobilizerDesc& m : d_.tree.mobilizers) addMobilizer(m);
    for (size_t k = 0; k < d_.bodies.size(); ++k)
      if (r_.body_index[k] < 0)
        r_.warnings.push_back("body " + quoted(d_.bodies[k].name) +
                              " is reached by no mobilizer and is left out");
    for (size_t ci = 0; ci < d_.coordinates.size(); ++ci) {
      const CoordinateDesc& c = d_.coordinates[ci];
      if (r_.coordinate_index[ci] >= 0 || c.joint_index < 0) continue;
      const JointDesc& j = d_.joints[c.joint_index];
      if (j.kind != JointKind::Unsupported)
        r_.unsupported.push_back({c.line, "coordinate " + quoted(c.name) + " of " + j.type + " " +
                                              quoted(j.name) +
                                              " has no mobilizer (the joint closes a loop) and "
                                              "is left out"});
    }
    try {
      skeleton_ = mb_.finalize();
    } catch (const ModelError& e) {
      // mass properties the reader passed but the core rejects (negative mass, NaN inertia)
      throw ConvertError(d_.source_file, 0, e.what());
    }
    model_ = std::make_unique<MusculoskeletalModelBuilder>(skeleton_);
    model_->settings().simbody_compat = opt_.simbody_compat;
    if (opt_.constraints) buildConstraints();
    if (opt_.muscles) buildMuscles();
    // every muscle was validated against the skeleton as it was added
    r_.model = model_->finalize();
    return std::move(r_);
  }

 private:
  // ---- bodies and joints -------------------------------------------------------------------
  void countSlaves() {
    for (const SlaveBodyDesc& s : d_.tree.slaves) {
      ++copies_[s.master];
      slave_master_[s.name] = s.master;
    }
  }

  // core index of a body or slave name; -1 for ground
  int coreBody(const std::string& name, int line) const {
    if (name == d_.ground_name) return -1;
    auto it = core_body_.find(name);
    if (it == core_body_.end())
      throw ConvertError(d_.source_file, line,
                         "body " + quoted(name) + " is not (yet) in the core model's tree");
    return it->second;
  }

  void addMobilizer(const MobilizerDesc& m) {
    if (m.joint < 0 || m.joint >= static_cast<int>(d_.joints.size()))
      throw ConvertError(d_.source_file, 0, "mobilizer of body " + quoted(m.outboard_body) +
                                                " refers to no joint");
    const JointDesc& j = d_.joints[m.joint];
    // the outboard body's mass properties (a slave shares its master's equally)
    auto sm = slave_master_.find(m.outboard_body);
    const std::string& mass_body = sm != slave_master_.end() ? sm->second : m.outboard_body;
    const int bi = d_.findBody(mass_body);
    if (bi < 0)
      throw ConvertError(d_.source_file, j.line,
                         "joint " + quoted(j.name) + " moves unknown body " + quoted(mass_body));
    const BodyDesc& b = d_.bodies[bi];
    if (!(b.mass >= 0.0) || !std::isfinite(b.mass) || !b.mass_center.allFinite() ||
        !b.inertia.allFinite())
      throw ConvertError(d_.source_file, b.line,
                         "body " + quoted(b.name) +
                             ": mass must be finite and >= 0, mass_center and inertia finite");
    auto cp = copies_.find(mass_body);
    const double share = cp == copies_.end() ? 1.0 : 1.0 / (1.0 + cp->second);
    const CoreMassProperties mp = coreMassProperties(b, share);
    if (mp.zeroed)
      r_.warnings.push_back("body " + quoted(b.name) +
                            " is massless; its nonzero inertia is set to zero, as Simbody does");

    CoreJoint cj;
    if (j.kind == JointKind::Unsupported) {
      // keep the tree: the body is welded at the joint's zero pose, its coordinates are dropped
      cj.joint = Fixed{};
      r_.unsupported.push_back({j.line, j.type + " " + quoted(j.name) +
                                            " is not modelled: body " +
                                            quoted(m.outboard_body) +
                                            " is welded to its parent and its " +
                                            std::to_string(j.coordinates.size()) +
                                            " coordinates are left out"});
    } else {
      cj = makeCoreJoint(d_, j, opt_.simbody_compat);
    }

    // F' = F F_post on the joint's parent, M' = M M_post on its child; a reversed joint swaps
    // the roles and inverts X_FM (Reversed), so its coordinates keep their meaning
    const Mat4 X_PF = j.X_PF * cj.F_post, X_BM = j.X_BM * cj.M_post;
    const int parent = coreBody(m.inboard_body, j.line);
    Joint joint = m.reversed ? Joint(Reversed(std::move(cj.joint))) : std::move(cj.joint);
    const Mat4& E_pf = m.reversed ? X_BM : X_PF;
    const Mat4& E_bm = m.reversed ? X_PF : X_BM;
    int body = -1;
    try {
      body = mb_.addBody(m.outboard_body, mp.mass, mp.com, mp.inertia_com, parent, j.name,
                         std::move(joint), E_pf, E_bm);
    } catch (const ModelError& e) {
      throw ConvertError(d_.source_file, j.line, "joint " + quoted(j.name) + ": " + e.what());
    }
    core_body_[m.outboard_body] = body;
    if (sm == slave_master_.end()) r_.body_index[bi] = body;
    r_.body_source.push_back(bi);
    r_.body_mass_share.push_back(share);

    // coordinates: names, defaults; q slots in creation order = the description's order
    if (j.kind == JointKind::Unsupported) return;
    std::vector<std::string> names;
    for (int ci : j.coordinates) names.push_back(d_.coordinates[ci].name);
    if (!names.empty()) mb_.setCoordinateNames(body, names);
    for (size_t k = 0; k < j.coordinates.size(); ++k) {
      const CoordinateDesc& c = d_.coordinates[j.coordinates[k]];
      mb_.coordinate(body, static_cast<int>(k)).default_value = c.default_value;
      r_.coordinate_index[j.coordinates[k]] = next_q_++;
    }
  }

  int coreCoordinate(const std::string& name, int line, const std::string& what) const {
    const int ci = d_.findCoordinate(name);
    if (ci < 0)
      throw ConvertError(d_.source_file, line, what + ": unknown coordinate " + quoted(name));
    return r_.coordinate_index[ci];
  }

  // ---- constraints -------------------------------------------------------------------------
  void buildConstraints() {
    std::shared_ptr<CoordinateMap> map;
    for (const ConstraintDesc& c : d_.constraints) {
      const std::string what = c.type + " " + quoted(c.name);
      if (!c.enforced) {
        r_.warnings.push_back(what + " is not enforced (isEnforced false) and is left out");
        continue;
      }
      try {
        switch (c.kind) {
          case ConstraintKind::CoordinateCoupler: {
            const int dep = coreCoordinate(c.dependent_coordinate, c.line, what);
            std::vector<int> indep;
            bool missing = dep < 0;
            for (const auto& n : c.independent_coordinates) {
              indep.push_back(coreCoordinate(n, c.line, what));
              missing = missing || indep.back() < 0;
            }
            if (missing) {
              r_.unsupported.push_back({c.line, what + ": a coordinate it couples is not modelled"});
              break;
            }
            if (!c.function)
              throw ConvertError(d_.source_file, c.line, what + " has no coupled_coordinates_function");
            const AxisFunctionPtr f = makeCoreFunction(*c.function, static_cast<int>(indep.size()),
                                                       d_.source_file, what);
            if (opt_.couplers == CouplerHandling::Eliminate) {
              if (!map) map = std::make_shared<CoordinateMap>(skeleton_);
              map->addDependent(dep, indep, f, c.scale_factor);
            } else {
              model_->addConstraint(std::make_shared<CoordinateCoupler>(
                  skeleton_, dep, indep, f, c.scale_factor, c.name));
            }
            break;
          }
          case ConstraintKind::Weld: {
            if (!opt_.body_constraints) break;
            const int b1 = coreBody(c.body1, c.line), b2 = coreBody(c.body2, c.line);
            model_->addConstraint(
                std::make_shared<WeldConstraint>(skeleton_, b1, c.X_B1F1, b2, c.X_B2F2, c.name));
            break;
          }
          case ConstraintKind::Point: {
            if (!opt_.body_constraints) break;
            const int b1 = coreBody(c.body1, c.line), b2 = coreBody(c.body2, c.line);
            model_->addConstraint(std::make_shared<PointConstraint>(
                skeleton_, b1, c.location1, b2, c.location2, c.name));
            break;
          }
          case ConstraintKind::Unsupported:
            r_.unsupported.push_back({c.line, what + " is not modelled"});
            break;
        }
      } catch (const ModelError& e) {
        throw ConvertError(d_.source_file, c.line, what + ": " + e.what());
      }
    }
    if (map) model_->setCoordinateMap(map);

    // locked and prescribed coordinates (PrescribedMotion constraints in OpenSim)
    for (size_t ci = 0; ci < d_.coordinates.size(); ++ci) {
      const CoordinateDesc& c = d_.coordinates[ci];
      const int k = r_.coordinate_index[ci];
      if (k < 0 || !(c.locked || c.prescribed)) continue;
      if (c.locked && opt_.locked_coordinates) {
        if (c.prescribed && c.prescribed_function)
          r_.warnings.push_back("coordinate " + quoted(c.name) +
                                " is locked and prescribed: it is held locked");
        model_->addConstraint(PrescribedCoordinate::makeLocked(skeleton_, k, c.default_value));
      } else if (!c.locked && c.prescribed && c.prescribed_function && opt_.prescribed_coordinates) {
        const std::string what = "coordinate " + quoted(c.name) + " prescribed_function";
        const AxisFunctionPtr f = makeCoreFunction(*c.prescribed_function, 1, d_.source_file, what);
        model_->addConstraint(
            std::make_shared<PrescribedCoordinate>(skeleton_, k, f, c.name + "_prescribed"));
      }
    }
  }

  // ---- muscles -----------------------------------------------------------------------------
  // body index and pose of the point's frame in that body; ground gives -1
  int pointBody(const PathPointDesc& p, const std::string& what) const {
    if (p.body == d_.ground_name) return -1;
    auto it = core_body_.find(p.body);
    if (it == core_body_.end())
      throw ConvertError(d_.source_file, p.line,
                         what + ": path point " + quoted(p.name) + " is on unknown body " +
                             quoted(p.body));
    return it->second;
  }

  PathPoint makePoint(const PathPointDesc& p, const std::string& what) const {
    const int body = pointBody(p, what);
    const Mat3 R = p.X_body_frame.topLeftCorner<3, 3>();
    const Vec3 t = p.X_body_frame.topRightCorner<3, 1>();
    switch (p.kind) {
      case PathPointKind::Fixed: return makeFixedPoint(body, R * p.location + t, p.name);
      case PathPointKind::Conditional: {
        // an unconnected coordinate: never active (-1), as in OpenSim
        int k = -1;
        if (!p.coordinate.empty()) k = coreCoordinate(p.coordinate, p.line, what);
        return makeConditionalPoint(body, R * p.location + t, k, p.range_min, p.range_max, p.name);
      }
      case PathPointKind::Moving: break;
    }
    // moving: every component is a function of one coordinate (clamped to its range); a
    // component without a coordinate is f(0), a constant
    std::string coord;
    for (const auto& c : p.location_coordinates)
      if (!c.empty()) {
        if (!coord.empty() && c != coord)
          throw ConvertError(d_.source_file, p.line,
                             what + ": moving path point " + quoted(p.name) +
                                 " names different coordinates (" + quoted(coord) + ", " +
                                 quoted(c) + ")");
        coord = c;
      }
    int k = -1, ci = -1;
    if (!coord.empty()) {
      ci = d_.findCoordinate(coord);
      k = coreCoordinate(coord, p.line, what);
    }
    std::array<AxisFunctionPtr, 3> f;
    static const char* kAxis[3] = {"x_location", "y_location", "z_location"};
    for (int a = 0; a < 3; ++a) {
      const std::string owner = what + ": moving path point " + quoted(p.name) + " " + kAxis[a];
      const AxisFunctionPtr fa = makeCoreFunction(p.location_functions[a], 1, d_.source_file, owner);
      if (p.location_coordinates[a].empty() || k < 0)
        f[a] = std::make_shared<const ConstantFunction>(fa->value(VecJ::Zero(1)), 1);
      else
        f[a] = fa;
    }
    // location given in an offset frame: x_b = R f + t, component by component
    if (!R.isIdentity(0.0) || !t.isZero(0.0)) {
      std::array<AxisFunctionPtr, 3> g;
      for (int a = 0; a < 3; ++a)
        g[a] = std::make_shared<const LinearCombination>(
            std::vector<AxisFunctionPtr>{f[0], f[1], f[2]},
            std::vector<double>{R(a, 0), R(a, 1), R(a, 2)}, t[a]);
      f = g;
    }
    PathPoint pp = makeMovingPoint(body, k, f, Vec3::Zero(), p.name);
    if (k >= 0) {
      // OpenSim evaluates at q clamped to the coordinate's range, whatever `clamped` says
      pp.clamp = true;
      pp.clamp_lo = d_.coordinates[ci].range_min;
      pp.clamp_hi = d_.coordinates[ci].range_max;
    }
    return pp;
  }

  // a PathWrap and the wrap object it names -> core PathWrap (surface frame pose in its body)
  PathWrap makeWrap(const PathWrapDesc& pw, const std::string& what) const {
    if (pw.wrap_index < 0 || pw.wrap_index >= static_cast<int>(d_.wrap_objects.size()))
      throw ConvertError(d_.source_file, pw.line,
                         what + ": wrap object " + quoted(pw.wrap_object) + " does not exist");
    const WrapObjectDesc& wo = d_.wrap_objects[pw.wrap_index];
    PathWrap w;
    w.name = wo.name;
    if (wo.body != d_.ground_name) {
      auto it = core_body_.find(wo.body);
      if (it == core_body_.end())
        throw ConvertError(d_.source_file, wo.line,
                           what + ": wrap object " + quoted(wo.name) + " is on unknown body " +
                               quoted(wo.body));
      w.body = it->second;
    }
    w.E_bs = wo.X_body;
    const int axis = wo.quadrant_sign == 0 ? -1 : wo.quadrant_axis;
    if (wo.type == "WrapCylinder")
      w.surface = WrapSurface::makeCylinder(wo.radius, wo.length, axis, wo.quadrant_sign);
    else if (wo.type == "WrapSphere")
      w.surface = WrapSurface::makeSphere(wo.radius, axis, wo.quadrant_sign);
    else if (wo.type == "WrapEllipsoid")
      w.surface = WrapSurface::makeEllipsoid(wo.dimensions, axis, wo.quadrant_sign);
    else
      w.surface = WrapSurface::makeTorus(wo.inner_radius, wo.outer_radius, axis, wo.quadrant_sign);
    w.surface.active = wo.active;
    // OpenSim's PathWrap method: hybrid unless midpoint or axial
    w.method = pw.method == "midpoint" ? WrapMethod::Midpoint
               : pw.method == "axial"  ? WrapMethod::Axial
                                       : WrapMethod::Hybrid;
    w.range_begin = pw.range_begin;
    w.range_end = pw.range_end;
    return w;
  }

  void buildMuscles() {
    for (size_t mi = 0; mi < d_.muscles.size(); ++mi) {
      const PathForceDesc& pf = d_.muscles[mi];
      const std::string what = pf.class_name + " " + quoted(pf.name);
      Muscle m;
      m.name = pf.name;
      m.optimal_fiber_length = pf.optimal_fiber_length;
      m.tendon_slack_length = pf.tendon_slack_length;
      for (const PathPointDesc& p : pf.points) m.path.points.push_back(makePoint(p, what));
      m.path.num_wraps = static_cast<int>(pf.wraps.size());
      for (const PathWrapDesc& pw : pf.wraps) m.path.wraps.push_back(makeWrap(pw, what));
      try {
        validateMuscle(skeleton_, m);
      } catch (const ModelError& e) {
        r_.unsupported.push_back({pf.line, what + " is left out: " + e.what()});
        continue;
      }
      // muscles carry their XML properties and, where redmax models the class, a force model
      if (pf.is_muscle) {
        try {
          model_->addMuscle(std::move(m), pf.class_name, pf.parameters);
        } catch (const hill::MuscleModelError& e) {
          throw ConvertError(d_.source_file, pf.line, what + ": " + e.what());
        }
      } else {
        model_->addMuscle(std::move(m), pf.class_name);
      }
      r_.muscle_source.push_back(static_cast<int>(mi));
    }
  }

  const ModelDescription& d_;
  const BuildOptions& opt_;
  ModelBuilder mb_;
  BuildResult r_;
  Model skeleton_;                                  // mb_ finalized
  std::unique_ptr<MusculoskeletalModelBuilder> model_;
  std::map<std::string, int> copies_;               // master body -> number of slaves
  std::map<std::string, std::string> slave_master_; // slave body -> master
  std::map<std::string, int> core_body_;            // body or slave name -> core index
  int next_q_ = 0;
};

}  // namespace

namespace {

// Numbers the reader accepts as OpenSim's parser does (strtod takes "nan" and "inf") but that no
// model can use: each one is an error at its element's line, before anything is built, so that a
// NaN never reaches a simulation.
void checkFiniteNumbers(const ModelDescription& d) {
  const std::string& file = d.source_file;
  auto fail = [&](int line, const std::string& what) { throw ConvertError(file, line, what); };
  if (!d.gravity.allFinite()) fail(0, "gravity is not finite");
  for (const FrameDesc& f : d.frames)
    if (!f.translation.allFinite() || !f.orientation.allFinite() || !f.X_base.allFinite())
      fail(f.line, "frame " + quoted(f.name) + ": translation or orientation is not finite");
  for (const JointDesc& j : d.joints) {
    if (!j.X_PF.allFinite() || !j.X_BM.allFinite())
      fail(j.line, j.type + " " + quoted(j.name) + ": a joint frame is not finite");
    if (!j.radii.allFinite() || !j.winging_origin.allFinite() || !std::isfinite(j.winging_direction))
      fail(j.line, j.type + " " + quoted(j.name) + ": radii or winging parameters are not finite");
    for (const TransformAxisDesc& a : j.spatial_transform)
      if (!a.axis.allFinite())
        fail(a.line ? a.line : j.line, j.type + " " + quoted(j.name) + ": axis of " + a.name + " is not finite");
  }
  for (const CoordinateDesc& c : d.coordinates) {
    if (!std::isfinite(c.default_value) || !std::isfinite(c.default_speed_value))
      fail(c.line, "coordinate " + quoted(c.name) + ": default value or speed is not finite");
    if (std::isnan(c.range_min) || std::isnan(c.range_max))
      fail(c.line, "coordinate " + quoted(c.name) + ": range is NaN");
  }
  std::vector<bool> used(d.wrap_objects.size(), false);
  for (const PathForceDesc& m : d.muscles) {
    for (const PathPointDesc& p : m.points)
      if (!p.location.allFinite() || !p.X_body_frame.allFinite() || std::isnan(p.range_min) ||
          std::isnan(p.range_max))
        fail(p.line ? p.line : m.line, quoted(m.name) + " path point " + quoted(p.name) + " is not finite");
    for (const PathWrapDesc& w : m.wraps)
      if (w.wrap_index >= 0 && w.wrap_index < static_cast<int>(used.size())) used[static_cast<size_t>(w.wrap_index)] = true;
  }
  for (size_t k = 0; k < d.wrap_objects.size(); ++k) {
    const WrapObjectDesc& w = d.wrap_objects[k];
    const std::string what = w.type + " " + quoted(w.name);
    if (!w.X_body.allFinite() || !std::isfinite(w.radius) || !std::isfinite(w.length) ||
        !w.dimensions.allFinite() || !std::isfinite(w.inner_radius) || !std::isfinite(w.outer_radius))
      fail(w.line, what + ": a size or its placement is not finite");
    if (!used[k]) continue;  // a size that no path uses cannot hurt
    bool ok = true;
    if (w.type == "WrapCylinder") ok = w.radius > 0.0 && w.length > 0.0;
    else if (w.type == "WrapSphere") ok = w.radius > 0.0;
    else if (w.type == "WrapEllipsoid") ok = (w.dimensions.array() > 0.0).all();
    else if (w.type == "WrapTorus") ok = w.inner_radius > 0.0 && w.outer_radius > 0.0;
    if (!ok) fail(w.line, what + ": its size must be positive");
  }
}

}  // namespace

BuildResult buildCoreModel(const ModelDescription& d, const BuildOptions& options) {
  checkFiniteNumbers(d);
  Builder b(d, options);
  return b.build();
}

CoreMassProperties coreMassProperties(const BodyDesc& b, double share) {
  CoreMassProperties p;
  p.mass = b.mass * share;
  p.com = b.mass_center;
  p.inertia_com = b.inertiaMatrix() * share;
  if (std::abs(p.mass) <= 1e-14 && !p.inertia_com.isZero(0.0)) {
    p.inertia_com.setZero();
    p.zeroed = true;
  }
  return p;
}

std::vector<Muscle> addMusclePointMasses(const std::vector<Muscle>& muscles,
                                         const std::vector<double>& masses,
                                         const MassPointOptions& options) {
  if (masses.size() != muscles.size())
    throw ModelError("addMusclePointMasses: " + std::to_string(masses.size()) + " masses for " +
                     std::to_string(muscles.size()) + " muscles");
  std::vector<Muscle> out = muscles;
  for (size_t k = 0; k < out.size(); ++k) {
    const double m = masses[k];
    if (!std::isfinite(m) || m < 0.0)
      throw ModelError("muscle '" + out[k].name + "': mass " + std::to_string(m) +
                       " is negative or not finite");
    if (m == 0.0) {
      out[k].mass_points = {};
      continue;
    }
    if (pathType(out[k].path) == redmax::PathType::III)
      throw ModelError("muscle '" + out[k].name +
                       "' wraps over surfaces (Type III): it cannot carry mass points yet");
    out[k].mass_points = makeMassPoints(m, out[k].optimal_fiber_length,
                                        out[k].tendon_slack_length, options);
  }
  return out;
}

}  // namespace redmax::osim
