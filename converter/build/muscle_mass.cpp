#include "converter/build/muscle_mass.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "core/dynamics/skeleton_dynamics.hpp"
#include "core/muscles/muscle_kinematics.hpp"
#include "core/muscles/wrap_muscle.hpp"
#include "core/skeleton/kinematics.hpp"

namespace redmax::osim {

namespace {

std::string quoted(const std::string& s) { return "'" + s + "'"; }

std::string fmt(double v, const char* f = "%.6g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// the parsed `muscles` selector
struct Selector {
  enum class Kind { All, Top, Regex } kind = Kind::All;
  int top_k = 0;
  std::optional<std::regex> re;
};

Selector parseSelector(const std::string& text) {
  Selector s;
  if (text == "all") return s;
  if (text.rfind("top:", 0) == 0) {
    const std::string k = text.substr(4);
    size_t used = 0;
    long v = 0;
    try {
      v = std::stol(k, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (k.empty() || used != k.size() || v < 1 || v > 1000000)
      throw std::invalid_argument("--muscles top:K needs a whole number K >= 1, got '" + text + "'");
    s.kind = Selector::Kind::Top;
    s.top_k = static_cast<int>(v);
    return s;
  }
  if (text.empty()) throw std::invalid_argument("--muscles needs all, top:K or a regular expression");
  try {
    s.re.emplace(text, std::regex::ECMAScript);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument("--muscles '" + text + "' is not a valid regular expression (" +
                                e.what() + ")");
  }
  s.kind = Selector::Kind::Regex;
  return s;
}

void checkOptions(const ModelDescription& d, const MuscleMassOptions& o) {
  if (o.mass_points < 1)
    throw std::invalid_argument("--mass-points must be >= 1, got " + std::to_string(o.mass_points));
  if (!(o.specific_tension > 0.0) || !std::isfinite(o.specific_tension))
    throw std::invalid_argument("--specific-tension must be a finite value > 0 (Pa), got " +
                                fmt(o.specific_tension));
  if (!(o.density > 0.0) || !std::isfinite(o.density))
    throw std::invalid_argument("--muscle-density must be a finite value > 0 (kg/m^3), got " +
                                fmt(o.density));
  if (o.placement == MuscleMassOptions::Placement::Fibre && o.region == MassPointOptions::Region::WholePath)
    throw std::invalid_argument("--mass-placement fibre spreads the points over the fibre; it excludes --mass-region whole");
  if (o.source == MuscleMassOptions::Source::Transfer) {
    if (!(o.transfer_fraction >= 0.0) || !(o.transfer_fraction < 1.0))
      throw std::invalid_argument("--transfer-fraction must be in [0, 1), got " +
                                  fmt(o.transfer_fraction));
    if (o.transfer_body.empty())
      throw std::invalid_argument("--muscle-mass transfer needs --transfer-body BODY");
    if (d.findBody(o.transfer_body) < 0)
      throw ConvertError(d.source_file, 0,
                         "--transfer-body " + quoted(o.transfer_body) + " is not a body of the model" +
                             (o.transfer_body == d.ground_name ? " (ground has no mass)" : ""));
  }
}

// inertia about the origin of a point mass at x: m (|x|^2 1 - x x^T)
Mat3 pointInertia(double m, const Vec3& x) {
  return m * (x.squaredNorm() * Mat3::Identity() - x * x.transpose());
}

// how far a symmetric inertia is from physical: max(-lambda_min, lambda_i - lambda_j - lambda_k)
double inertiaViolation(const Mat3& I) {
  const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (I + I.transpose()), Eigen::EigenvaluesOnly);
  const Vec3 l = es.eigenvalues();
  double v = -l.minCoeff();
  for (int i = 0; i < 3; ++i) v = std::max(v, l[i] - l[(i + 1) % 3] - l[(i + 2) % 3]);
  return v;
}

void setInertia(BodyDesc& b, const Mat3& I) {
  const Mat3 S = 0.5 * (I + I.transpose());
  b.inertia << S(0, 0), S(1, 1), S(2, 2), S(0, 1), S(0, 2), S(1, 2);
}

// what one mass point takes from one body
struct Removal {
  double mass = 0.0;
  Vec3 first = Vec3::Zero();   // sum m_a r_a, r_a about the body's old COM (body frame)
  Mat3 second = Mat3::Zero();  // sum of point inertias about the old COM
  std::vector<std::string> muscles;
};

// the body a mass point was lumped into: the body (with mass) of the muscle's span whose bone is
// nearest, the bone of body b being the segments from its origin to its centre of mass and to the
// origins of its children's joint frames, at the default pose. Segment masses (de Leva, Dempster)
// count all tissue inside the segment, so a point beside the femur belongs to the femur even when
// the muscle has no path point on it. The span is every body on the tree path between the
// bodies of the muscle's path points (ground excluded).
struct PointOwner {
  int body = -1;  // description body
  Vec3 x_b = Vec3::Zero();
};

struct Bones {
  std::vector<std::vector<std::pair<Vec3, Vec3>>> segments;  // per core body, world     (nb)
};

Bones calcBones(const Model& model, const SkeletonWorkspace& sk) {
  Bones b;
  b.segments.resize(model.nb());
  for (int i = 0; i < model.nb(); ++i) {
    const Vec3 o = sk.E_wi[i].topRightCorner<3, 1>();
    b.segments[i].push_back({o, transformPoint(sk.E_wi[i], model.bodies()[i].com)});
  }
  for (int j = 0; j < model.nb(); ++j) {
    const int p = model.joints()[j].parent;
    if (p < 0) continue;
    const Vec3 o = sk.E_wi[p].topRightCorner<3, 1>();
    // the child's origin at the default pose (joint translations such as gait2392's knee live in
    // the joint's functions, not in its frames)
    b.segments[p].push_back({o, sk.E_wi[j].topRightCorner<3, 1>()});
  }
  return b;
}

double segmentDistance(const Vec3& x, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double L2 = ab.squaredNorm();
  const double t = L2 > 0.0 ? std::clamp((x - a).dot(ab) / L2, 0.0, 1.0) : 0.0;
  return (x - (a + t * ab)).norm();
}

// bodies on the tree paths between the bodies of the path's points (core indices, ground left out)
std::vector<int> muscleSpan(const Model& model, const MusclePath& path) {
  std::vector<int> ends;
  for (const PathPoint& p : path.points)
    if (p.body >= 0 && std::find(ends.begin(), ends.end(), p.body) == ends.end()) ends.push_back(p.body);
  if (ends.empty()) return {};
  auto chain = [&](int b) {  // b, its parent, ..., root, then -1 (ground)
    std::vector<int> c;
    for (int i = b; i >= 0; i = model.joints()[i].parent) c.push_back(i);
    c.push_back(-1);
    return c;
  };
  // lowest common ancestor: the deepest entry of the first chain that every other chain contains
  const std::vector<int> first = chain(ends[0]);
  size_t lca_at = 0;
  for (size_t k = 1; k < ends.size(); ++k) {
    const std::vector<int> c = chain(ends[k]);
    while (std::find(c.begin(), c.end(), first[lca_at]) == c.end()) ++lca_at;
  }
  const int lca = first[lca_at];
  std::vector<int> span;
  for (int e : ends)
    for (int i = e; i >= 0; i = model.joints()[i].parent) {
      if (std::find(span.begin(), span.end(), i) == span.end()) span.push_back(i);
      if (i == lca) break;
    }
  return span;
}

// the default-pose positions of one muscle's mass points and the bodies they are taken from;
// false (why set) when the path cannot carry points there or no body of its span has mass
bool locatePoints(const Model& model, const State& s, const SkeletonWorkspace& sk, const Bones& bones,
                  const Muscle& muscle, const std::vector<int>& desc_of_core,
                  const ModelDescription& d, std::vector<PointOwner>& owners, std::string& why) {
  MuscleKinematics mk;
  try {
    calcMuscleKinematics(model, s, sk, muscle, mk, false);
  } catch (const MuscleError& e) {
    why = std::string("path degenerate at the default pose (") + e.what() + ")";
    return false;
  }
  std::vector<int> span;
  for (int cb : muscleSpan(model, muscle.path)) {
    const int db = desc_of_core[cb];
    if (db >= 0 && d.bodies[db].mass > 0.0) span.push_back(cb);
  }
  if (span.empty()) {
    why = "no body with mass along its path (its mass would come from nowhere)";
    return false;
  }
  owners.assign(mk.x_a.size(), {});
  for (size_t a = 0; a < mk.x_a.size(); ++a) {
    int best = -1;
    double best_dist = std::numeric_limits<double>::infinity();
    for (int cb : span)
      for (const auto& [p0, p1] : bones.segments[cb]) {
        const double dist = segmentDistance(mk.x_a[a], p0, p1);
        if (dist < best_dist) {
          best_dist = dist;
          best = cb;
        }
      }
    owners[a].body = desc_of_core[best];
    owners[a].x_b = transformPoint(inverseE(sk.E_wi[best]), mk.x_a[a]);
  }
  return true;
}

// largest ||M_muscle(q)||_F / ||M_skeleton(q)||_F over the samples, muscle carrying its points
double inertiaShare(const Model& model, const std::vector<VecX>& samples, const Muscle& muscle) {
  double best = 0.0;
  SkeletonWorkspace sk(model);
  MuscleKinematics mk;
  MatX M_s(model.nr(), model.nr());
  State s;
  s.qdot = VecX::Zero(model.nr());
  for (const VecX& q : samples) {
    s.q = q;
    calcKinematics(model, s, sk);
    try {
      calcMuscleKinematics(model, s, sk, muscle, mk, false);
    } catch (const MuscleError&) {
      continue;
    }
    const int N = muscle.mass_points.size();
    const int k = static_cast<int>(mk.cols.size());
    MatX Mm = MatX::Zero(k, k);
    for (int a = 0; a < N; ++a)
      Mm.noalias() += muscle.mass_points.mass[a] * mk.J_ar.middleRows(3 * a, 3).transpose() *
                      mk.J_ar.middleRows(3 * a, 3);
    calcSkeletonMass(model, sk, M_s);
    const double ns = M_s.norm();
    if (ns > 0.0) best = std::max(best, Mm.norm() / ns);
  }
  return best;
}

}  // namespace

MuscleMassOptions::Source parseMuscleMassSource(const std::string& text) {
  if (text == "none") return MuscleMassOptions::Source::None;
  if (text == "physiological") return MuscleMassOptions::Source::Physiological;
  if (text == "transfer") return MuscleMassOptions::Source::Transfer;
  throw std::invalid_argument("--muscle-mass must be none, physiological or transfer, got '" + text + "'");
}

const char* toString(MuscleMassOptions::Source source) {
  switch (source) {
    case MuscleMassOptions::Source::None: return "none";
    case MuscleMassOptions::Source::Physiological: return "physiological";
    case MuscleMassOptions::Source::Transfer: return "transfer";
  }
  return "?";
}

double physiologicalMass(const PathForceDesc& muscle, const MuscleMassOptions& options) {
  // PCSA = F_max / sigma, volume = PCSA * l_opt, mass = rho * volume
  return options.density * (muscle.max_isometric_force / options.specific_tension) *
         muscle.optimal_fiber_length;
}

MuscleMassModel applyMuscleMass(const ModelDescription& d, const BuildOptions& build_options,
                                const MuscleMassOptions& options, const std::vector<VecX>& samples) {
  checkOptions(d, options);
  parseSelector(options.muscles);  // bad options fail before the model is built
  BuildOptions bo = build_options;
  bo.muscles = true;  // the muscles carry the mass, whatever the caller builds them for
  return addMuscleMass(d, buildCoreModel(d, bo), options, samples);
}

MuscleMassModel addMuscleMass(const ModelDescription& d, BuildResult base,
                              const MuscleMassOptions& options, const std::vector<VecX>& samples) {
  using Source = MuscleMassOptions::Source;
  checkOptions(d, options);
  const Selector selector = parseSelector(options.muscles);
  if (!base.options.muscles)
    throw std::invalid_argument("muscle mass: the model was built without its muscles (BuildOptions::muscles)");

  MuscleMassModel out;
  out.plan.options = options;
  out.description = d;
  const Model& model = base.model.skeleton();
  // the muscles as they will be: wrap model set, mass points added below
  std::vector<Muscle> muscles = base.model.muscles();
  const int nm = static_cast<int>(muscles.size());
  out.plan.muscles.resize(nm);
  for (int k = 0; k < nm; ++k) {
    out.plan.muscles[k].name = muscles[k].name;
    out.plan.muscles[k].wraps = pathType(muscles[k].path) == redmax::PathType::III;
    // the wrap model decides which surfaces a Type III muscle may carry mass over
    if (out.plan.muscles[k].wraps) muscles[k].wrap = options.wrap;
  }
  // the one edit of the built model: bodies' mass properties and the muscles
  MusculoskeletalModelBuilder edit(base.model);
  auto finish = [&]() {
    for (int k = 0; k < nm; ++k) edit.muscle(k) = muscles[k];
    out.build = std::move(base);
    out.build.model = edit.finalize();
  };

  if (options.source == Source::None) {
    for (auto& e : out.plan.muscles) e.lumped_why = "--muscle-mass none";
    finish();
    return out;
  }

  for (const VecX& q : samples)
    if (q.size() != model.nr())
      throw std::invalid_argument("muscle mass: a sample has " + std::to_string(q.size()) +
                                  " coordinates; the model has " + std::to_string(model.nr()));

  // core body -> description body (masters only; path points name masters)
  std::vector<int> desc_of_core(model.nb(), -1);
  for (size_t bi = 0; bi < base.body_index.size(); ++bi)
    if (base.body_index[bi] >= 0) desc_of_core[base.body_index[bi]] = static_cast<int>(bi);

  const int transfer_body = options.source == Source::Transfer ? d.findBody(options.transfer_body) : -1;
  const int transfer_core = transfer_body >= 0 ? base.body_index[transfer_body] : -1;

  // candidates: muscles whose mass the options could move
  std::vector<double> phys(nm, 0.0);
  std::vector<bool> candidate(nm, false);
  for (int k = 0; k < nm; ++k) {
    const PathForceDesc& pf = d.muscles[base.muscle_source[k]];
    MuscleMassEntry& e = out.plan.muscles[k];
    phys[k] = physiologicalMass(pf, options);
    // why the wrap model refuses this wrapping muscle's path ("" = it takes it)
    const std::string wrap_why = pf.is_muscle && e.wraps && options.wrap_mass
                                     ? redmax::wrapMassPointsUnsupportedReason(muscles[k])
                                     : std::string();
    if (!pf.is_muscle) {
      e.lumped_why = "not a muscle (" + pf.class_name + ")";
    } else if (e.wraps && !options.wrap_mass) {
      e.lumped_why = "Type III path (wrap mass off: --wrap lumped)";
    } else if (!wrap_why.empty()) {
      e.lumped_why = "Type III path (" + wrap_why + ")";
    } else if (!(phys[k] > 0.0) || !std::isfinite(phys[k])) {
      e.lumped_why = "zero physiological mass (max_isometric_force " + fmt(pf.max_isometric_force) +
                     " N, optimal_fiber_length " + fmt(pf.optimal_fiber_length) + " m)";
    } else if (selector.kind == Selector::Kind::Regex && !std::regex_match(pf.name, *selector.re)) {
      e.lumped_why = "not selected (--muscles " + options.muscles + ")";
    } else if (transfer_core >= 0 &&
               std::none_of(muscles[k].path.points.begin(), muscles[k].path.points.end(),
                            [&](const PathPoint& p) { return p.body == transfer_core; })) {
      e.lumped_why = "does not span " + options.transfer_body;
    } else {
      candidate[k] = true;
    }
  }

  const MassPointOptions mpo{options.mass_points, options.region};
  // the points' placement: fibre-following where asked and possible (alpha at the default pose)
  auto place = [&](int k, Muscle& mu) {
    const auto& mm = base.model.muscleModels();
    return placeMassPoints(model, options, k < static_cast<int>(mm.size()) ? mm[k] : nullptr, mu);
  };
  auto withPoints = [&](int k, double m) {
    Muscle mu = muscles[k];
    const PathForceDesc& pf = d.muscles[base.muscle_source[k]];
    mu.mass_points = makeMassPoints(m, pf.optimal_fiber_length, pf.tendon_slack_length, mpo);
    place(k, mu);
    return mu;
  };

  // top:K: rank the candidates by the share of the mass matrix they would add (physiological mass)
  if (selector.kind == Selector::Kind::Top) {
    // at most 100 evenly spaced samples: the ranking needs the spread of poses, not every frame
    std::vector<VecX> poses;
    if (samples.empty()) {
      poses.push_back(model.defaultQ());
    } else {
      const size_t n = std::min<size_t>(samples.size(), 100);
      for (size_t j = 0; j < n; ++j)
        poses.push_back(samples[n == 1 ? 0 : j * (samples.size() - 1) / (n - 1)]);
    }
    std::vector<std::pair<double, int>> rank;
    for (int k = 0; k < nm; ++k) {
      if (!candidate[k]) continue;
      double share = 0.0;
      try {
        share = inertiaShare(model, poses, withPoints(k, phys[k]));
      } catch (const ModelError&) {
        share = 0.0;
      }
      rank.push_back({share, k});
    }
    std::stable_sort(rank.begin(), rank.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    for (size_t r = 0; r < rank.size(); ++r) {
      const int k = rank[r].second;
      out.plan.ranking.push_back({muscles[k].name, rank[r].first});
      if (static_cast<int>(r) >= selector.top_k) {
        candidate[k] = false;
        out.plan.muscles[k].lumped_why =
            "not in the top " + std::to_string(selector.top_k) + " (rank " + std::to_string(r + 1) + ")";
      }
    }
  }

  // masses
  std::vector<double> mass(nm, 0.0);
  std::map<int, Removal> removals;  // description body -> what is taken from it
  if (options.source == Source::Physiological) {
    State s;
    s.q = model.defaultQ();
    s.qdot = VecX::Zero(model.nr());
    SkeletonWorkspace sk(model);
    calcKinematics(model, s, sk);
    const Bones bones = calcBones(model, sk);
    std::vector<PointOwner> owners;
    for (int k = 0; k < nm; ++k) {
      if (!candidate[k]) continue;
      const Muscle mu = withPoints(k, phys[k]);
      std::string why;
      if (!locatePoints(model, s, sk, bones, mu, desc_of_core, d, owners, why)) {
        out.plan.muscles[k].lumped_why = why;
        continue;
      }
      mass[k] = phys[k];
      for (int a = 0; a < mu.mass_points.size(); ++a) {
        const BodyDesc& b = d.bodies[owners[a].body];
        Removal& r = removals[owners[a].body];
        const double m_a = mu.mass_points.mass[a];
        const Vec3 rel = owners[a].x_b - b.mass_center;
        r.mass += m_a;
        r.first += m_a * rel;
        r.second += pointInertia(m_a, rel);
        if (r.muscles.empty() || r.muscles.back() != mu.name) r.muscles.push_back(mu.name);
      }
    }
  } else {  // Transfer
    double sum = 0.0;
    for (int k = 0; k < nm; ++k)
      if (candidate[k]) sum += phys[k];
    const BodyDesc& b = d.bodies[transfer_body];
    if (sum <= 0.0)
      throw ConvertError(d.source_file, b.line,
                         "--transfer-body " + quoted(b.name) + ": no selected muscle without wrapping "
                         "has a path point on it, so no muscle can take its mass");
    const double moved = options.transfer_fraction * b.mass;
    for (int k = 0; k < nm; ++k)
      if (candidate[k]) mass[k] = moved * phys[k] / sum;
  }

  // the bodies after the mass has left them
  if (options.source == Source::Physiological) {
    for (const auto& [bi, r] : removals) {
      const BodyDesc& b = d.bodies[bi];
      BodyDesc& nb = out.description.bodies[bi];
      const double m1 = b.mass - r.mass;
      // new COM c' = c + dc with m' dc = -sum m_a r_a; inertia about c' by parallel axes
      const Vec3 dc = m1 > 0.0 ? Vec3(-r.first / m1) : Vec3::Zero();
      const Mat3 I1 = b.inertiaMatrix() - r.second - pointInertia(m1, dc);
      const double scale = std::max(b.inertiaMatrix().trace(), 1e-300);
      const double tol = 1e-9 * scale;
      std::string muscles;
      for (size_t j = 0; j < r.muscles.size() && j < 6; ++j) muscles += (j ? ", " : "") + r.muscles[j];
      if (r.muscles.size() > 6) muscles += ", ... (" + std::to_string(r.muscles.size()) + " muscles)";
      const std::string head = "body " + quoted(b.name) + " would become non-physical after giving " +
                               fmt(r.mass) + " kg to the mass points of " + muscles + ": ";
      const std::string hint = " (give less mass: --muscles, --muscle-density or --specific-tension)";
      if (!(m1 > 1e-12 * b.mass))
        throw ConvertError(d.source_file, b.line,
                           head + "its mass " + fmt(b.mass) + " kg would become " + fmt(m1) + " kg" + hint);
      const double v0 = inertiaViolation(b.inertiaMatrix()), v1 = inertiaViolation(I1);
      if (v1 > std::max(v0, 0.0) + tol) {
        const Eigen::SelfAdjointEigenSolver<Mat3> es(I1, Eigen::EigenvaluesOnly);
        const Vec3 l = es.eigenvalues();
        throw ConvertError(d.source_file, b.line,
                           head + "its principal moments about the new centre of mass would be " +
                               fmt(l[0]) + ", " + fmt(l[1]) + ", " + fmt(l[2]) + " kg m^2 (" +
                               (l[0] < -tol ? "not positive semi-definite" : "triangle inequality broken") +
                               ")" + hint);
      }
      nb.mass = m1;
      nb.mass_center = b.mass_center + dc;
      setInertia(nb, I1);
    }
  } else if (transfer_body >= 0) {
    const double keep = 1.0 - options.transfer_fraction;
    BodyDesc& nb = out.description.bodies[transfer_body];
    nb.mass *= keep;
    nb.inertia *= keep;
    removals[transfer_body].mass = d.bodies[transfer_body].mass * options.transfer_fraction;
  }
  for (const auto& [bi, r] : removals) {
    const BodyDesc& b = d.bodies[bi];
    const BodyDesc& nb = out.description.bodies[bi];
    BodyMassChange c;
    c.name = b.name;
    c.mass_before = b.mass;
    c.mass_after = nb.mass;
    c.com_before = b.mass_center;
    c.com_after = nb.mass_center;
    c.inertia_before = b.inertiaMatrix();
    c.inertia_after = nb.inertiaMatrix();
    out.plan.bodies.push_back(c);
  }

  // the bodies that gave mass: the core bodies carrying them (a split body's slaves too) take the
  // new properties exactly as buildCoreModel derives them from the description
  for (const auto& [bi, r] : removals) {
    const BodyDesc& nb = out.description.bodies[bi];
    for (int c = 0; c < model.nb(); ++c) {
      if (base.body_source[c] != bi) continue;
      const CoreMassProperties mp = coreMassProperties(nb, base.body_mass_share[c]);
      if (mp.zeroed)
        base.warnings.push_back("body " + quoted(nb.name) +
                                " is massless; its nonzero inertia is set to zero, as Simbody does");
      edit.skeleton().setBodyMassProperties(c, mp.mass, mp.com, mp.inertia_com);
    }
  }

  // the muscles with their points; Type III muscles (wrap_mass) get theirs here:
  // addMusclePointMasses keeps refusing them
  std::vector<double> plain = mass;
  for (int k = 0; k < nm; ++k)
    if (pathType(muscles[k].path) == redmax::PathType::III) plain[k] = 0.0;
  muscles = addMusclePointMasses(muscles, plain, mpo);
  for (int k = 0; k < nm; ++k) {
    Muscle& mu = muscles[k];
    if (!(mass[k] > 0.0)) continue;
    if (plain[k] != mass[k])
      mu.mass_points = makeMassPoints(mass[k], mu.optimal_fiber_length, mu.tendon_slack_length, mpo);
    out.plan.muscles[k].uniform_why = place(k, mu);
  }
  // finalize validates every muscle against the edited skeleton (ModelError)
  finish();
  for (int k = 0; k < nm; ++k) {
    MuscleMassEntry& e = out.plan.muscles[k];
    e.mass = mass[k];
    e.points = out.build.model.muscles()[k].mass_points.size();
    if (mass[k] > 0.0) {
      e.lumped_why.clear();
    } else if (e.lumped_why.empty()) {
      e.lumped_why = "zero mass";  // a transfer of fraction 0
    }
    out.plan.total_muscle_mass += mass[k];
  }
  return out;
}

WrapMassCount countWrapMass(const MuscleMassPlan& plan) {
  WrapMassCount c;
  for (const auto& e : plan.muscles) {
    if (!e.wraps) continue;
    ++c.wrapping;
    if (e.mass > 0.0) ++c.with_mass;
    else c.lumped.push_back({e.name, e.lumped_why});
  }
  return c;
}

MuscleMassOptions::Placement parseMassPlacement(const std::string& text) {
  if (text == "uniform") return MuscleMassOptions::Placement::Uniform;
  if (text == "fibre") return MuscleMassOptions::Placement::Fibre;
  throw std::invalid_argument("--mass-placement must be uniform or fibre, got '" + text + "'");
}

const char* toString(MuscleMassOptions::Placement placement) {
  return placement == MuscleMassOptions::Placement::Fibre ? "fibre" : "uniform";
}

std::string placeMassPoints(const Model& model, const MuscleMassOptions& options,
                            const std::shared_ptr<const hill::MuscleModel>& mm, Muscle& mu) {
  mu.fibre = FibreFollowing{};
  if (options.placement != MuscleMassOptions::Placement::Fibre || mu.mass_points.size() == 0) return "";
  const std::string why = fibrePlacementUnsupportedReason(mu, mm.get());
  if (!why.empty()) return why;
  const VecX q = model.defaultQ();
  std::vector<Mat4> E_wi(model.nb());
  calcBodyPoses(model, q, E_wi);
  setFibrePlacement(model, q, E_wi, mm, mu);
  return "";
}

const char* toString(WrapModel model) {
  switch (model) {
    case WrapModel::Smooth: return "smooth";
    case WrapModel::Exact: return "exact";
    case WrapModel::Neural: return "neural";
  }
  return "?";
}

std::string describeMuscleMass(const MuscleMassPlan& plan) {
  std::ostringstream os;
  const MuscleMassOptions& o = plan.options;
  os << "muscle mass: " << toString(o.source);
  if (o.source == MuscleMassOptions::Source::None) {
    os << " (muscles lumped into the bones, as OpenSim sees them)\n";
    return os.str();
  }
  os << ", muscles " << o.muscles << ", " << o.mass_points << " points each in the "
     << (o.region == MassPointOptions::Region::Fibre ? "fibre" : "whole path")
     << (o.placement == MuscleMassOptions::Placement::Fibre ? " (fibre-following placement)" : "") << ", density "
     << fmt(o.density) << " kg/m^3, specific tension " << fmt(o.specific_tension) << " Pa";
  if (o.source == MuscleMassOptions::Source::Transfer)
    os << ", " << fmt(100.0 * o.transfer_fraction) << "% of " << o.transfer_body;
  os << "\n";
  int with = 0;
  for (const auto& e : plan.muscles) with += e.mass > 0.0;
  os << "  " << with << " of " << plan.muscles.size() << " path forces carry "
     << fmt(plan.total_muscle_mass) << " kg\n";
  const WrapMassCount wc = countWrapMass(plan);
  if (wc.wrapping > 0) {
    os << "  wrapping (Type III): " << wc.with_mass << " of " << wc.wrapping << " carry mass";
    if (o.wrap_mass) {
      os << " (wrap model " << toString(o.wrap.model);
      if (o.wrap.model != WrapModel::Exact)
        os << ", width " << (o.wrap.width > 0.0 ? fmt(o.wrap.width) + " m" : std::string("0.05 radius"));
      os << ")";
    } else {
      os << " (wrap mass off)";
    }
    os << "\n";
  }
  if (!plan.bodies.empty()) {
    os << "  bodies (mass before -> after, kg; centre of mass after, m):\n";
    for (const auto& b : plan.bodies)
      os << "    " << b.name << ": " << fmt(b.mass_before, "%.9g") << " -> " << fmt(b.mass_after, "%.9g")
         << "  (" << fmt(b.mass_after - b.mass_before, "%+.6g") << "), com [" << fmt(b.com_after[0]) << ", "
         << fmt(b.com_after[1]) << ", " << fmt(b.com_after[2]) << "]\n";
  }
  if (with > 0) {
    os << "  muscles with mass (kg, points):\n";
    for (const auto& e : plan.muscles)
      if (e.mass > 0.0)
        os << "    " << e.name << ": " << fmt(e.mass) << " kg, " << e.points << " points"
           << (e.uniform_why.empty() ? std::string() : ", uniform placement (" + e.uniform_why + ")") << "\n";
  }
  if (with < static_cast<int>(plan.muscles.size())) {
    os << "  lumped (no mass):\n";
    for (const auto& e : plan.muscles)
      if (!(e.mass > 0.0)) os << "    " << e.name << ": " << e.lumped_why << "\n";
  }
  if (!plan.ranking.empty()) {
    os << "  ranking (largest ||M_muscle||_F / ||M_skeleton||_F over the samples):\n";
    for (size_t r = 0; r < plan.ranking.size(); ++r)
      os << "    " << (r + 1) << ". " << plan.ranking[r].first << " " << fmt(plan.ranking[r].second) << "\n";
  }
  return os.str();
}

}  // namespace redmax::osim
