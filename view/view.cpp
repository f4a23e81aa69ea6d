#include "view/view.hpp"

#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "converter/build/build_core_model.hpp"
#include "converter/coordinates_file.hpp"
#include "converter/json_writer.hpp"
#include "converter/mesh_file.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "core/muscles/wrap/wrap_path.hpp"
#include "core/skeleton/kinematics.hpp"
#include "core/skeleton/workspace.hpp"

namespace redmax::view {

namespace fs = std::filesystem;

namespace {

// positions to 1 micrometre at 1 m, quaternions to 1e-6: below a pixel of any view
constexpr int kDigits = 6;
// samples of a wrap arc between its tangent points (drawn as a polyline)
constexpr int kArcSamples = 12;

// kinds of the points of a drawn path (view.js draws a marker for 0-2)
enum PointKind { kPathPoint = 0, kMovingPoint = 1, kTangentPoint = 2, kArcSample = 3 };

// pose as position and quaternion (x, y, z, w): 7 numbers
void appendPose(const Mat4& E, std::vector<double>& out) {
  const Eigen::Quaterniond q(Mat3(E.topLeftCorner<3, 3>()));
  out.insert(out.end(), {E(0, 3), E(1, 3), E(2, 3), q.x(), q.y(), q.z(), q.w()});
}

void writePose(osim::JsonWriter& w, const char* key, const Mat4& E) {
  std::vector<double> p;
  appendPose(E, p);
  w.key(key).compactNumbers(p.data(), 7, kDigits);
}

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

Mat4 poseInWorld(const std::vector<Mat4>& E_wi, int body, const Mat4& E_b) {
  return body >= 0 ? Mat4(E_wi[body] * E_b) : E_b;
}

// the meshes of each core body, read from the model's folder or its Geometry/; what cannot be
// drawn goes to `messages`
struct BodyMesh {
  std::string file;
  Vec3 scale;
  Mat4 X_body;
  osim::TriangleMesh mesh;
};

std::vector<std::vector<BodyMesh>> readBodyMeshes(const osim::ModelDescription& d, const Model& skel,
                                                  std::vector<std::string>& messages) {
  std::vector<std::vector<BodyMesh>> out(skel.nb());
  std::vector<std::string> dropped, missing, unreadable;
  const std::vector<osim::MeshAttachment> attached = osim::readMeshAttachments(d, dropped);
  const std::string dir = fs::path(d.source_file).parent_path().string();
  int named = 0;
  for (const osim::MeshAttachment& a : attached) {
    const int b = skel.findBody(a.body);
    if (b < 0) continue;  // ground's meshes: not drawn (the floor of a scene)
    ++named;
    const std::string file = osim::findMeshFile(dir.empty() ? "." : dir, a.mesh_file);
    if (file.empty()) {
      missing.push_back(a.mesh_file);
      continue;
    }
    try {
      out[b].push_back({a.mesh_file, a.scale, a.X_body, osim::readMeshFile(file)});
    } catch (const std::exception& e) {
      unreadable.push_back(e.what());
    }
  }
  for (const std::string& s : dropped) messages.push_back(d.source_file + ":" + s + "; not drawn");
  if (named == 0)
    messages.push_back("the model names no mesh files: bodies are drawn as ellipsoids of their inertia "
                       "(uniform density)");
  if (!missing.empty())
    messages.push_back(std::to_string(missing.size()) + " of " + std::to_string(named) +
                       " mesh files not found beside the model or in its Geometry folder (" + missing.front() +
                       (missing.size() > 1 ? ", ..." : "") + "): bodies without a mesh are drawn as ellipsoids "
                       "of their inertia");
  for (const std::string& u : unreadable) messages.push_back("mesh not drawn: " + u);
  return out;
}

// the wrapped path as drawn: its points, tangent points and arc samples on the surfaces
void drawnPath(const MusclePath& path, const WrappedPath& wp, const std::vector<Mat4>& E_wi, std::vector<double>& x,
               std::vector<int>& kind) {
  x.clear();
  kind.clear();
  auto add = [&](const Vec3& p, int k) {
    x.insert(x.end(), {p.x(), p.y(), p.z()});
    kind.push_back(k);
  };
  for (size_t i = 0; i < wp.points.size(); ++i) {
    const WrappedPathPoint& p = wp.points[i];
    if (p.point >= 0) {
      add(p.x_w, path.points[p.point].kind == PathPointKind::Fixed ? kPathPoint : kMovingPoint);
      continue;
    }
    add(p.x_w, kTangentPoint);
    // r1 followed by r2 of the same surface: the arc between them
    if (p.which == 1 && i + 1 < wp.points.size() && wp.points[i + 1].wrap == p.wrap) {
      const PathWrap& w = path.wraps[p.wrap];
      const Mat4 E_ws = poseInWorld(E_wi, w.body, w.E_bs);
      for (int s = 1; s < kArcSamples; ++s)
        add(transformPoint(E_ws, wp.results[p.wrap].arcPoint(static_cast<double>(s) / kArcSamples)), kArcSample);
    }
  }
}

void writeSurface(osim::JsonWriter& w, const WrapSurface& s) {
  w.key("type").value(wrapTypeName(s.type));
  switch (s.type) {
    case WrapType::Cylinder: w.key("radius").value(s.radius).key("length").value(s.length); break;
    case WrapType::Sphere: w.key("radius").value(s.radius); break;
    case WrapType::Ellipsoid: w.key("dimensions").compactNumbers(s.dimensions.data(), 3, kDigits); break;
    case WrapType::Torus: w.key("inner_radius").value(s.inner_radius).key("outer_radius").value(s.outer_radius); break;
  }
}

bool isView(const fs::path& dir) {
  return fs::is_regular_file(dir / "data.js") && fs::is_regular_file(dir / "view.js");
}

}  // namespace

void inertiaEllipsoid(double mass, const Mat3& I_com, Vec3& radii, Mat3& axes) {
  radii.setZero();
  axes.setIdentity();
  if (!(mass > 0.0)) return;
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (I_com + I_com.transpose()));
  const Vec3 I = eig.eigenvalues();
  axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) *= -1.0;
  for (int a = 0; a < 3; ++a) {
    const double sq = 5.0 * (I[(a + 1) % 3] + I[(a + 2) % 3] - I[a]) / (2.0 * mass);
    radii[a] = sq > 0.0 ? std::sqrt(sq) : 0.0;
  }
  const double floor = 0.02 * radii.maxCoeff();
  for (int a = 0; a < 3; ++a) radii[a] = std::max(radii[a], floor);
}

ViewAssets findViewAssets(const std::vector<std::string>& folders) {
  std::string searched;
  for (const std::string& f : folders) {
    if (f.empty()) continue;
    searched += (searched.empty() ? "" : ", ") + f;
    const fs::path d(f);
    std::error_code ec;
    ViewAssets a{(d / "index.html").string(), (d / "view.js").string(), (d / "view.css").string(), ""};
    if (!fs::is_regular_file(a.index_html, ec) || !fs::is_regular_file(a.view_js, ec) ||
        !fs::is_regular_file(a.view_css, ec))
      continue;
    for (const fs::path& t : {d / "three.min.js", d / "node_modules" / "three" / "build" / "three.min.js"})
      if (fs::is_regular_file(t, ec)) {
        a.three_js = t.string();
        return a;
      }
  }
  throw std::runtime_error("the page's files (index.html, view.js, view.css, three.min.js) are not in " + searched +
                           " (scripts/setup runs `npm ci` in view/web and the build copies them; docs/view.md)");
}

ViewSummary writeView(const ViewInput& in, const ViewAssets& assets, const std::string& out_dir) {
  const osim::ModelDescription& d = in.description;
  ViewSummary sum;
  std::vector<std::string>& messages = sum.messages;

  // the model as the engine builds it, with its muscle mass; constraints are not enforced (the
  // motion's coordinates are drawn as written, as `redmax lengths` takes them)
  osim::BuildOptions bo;
  bo.constraints = false;
  osim::BuildResult build;
  std::vector<VecX> q_rows;
  std::vector<double> times{0.0};
  const bool with_mass = in.mass.source != osim::MuscleMassOptions::Source::None;
  osim::MuscleMassPlan plan;
  try {
    build = osim::buildCoreModel(d, bo);
    if (!in.motion_file.empty()) {
      const osim::CoordinateRows rows =
          osim::coordinateRows(in.motion, d.coordinates, build.coordinate_index, build.model.skeleton().nr(),
                               in.motion_file);
      if (rows.q.empty()) throw osim::ConvertError(in.motion_file, 0, "no rows");
      q_rows = rows.q;
      times = in.motion.time;
      if (rows.missing > 0)
        messages.push_back(std::to_string(rows.missing) + " coordinates are not in " +
                           fs::path(in.motion_file).filename().string() + ": held at their default values");
    } else {
      q_rows.push_back(build.model.skeleton().defaultQ());
      messages.push_back("no motion given (--motion): the model at its default pose");
    }
    if (with_mass) {
      osim::MuscleMassModel mm = osim::addMuscleMass(d, std::move(build), in.mass, q_rows);
      build = std::move(mm.build);
      plan = std::move(mm.plan);
      sum.mass_plan = osim::describeMuscleMass(plan);
    }
  } catch (const osim::ConvertError&) {
    throw;
  } catch (const std::exception& e) {
    throw osim::ConvertError(d.source_file, 0, std::string("the core cannot build this model: ") + e.what());
  }
  if (!with_mass) messages.push_back("no muscle mass (--muscle-mass none): no mass points to draw");
  for (const auto& u : build.unsupported)
    messages.push_back("not drawn: " + d.source_file + ":" + std::to_string(u.line) + ": " + u.what);

  const MusculoskeletalModel& mm = build.model;
  const Model& skel = mm.skeleton();
  const std::vector<Muscle>& muscles = mm.muscles();
  const std::vector<std::vector<BodyMesh>> meshes = readBodyMeshes(d, skel, messages);

  osim::JsonWriter w;
  w.beginObject();
  w.key("format").value("redmax view 1");
  w.key("model").value(d.name).key("model_file").value(fs::path(d.source_file).filename().string());
  w.key("motion_file").value(in.motion_file.empty() ? "" : fs::path(in.motion_file).filename().string());
  w.key("muscle_mass").value(osim::toString(in.mass.source));

  // bodies: mass, the inertia ellipsoid, meshes
  w.key("bodies").beginArray();
  for (int b = 0; b < skel.nb(); ++b) {
    const Body& body = skel.bodies()[b];
    w.beginObject().key("name").value(body.name).key("mass").value(body.mass);
    Vec3 radii;
    Mat3 axes;
    inertiaEllipsoid(body.mass, body.inertia_com, radii, axes);
    Mat4 E = Mat4::Identity();
    E.topLeftCorner<3, 3>() = axes;
    E.topRightCorner<3, 1>() = body.com;
    writePose(w, "ellipsoid_pose", E);
    w.key("ellipsoid_radii").compactNumbers(radii.data(), 3, kDigits);
    const JointSlot& j = skel.joints()[b];
    w.key("joint").value(j.name).key("parent").value(j.parent);
    writePose(w, "joint_frame", j.E_mi.inverse());  // frame M in the body
    w.key("meshes").beginArray();
    for (const BodyMesh& m : meshes[b]) {
      ++sum.meshes;
      w.beginObject().key("file").value(m.file);
      writePose(w, "pose", m.X_body);
      w.key("scale").compactNumbers(m.scale.data(), 3, kDigits);
      w.key("vertices").compactNumbers(m.mesh.vertices.data(), static_cast<int>(m.mesh.vertices.size()), kDigits);
      w.key("triangles").compactIntegers(m.mesh.triangles.data(), static_cast<int>(m.mesh.triangles.size()));
      w.endObject();
    }
    w.endArray().endObject();
  }
  w.endArray();
  sum.bodies = skel.nb();

  // wrap surfaces (each object once, however many paths use it) and muscles
  std::map<std::pair<std::string, int>, int> surface_index;
  w.key("wrap_surfaces").beginArray();
  for (const Muscle& mu : muscles)
    for (const PathWrap& pw : mu.path.wraps) {
      const auto key = std::make_pair(pw.name, pw.body);
      if (surface_index.count(key)) continue;
      surface_index[key] = static_cast<int>(surface_index.size());
      w.beginObject().key("name").value(pw.name).key("body").value(pw.body);
      writeSurface(w, pw.surface);
      writePose(w, "pose", pw.E_bs);
      w.endObject();
    }
  w.endArray();
  w.key("muscles").beginArray();
  for (size_t k = 0; k < muscles.size(); ++k) {
    const Muscle& mu = muscles[k];
    const osim::PathForceDesc& src = d.muscles[build.muscle_source[k]];
    w.beginObject().key("name").value(mu.name).key("class").value(src.class_name);
    w.key("path_type").value(pathTypeName(pathType(mu.path)));
    w.key("mass").value(mu.mass_points.totalMass()).key("mass_points").value(mu.mass_points.size());
    w.key("point_masses").compactNumbers(mu.mass_points.mass.data(), mu.mass_points.size(), kDigits);
    std::string lumped;
    if (with_mass && k < plan.muscles.size()) lumped = plan.muscles[k].lumped_why;
    w.key("lumped_why").value(lumped);
    w.key("wraps").beginArray();
    for (const PathWrap& pw : mu.path.wraps) w.value(surface_index.at({pw.name, pw.body}));
    w.endArray().endObject();
    sum.mass_points += mu.mass_points.size();
    sum.muscle_mass += mu.mass_points.totalMass();
  }
  w.endArray();
  sum.muscles = static_cast<int>(muscles.size());

  // frames: body poses, drawn paths, mass points, lengths
  w.key("times").compactNumbers(times.data(), static_cast<int>(times.size()), 10);
  w.key("frames").beginArray();
  SkeletonWorkspace sk(skel);
  MuscleWorkspace mws(skel, muscles);
  State s;
  s.qdot = VecX::Zero(skel.nr());
  std::vector<double> x, poses;
  std::vector<int> kind;
  for (size_t f = 0; f < q_rows.size(); ++f) {
    s.t = times[f];
    s.q = q_rows[f];
    calcKinematics(skel, s, sk);
    w.beginObject();
    poses.clear();
    for (int b = 0; b < skel.nb(); ++b) appendPose(sk.E_wi[b], poses);
    w.key("bodies").compactNumbers(poses.data(), static_cast<int>(poses.size()), kDigits);
    std::vector<double> lengths;
    w.key("paths").beginArray();
    for (const Muscle& mu : muscles) {
      const WrappedPath wp = calcWrappedPath(skel, mu.path, s.q, sk.E_wi);
      lengths.push_back(wp.length);
      drawnPath(mu.path, wp, sk.E_wi, x, kind);
      w.beginObject().key("x").compactNumbers(x.data(), static_cast<int>(x.size()), kDigits);
      w.key("kind").compactIntegers(kind.data(), static_cast<int>(kind.size())).endObject();
    }
    w.endArray();
    w.key("lengths").compactNumbers(lengths.data(), static_cast<int>(lengths.size()), 8);
    w.key("mass_points").beginArray();
    for (size_t k = 0; k < muscles.size(); ++k) {
      x.clear();
      if (muscles[k].mass_points.size() > 0) {
        try {
          calcMuscleKinematics(skel, s, sk, muscles[k], mws.muscles[k], false);
        } catch (const MuscleError& e) {
          std::ostringstream os;
          os << "at t = " << s.t << " (row " << f + 1 << "): " << e.what();
          throw std::runtime_error(os.str());
        }
        for (const Vec3& p : mws.muscles[k].x_a) x.insert(x.end(), p.data(), p.data() + 3);
      }
      w.compactNumbers(x.data(), static_cast<int>(x.size()), kDigits);
    }
    w.endArray().endObject();
  }
  w.endArray();
  sum.frames = static_cast<int>(q_rows.size());
  w.key("messages").beginArray();
  for (const std::string& m : messages) w.value(m);
  w.endArray().endObject();

  // the folder: built beside the target, then swapped in
  const fs::path out = fs::absolute(out_dir).lexically_normal();
  const fs::path target = out.filename().empty() ? out.parent_path() : out;
  std::error_code ec;
  if (fs::exists(target, ec) && (!fs::is_directory(target, ec) || (!fs::is_empty(target, ec) && !isView(target))))
    throw osim::ConvertError(out_dir, 0, "exists and is not an earlier view: give a new folder");
  fs::create_directories(target.parent_path(), ec);
  const std::string tag = "." + std::to_string(::getpid());
  const fs::path tmp = target.string() + ".tmp" + tag, old = target.string() + ".old" + tag;
  fs::remove_all(tmp, ec);
  try {
    fs::create_directory(tmp);
    writeText(tmp / "data.js", "window.REDMAX_VIEW = " + w.str() + ";\n");
    for (const auto& [file, name] : {std::pair{&assets.index_html, "index.html"}, {&assets.view_js, "view.js"},
                                     {&assets.view_css, "view.css"}, {&assets.three_js, "three.min.js"}})
      fs::copy_file(*file, tmp / name);
    for (const auto& e : fs::directory_iterator(tmp)) sum.bytes += e.file_size();
    if (fs::exists(target)) fs::rename(target, old);
    fs::rename(tmp, target);
    fs::remove_all(old, ec);
  } catch (const std::exception& e) {
    fs::remove_all(tmp, ec);
    if (!fs::exists(target, ec) && fs::exists(old, ec)) fs::rename(old, target, ec);
    throw std::runtime_error(out_dir + ": cannot write the view: " + e.what());
  }
  return sum;
}

}  // namespace redmax::view
