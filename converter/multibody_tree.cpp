// The multibody tree OpenSim builds from its joints (docs/opensim_compatibility.md §3.1): a restatement of
// Simbody's MultibodyGraphMaker (breadth-first by level in JointSet order, reversed joints,
// massless bodies extended to a massful one, loops cut by welds or slave bodies) and of
// Model::createMultibodyTree / extendConnectToModel, which fix the q order.
#include <algorithm>
#include <map>

#include "converter/osim_reader.hpp"

namespace redmax::osim {
namespace {

struct GraphBody {
  std::string name;
  double mass = 0.0;
  std::vector<int> as_parent, as_child;  // joint numbers
  int level = -1;                        // -1: not yet in the tree
  bool inTree() const { return level >= 0; }
};

struct GraphJoint {
  int desc = -1;  // into d.joints
  int parent = -1, child = -1;
  int mobilities = 0;
  bool weld = false, free = false;
  int mobilizer = -1;
  bool loop = false;
};

struct Mobilizer {
  int joint;
  int inboard, outboard;  // graph body numbers (outboard may be a slave)
  bool reversed;
  int level;
  bool slave = false;
};

class Graph {
 public:
  explicit Graph(ModelDescription& d) : d_(d) {}

  void build() {
    addBodies();
    addJoints();
    checkMasslessAndConnect();
    // grow from ground; when bodies remain, connect the best new base body and grow again
    while (true) {
      growTree();
      const int base = chooseNewBaseBody();
      if (base < 0) break;
      connectToGround(base);
    }
    breakLoops();
    emit();
  }

 private:
  void addBodies() {
    bodies_.push_back({d_.ground_name, 0.0, {}, {}, 0});
    index_[d_.ground_name] = 0;
    for (const auto& b : d_.bodies) {
      index_[b.name] = static_cast<int>(bodies_.size());
      bodies_.push_back({b.name, b.mass, {}, {}, -1});
    }
  }

  int bodyIndex(const std::string& name, const JointDesc& j) const {
    auto it = index_.find(name);
    if (it == index_.end())
      throw ConvertError(d_.source_file, j.line,
                         "joint '" + j.name + "' connects unknown body '" + name + "'");
    return it->second;
  }

  void addJoint(int desc, int parent, int child) {
    GraphJoint g;
    g.desc = desc;
    g.parent = parent;
    g.child = child;
    const JointDesc& j = d_.joints[desc];
    g.mobilities = static_cast<int>(j.coordinates.size());
    g.weld = j.kind == JointKind::Weld;
    g.free = j.kind == JointKind::Free;
    const int n = static_cast<int>(joints_.size());
    joints_.push_back(g);
    bodies_[parent].as_parent.push_back(n);
    bodies_[child].as_child.push_back(n);
  }

  void addJoints() {
    for (size_t i = 0; i < d_.joints.size(); ++i) {
      const JointDesc& j = d_.joints[i];
      addJoint(static_cast<int>(i), bodyIndex(j.parent_body, j), bodyIndex(j.child_body, j));
    }
  }

  // a FreeJoint "free_<body>" from ground, as OpenSim adds for unconnected bodies
  void connectToGround(int body) {
    JointDesc j;
    j.name = "free_" + bodies_[body].name;
    j.type = "FreeJoint";
    j.kind = JointKind::Free;
    j.parent_frame = "/" + d_.ground_name;
    j.child_frame = "/bodyset/" + bodies_[body].name;
    j.parent_body = d_.ground_name;
    j.child_body = bodies_[body].name;
    j.added = true;
    const int ji = static_cast<int>(d_.joints.size());
    static const MotionType mt[6] = {MotionType::Rotational,    MotionType::Rotational,
                                     MotionType::Rotational,    MotionType::Translational,
                                     MotionType::Translational, MotionType::Translational};
    for (int k = 0; k < 6; ++k) {
      CoordinateDesc c;
      c.name = j.name + "_coord_" + std::to_string(k);
      c.joint = j.name;
      c.joint_index = ji;
      c.mobility = k;
      c.motion_type = mt[k];
      c.declared_index = static_cast<int>(d_.coordinates.size());
      j.coordinates.push_back(static_cast<int>(d_.coordinates.size()));
      d_.coordinates.push_back(c);
    }
    d_.joints.push_back(j);
    d_.warnings.push_back("body '" + bodies_[body].name +
                          "' is connected by no joint: a FreeJoint '" + j.name +
                          "' to ground is added, as OpenSim does");
    addJoint(ji, 0, body);
  }

  void checkMasslessAndConnect() {
    for (size_t b = 1; b < bodies_.size(); ++b) {
      const GraphBody& body = bodies_[b];
      const size_t nj = body.as_parent.size() + body.as_child.size();
      if (body.mass == 0.0 && nj == 1) {
        const int j = body.as_child.empty() ? body.as_parent[0] : body.as_child[0];
        if (joints_[j].mobilities > 0)
          d_.warnings.push_back("body '" + body.name +
                                "' is massless at the end of a mobile joint: Simbody would reject "
                                "this tree (singular mass matrix)");
      }
      if (nj == 0) {
        if (body.mass == 0.0)
          d_.warnings.push_back("body '" + body.name +
                                "' is massless and free: Simbody would reject this tree");
        connectToGround(static_cast<int>(b));
      }
    }
  }

  int addMobilizer(int jn) {
    GraphJoint& j = joints_[jn];
    GraphBody& parent = bodies_[j.parent];
    GraphBody& child = bodies_[j.child];
    Mobilizer m;
    m.joint = jn;
    if (parent.inTree()) {
      child.level = parent.level + 1;
      m = {jn, j.parent, j.child, false, child.level};
    } else {
      // the child is inboard: the joint is reversed, its coordinates keep their meaning
      parent.level = child.level + 1;
      m = {jn, j.child, j.parent, true, parent.level};
    }
    j.mobilizer = static_cast<int>(mobilizers_.size());
    mobilizers_.push_back(m);
    return j.mobilizer;
  }

  int heaviestForward(int b) const {
    int best = -1;
    double max_mass = 0.0;
    for (int jn : bodies_[b].as_parent) {
      const GraphJoint& j = joints_[jn];
      if (j.mobilizer >= 0 || bodies_[j.child].inTree()) continue;
      if (bodies_[j.child].mass > max_mass) best = jn, max_mass = bodies_[j.child].mass;
    }
    return best;
  }

  int heaviestReverse(int b) const {
    int best = -1;
    double max_mass = 0.0;
    for (int jn : bodies_[b].as_child) {
      const GraphJoint& j = joints_[jn];
      if (j.mobilizer >= 0 || bodies_[j.parent].inTree()) continue;
      if (bodies_[j.parent].mass > max_mass) best = jn, max_mass = bodies_[j.parent].mass;
    }
    return best;
  }

  void growTree() {
    std::vector<bool> added(joints_.size(), false);
    for (int level = 1;; ++level) {
      bool any = false;
      for (size_t jn = 0; jn < joints_.size(); ++jn) {
        GraphJoint& j = joints_[jn];
        if (j.mobilizer >= 0) {
          // joints added during this sweep (massless extensions) count at their level
          if (jn < added.size() && added[jn] && mobilizers_[j.mobilizer].level == level) any = true;
          continue;
        }
        const GraphBody& p = bodies_[j.parent];
        const GraphBody& c = bodies_[j.child];
        if (p.inTree() == c.inTree()) continue;  // exactly one end must be in the tree
        if ((p.inTree() ? p.level : c.level) != level - 1) continue;
        addMobilizer(static_cast<int>(jn));
        added.resize(joints_.size(), false);
        added[jn] = true;
        any = true;
        // a mobile massless outboard body: extend its branch to a massful body at once
        const int out = mobilizers_.back().outboard;
        if (j.mobilities == 0 || bodies_[out].mass > 0) continue;
        while (true) {
          const int b = mobilizers_.back().outboard;
          // only massful candidates qualify (MultibodyGraphMaker::findHeaviestUnassigned*);
          // where Simbody would throw, we stop extending and warn
          const int jf = heaviestForward(b);
          if (jf >= 0) {
            addMobilizer(jf);
            added[jf] = true;
            break;
          }
          const int jr = heaviestReverse(b);
          if (jr >= 0) {
            addMobilizer(jr);
            added[jr] = true;
            break;
          }
          d_.warnings.push_back("the branch through massless body '" + bodies_[b].name +
                                "' ends without a massful body: Simbody would reject this tree");
          break;
        }
      }
      if (!any) break;
    }
  }

  int chooseNewBaseBody() const {
    bool parent_only_seen = false;
    int best = -1, n_children = -1;
    for (size_t b = 1; b < bodies_.size(); ++b) {
      const GraphBody& body = bodies_[b];
      if (body.inTree()) continue;
      if (parent_only_seen && !body.as_child.empty()) continue;
      if (!parent_only_seen && body.as_child.empty()) {
        parent_only_seen = true;
        best = static_cast<int>(b);
        n_children = static_cast<int>(body.as_parent.size());
      } else if (static_cast<int>(body.as_parent.size()) > n_children) {
        best = static_cast<int>(b);
        n_children = static_cast<int>(body.as_parent.size());
      }
    }
    return best;
  }

  void breakLoops() {
    for (size_t jn = 0; jn < joints_.size(); ++jn) {
      GraphJoint& j = joints_[jn];
      if (j.mobilizer >= 0) continue;
      if (j.weld || j.free) {
        // Weld and Free have loop constraints (a weld; nothing for a free joint)
        j.loop = true;
        loops_.push_back(static_cast<int>(jn));
        continue;
      }
      // otherwise the child is split: a slave body carries the joint, welded to its master
      const int master = j.child;
      const int n = static_cast<int>(slaves_of_[master]++);
      GraphBody slave;
      slave.name = bodies_[master].name + "_slave_" + std::to_string(n);
      slave.level = bodies_[j.parent].level + 1;
      const int s = static_cast<int>(bodies_.size());
      bodies_.push_back(slave);
      master_of_[s] = master;
      Mobilizer m{static_cast<int>(jn), j.parent, s, false, slave.level, true};
      j.mobilizer = static_cast<int>(mobilizers_.size());
      mobilizers_.push_back(m);
    }
  }

  void emit() {
    TreeDesc tree;
    std::vector<int> new_order;
    std::vector<bool> placed(d_.coordinates.size(), false);
    for (const Mobilizer& m : mobilizers_) {
      const GraphJoint& j = joints_[m.joint];
      MobilizerDesc md;
      md.joint = j.desc;
      md.inboard_body = bodies_[m.inboard].name;
      md.outboard_body = bodies_[m.outboard].name;
      md.reversed = m.reversed;
      md.level = m.level;
      tree.mobilizers.push_back(md);
      for (int ci : d_.joints[j.desc].coordinates) {
        new_order.push_back(ci);
        placed[ci] = true;
      }
      if (m.slave) {
        const std::string& master = bodies_[master_of_.at(m.outboard)].name;
        tree.slaves.push_back({md.outboard_body, master});
        ConstraintDesc c;
        c.name = md.outboard_body + "_weld";
        c.type = "WeldConstraint";
        c.kind = ConstraintKind::Weld;
        c.generated_by = "loop closure: joint '" + d_.joints[j.desc].name + "' moves slave body '" +
                         md.outboard_body + "', welded to its master '" + master + "'";
        c.body1 = master;
        c.body2 = md.outboard_body;
        d_.constraints.push_back(c);
      }
    }
    for (int jn : loops_) {
      const GraphJoint& j = joints_[jn];
      const JointDesc& jd = d_.joints[j.desc];
      if (j.weld) {
        ConstraintDesc c;
        c.name = jd.name + "_Loop";
        c.type = "WeldConstraint";
        c.kind = ConstraintKind::Weld;
        c.generated_by = "loop closure: WeldJoint '" + jd.name + "' closes a loop";
        c.frame1 = jd.parent_frame;
        c.frame2 = jd.child_frame;
        c.body1 = jd.parent_body;
        c.body2 = jd.child_body;
        c.X_B1F1 = jd.X_PF;
        c.X_B2F2 = jd.X_BM;
        d_.constraints.push_back(c);
      } else {
        d_.warnings.push_back("FreeJoint '" + jd.name + "' closes a loop and is ignored, as in OpenSim");
      }
    }
    // coordinates of joints without a mobilizer (a FreeJoint closing a loop) go last
    for (size_t ci = 0; ci < d_.coordinates.size(); ++ci)
      if (!placed[ci]) new_order.push_back(static_cast<int>(ci));
    // permute the coordinates into q order and remap the joints' indices
    std::vector<CoordinateDesc> coords;
    std::vector<int> new_index(d_.coordinates.size());
    for (size_t k = 0; k < new_order.size(); ++k) {
      new_index[new_order[k]] = static_cast<int>(k);
      coords.push_back(d_.coordinates[new_order[k]]);
    }
    for (auto& j : d_.joints)
      for (auto& ci : j.coordinates) ci = new_index[ci];
    d_.coordinates = std::move(coords);
    // the slave bodies share their master's mass equally (Body::addSlave / mass split)
    d_.tree = std::move(tree);
  }

  ModelDescription& d_;
  std::vector<GraphBody> bodies_;
  std::vector<GraphJoint> joints_;
  std::vector<Mobilizer> mobilizers_;
  std::vector<int> loops_;
  std::map<std::string, int> index_;
  std::map<int, int> slaves_of_, master_of_;
};

}  // namespace

void buildMultibodyTree(ModelDescription& d) {
  Graph g(d);
  g.build();
}

}  // namespace redmax::osim
