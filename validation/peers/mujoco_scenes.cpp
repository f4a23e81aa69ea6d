#include "validation/peers/mujoco_scenes.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace redmax::peers {
namespace {

constexpr double kG = 9.81;  // the scenes' gravity (contact_scenes.cpp)

// <option> and the contact defaults every scene shares; `condim` 1 is frictionless, 3 Coulomb
std::string header(const std::string& name, double dt, const MjContactParams& p) {
  std::ostringstream s;
  s.precision(17);
  s << "<mujoco model=\"" << name << "\">\n"
    << "  <option timestep=\"" << dt << "\" gravity=\"0 0 " << -kG << "\" cone=\""
    << (p.elliptic_cone ? "elliptic" : "pyramidal") << "\"/>\n";
  if (!p.solref.empty() || !p.solimp.empty()) {
    s << "  <default><geom";
    if (!p.solref.empty()) s << " solref=\"" << p.solref << "\"";
    if (!p.solimp.empty()) s << " solimp=\"" << p.solimp << "\"";
    s << "/></default>\n";
  }
  return s.str();
}

// MuJoCo combines the two geoms' friction by the maximum, condim by the maximum: both sides get
// the same values. The torsional and rolling coefficients are MuJoCo's defaults (unused at condim 3).
std::string contactAttrs(double mu) {
  std::ostringstream s;
  s.precision(17);
  if (mu > 0.0) s << "condim=\"3\" friction=\"" << mu << " 0.005 0.0001\"";
  else s << "condim=\"1\"";
  return s.str();
}

std::string ground(double mu) {
  return "    <geom name=\"ground\" type=\"plane\" size=\"10 10 0.1\" " + contactAttrs(mu) + "/>\n";
}

void throwOnWarnings(const mjData* d) {
  if (d->warning[mjWARN_BADQACC].number > 0)
    throw std::runtime_error("MuJoCo: bad qacc (the simulation diverged) at t = " + std::to_string(d->time));
}

}  // namespace

MjContactParams bouncyContact(double e, double stiffness) {
  const double l = std::log(e), z = -l / std::sqrt(M_PI * M_PI + l * l);
  std::array<char, 64> buf{};
  std::snprintf(buf.data(), buf.size(), "-%.0f -%.1f", stiffness, 2 * z * std::sqrt(stiffness));
  MjContactParams p;
  p.solref = buf.data();
  return p;
}

struct MujocoModel::Impl {
  mjModel* m = nullptr;
  mjData* d = nullptr;
};

MujocoModel::MujocoModel(const std::string& mjcf) : impl_(std::make_unique<Impl>()) {
  // mj_loadXML reads a file: a private temporary directory, removed whatever happens
  std::string tmpl = (std::filesystem::temp_directory_path() / "redmax_mujoco_XXXXXX").string();
  if (!mkdtemp(tmpl.data())) throw std::runtime_error("MujocoModel: cannot create a temporary directory");
  const std::filesystem::path dir(tmpl), file = dir / "scene.xml";
  std::array<char, 1000> err{};
  {
    std::ofstream out(file);
    out << mjcf;
  }
  impl_->m = mj_loadXML(file.c_str(), nullptr, err.data(), static_cast<int>(err.size()));
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  if (!impl_->m) throw std::runtime_error(std::string("MuJoCo could not load the scene: ") + err.data());
  impl_->d = mj_makeData(impl_->m);
  reset();
}

MujocoModel::~MujocoModel() {
  if (impl_->d) mj_deleteData(impl_->d);
  if (impl_->m) mj_deleteModel(impl_->m);
}

void MujocoModel::reset() {
  if (impl_->m->nkey > 0) mj_resetDataKeyframe(impl_->m, impl_->d, 0);
  else mj_resetData(impl_->m, impl_->d);
}
void MujocoModel::step() {
  mj_step(impl_->m, impl_->d);
  throwOnWarnings(impl_->d);
}
double MujocoModel::time() const { return impl_->d->time; }
double MujocoModel::qpos(int i) const { return impl_->d->qpos[i]; }
double MujocoModel::qvel(int i) const { return impl_->d->qvel[i]; }
int MujocoModel::contacts() const { return impl_->d->ncon; }
double MujocoModel::penetration() const {
  double p = 0.0;
  for (int i = 0; i < impl_->d->ncon; ++i) p = std::max(p, -impl_->d->contact[i].dist);
  return p;
}
double MujocoModel::timestep() const { return impl_->m->opt.timestep; }

std::string mujocoVersion() { return mj_versionString(); }

// ---- MJCF (z up; a free joint's qpos is x y z qw qx qy qz, its qvel vx vy vz in world, then w)

std::string ballDropMjcf(const scenes::BallDropOptions& o, const MjContactParams& p) {
  std::ostringstream s;
  s.precision(17);
  s << header("ball_drop", o.dt, p) << "  <worldbody>\n"
    << ground(o.friction) << "    <body name=\"ball\" pos=\"0 0 " << o.drop_height + o.radius << "\">\n"
    << "      <freejoint/>\n"
    << "      <geom type=\"sphere\" size=\"" << o.radius << "\" mass=\"" << o.mass << "\" " << contactAttrs(o.friction)
    << "/>\n"
    << "    </body>\n  </worldbody>\n</mujoco>\n";
  return s.str();
}

std::string blockSlideMjcf(const scenes::BlockSlideOptions& o, const MjContactParams& p) {
  // redmax's half extents are (x, y up, z): MuJoCo's box is (x, z, y up)
  const Vec3& h = o.half_extents;
  std::ostringstream s;
  s.precision(17);
  s << header("block_slide", o.dt, p) << "  <worldbody>\n"
    << ground(o.friction) << "    <body name=\"block\" pos=\"0 0 " << h.y() << "\">\n"
    << "      <freejoint/>\n"
    << "      <geom type=\"box\" size=\"" << h.x() << " " << h.z() << " " << h.y() << "\" mass=\"" << o.mass << "\" "
    << contactAttrs(o.friction) << "/>\n"
    << "    </body>\n  </worldbody>\n"
    << "  <keyframe><key qpos=\"0 0 " << h.y() << " 1 0 0 0\" qvel=\"" << o.v0 << " 0 0 0 0 0\"/></keyframe>\n"
    << "</mujoco>\n";
  return s.str();
}

std::string boxStackMjcf(const scenes::BoxStackOptions& o, const MjContactParams& p) {
  std::ostringstream s;
  s.precision(17);
  s << header("box_stack", o.dt, p) << "  <worldbody>\n" << ground(o.friction);
  for (int i = 0; i < o.boxes; ++i)
    s << "    <body name=\"box" << i << "\" pos=\"0 0 " << o.half + i * (2 * o.half + o.initial_gap) << "\">\n"
      << "      <freejoint/>\n"
      << "      <geom type=\"box\" size=\"" << o.half << " " << o.half << " " << o.half << "\" mass=\"" << o.mass
      << "\" " << contactAttrs(o.friction) << "/>\n"
      << "    </body>\n";
  s << "  </worldbody>\n</mujoco>\n";
  return s.str();
}

// ---- runs (the same measures as contact_scenes.cpp's, on MuJoCo's state)

double firstImpactTime(const std::vector<double>& t, const std::vector<double>& v, double g) {
  for (size_t k = 1; k < v.size() && k < t.size(); ++k) {
    const double h = t[k] - t[k - 1];
    if (std::abs(v[k] - (v[k - 1] - g * h)) > 1e-9) return t[k];
  }
  return -1.0;
}

MjBallDropResult runBallDrop(MujocoModel& m, const scenes::BallDropOptions& o) {
  MjBallDropResult r;
  m.reset();
  const long n = std::lround(o.duration / o.dt);
  std::vector<double> vz{m.qvel(2)};
  r.height.t.push_back(m.time());
  r.height.y.push_back(m.qpos(2) - o.radius);
  double prev_v = m.qvel(2);
  bool bounced = false;
  for (long k = 0; k < n; ++k) {
    m.step();
    const double z = m.qpos(2), v = m.qvel(2);
    r.height.t.push_back(m.time());
    r.height.y.push_back(z - o.radius);
    vz.push_back(v);
    r.max_penetration = std::max(r.max_penetration, o.radius - z);
    if (prev_v < 0.0 && v > 0.0) bounced = true;
    // an apex is a top of flight: the soft contact's oscillation while in contact is none
    if (bounced && prev_v > 0.0 && v <= 0.0 && z > o.radius) r.apexes.push_back(z - o.radius);
    prev_v = v;
  }
  r.first_impact = firstImpactTime(r.height.t, vz, kG);
  r.rest_height = m.qpos(2);
  r.steps = n;
  return r;
}

MjBlockSlideResult runBlockSlide(MujocoModel& m, const scenes::BlockSlideOptions& o) {
  MjBlockSlideResult r;
  m.reset();
  const long n = std::lround(o.duration / o.dt);
  r.x.t.push_back(m.time());
  r.x.y.push_back(m.qpos(0));
  for (long k = 0; k < n; ++k) {
    m.step();
    r.x.t.push_back(m.time());
    r.x.y.push_back(m.qpos(0));
    const double speed = std::hypot(m.qvel(0), m.qvel(1), m.qvel(2));
    if (r.stop_time < 0.0 && speed < 1e-3) r.stop_time = m.time();
    r.max_penetration = std::max(r.max_penetration, m.penetration());
  }
  r.distance = m.qpos(0);
  r.final_speed = std::hypot(m.qvel(0), m.qvel(1), m.qvel(2));
  r.steps = n;
  return r;
}

MjBoxStackResult runBoxStack(MujocoModel& m, const scenes::BoxStackOptions& o) {
  MjBoxStackResult r;
  m.reset();
  const long n = std::lround(o.duration / o.dt), k1 = std::max(0L, n - std::lround(1.0 / o.dt));
  std::vector<double> earlier;
  double t1 = 0.0;
  auto centres = [&] {
    std::vector<double> c;
    for (int i = 0; i < o.boxes; ++i)
      for (int j = 0; j < 3; ++j) c.push_back(m.qpos(7 * i + j));
    return c;
  };
  if (k1 == 0) earlier = centres();
  for (long k = 0; k < n; ++k) {
    m.step();
    if (k + 1 == k1) earlier = centres(), t1 = m.time();
  }
  const std::vector<double> last = centres();
  const double span = m.time() - t1;
  for (int i = 0; i < o.boxes; ++i) {
    const double d = std::hypot(last[3 * i] - earlier[3 * i], last[3 * i + 1] - earlier[3 * i + 1],
                                last[3 * i + 2] - earlier[3 * i + 2]);
    r.drift_per_second = std::max(r.drift_per_second, d / span);
  }
  r.max_penetration = m.penetration();
  for (int i = 0; i < 6 * o.boxes; ++i) r.final_max_speed = std::max(r.final_max_speed, std::abs(m.qvel(i)));
  r.steps = n;
  return r;
}

}  // namespace redmax::peers
