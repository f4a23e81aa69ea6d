// Dependencies point down only (docs/design.md §3): this test fails on any upward or forbidden #include.
//   core/spatial <- core/joints <- core/skeleton <- core/muscles <- core/dynamics <- core/integrators
//   core/spatial <- core/geometry <- core/muscles   (surface geometry: wrap surfaces, dual numbers)
//   core/muscles/hill (Hill-type muscle models: the standard library only) <- core/muscles
//   core/dynamics <- core/model (the musculoskeletal aggregate, beside core/integrators)
//   core/integrators <- core/adjoint (the discrete adjoint of the fixed-step integrators)
//   core/dynamics <- core/deformable (deformable bodies as force terms, beside core/integrators)
//   converter/, plugin/ -> core/ (plugin may also read the converter's description)
//   tools/ -> core/ (offline work the engine never runs: wrap-network training, wrap benchmarks)
//   view/ -> core, converter (`redmax view`, docs/view.md)
//   validation/ -> core, converter, plugin, view;  cli/ -> anything
// External libraries: tinyxml2 only in converter/; Simbody only in plugin/, validation/ and
// tests; SUNDIALS only in core/integrators/*.cpp (never a header); LBFGSpp and NLopt only in
// validation/optimize/*.cpp; MuJoCo (the contact comparison) only in validation/peers/*.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct Include {
  std::string file;
  int line;
  std::string target;
};

std::vector<Include> scan(const fs::path& root, const std::string& dir) {
  std::vector<Include> out;
  const fs::path base = root / dir;
  if (!fs::exists(base)) return out;
  const std::regex re(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
  for (const auto& e : fs::recursive_directory_iterator(base)) {
    if (!e.is_regular_file()) continue;
    const auto ext = e.path().extension();
    if (ext != ".hpp" && ext != ".cpp" && ext != ".h") continue;
    std::ifstream in(e.path());
    std::string s;
    int n = 0;
    while (std::getline(in, s)) {
      ++n;
      std::smatch m;
      if (std::regex_search(s, m, re)) out.push_back({fs::relative(e.path(), root).string(), n, m[1]});
    }
  }
  return out;
}

// the project folder an include names ("core/joints/joint.hpp" -> "core/joints"), or "" if external
std::string layerOf(const std::string& inc) {
  static const std::vector<std::string> layers = {
      "core/spatial", "core/geometry", "core/joints", "core/skeleton", "core/muscles/hill", "core/muscles",
      "core/dynamics",
      "core/integrators", "core/adjoint", "core/model", "core/deformable", "converter", "plugin", "tools", "view", "validation", "cli"};
  for (const auto& l : layers)
    if (inc.rfind(l + "/", 0) == 0) return l;
  return "";
}

bool isSimbody(const std::string& inc) {
  return inc.rfind("Simbody", 0) == 0 || inc.rfind("SimTK", 0) == 0 || inc.rfind("simbody/", 0) == 0 ||
         inc.rfind("simmath/", 0) == 0 || inc.rfind("OpenSim", 0) == 0;
}
bool isSundials(const std::string& inc) {
  return inc.rfind("sundials/", 0) == 0 || inc.rfind("arkode/", 0) == 0 || inc.rfind("cvode/", 0) == 0 ||
         inc.rfind("nvector/", 0) == 0 || inc.rfind("sunmatrix/", 0) == 0 || inc.rfind("sunlinsol/", 0) == 0;
}

// which project folders each folder may include (cli/ and tests/ are not checked: anything)
std::map<std::string, std::set<std::string>> layerRules() {
  std::map<std::string, std::set<std::string>> rules = {
      {"core/spatial", {"core/spatial"}},
      {"core/muscles/hill", {"core/muscles/hill"}},
      {"core/geometry", {"core/spatial", "core/geometry"}},
      {"core/joints", {"core/spatial", "core/joints"}},
      {"core/skeleton", {"core/spatial", "core/joints", "core/skeleton"}},
      {"core/muscles", {"core/spatial", "core/geometry", "core/joints", "core/skeleton", "core/muscles/hill", "core/muscles"}},
      {"core/dynamics",
       {"core/spatial", "core/geometry", "core/joints", "core/skeleton", "core/muscles/hill", "core/muscles", "core/dynamics"}},
      {"core/integrators",
       {"core/spatial", "core/geometry", "core/joints", "core/skeleton", "core/muscles/hill", "core/muscles", "core/dynamics",
        "core/integrators"}},
      {"core/model",
       {"core/spatial", "core/geometry", "core/joints", "core/skeleton", "core/muscles/hill", "core/muscles", "core/dynamics",
        "core/model"}},
      {"core/adjoint",
       {"core/spatial", "core/geometry", "core/joints", "core/skeleton", "core/muscles/hill", "core/muscles", "core/dynamics",
        "core/integrators", "core/adjoint"}},
      {"core/deformable",
       {"core/spatial", "core/geometry", "core/joints", "core/skeleton", "core/muscles/hill", "core/muscles", "core/dynamics",
        "core/deformable"}},
  };
  std::set<std::string> core_all = rules.at("core/integrators");
  core_all.insert({"core/model", "core/adjoint", "core/deformable"});
  std::set<std::string> converter = core_all, plugin = core_all, tools = core_all, validation = core_all,
                        view = core_all;
  converter.insert("converter");
  view.insert({"converter", "view"});
  plugin.insert({"converter", "plugin"});
  tools.insert("tools");
  validation.insert({"converter", "plugin", "view", "validation"});
  rules["converter"] = converter;
  rules["plugin"] = plugin;
  rules["tools"] = tools;
  rules["view"] = view;
  rules["validation"] = validation;
  return rules;
}

// whether a file in folder `dir` may include `target` (external headers: always, checked apart)
bool mayInclude(const std::string& dir, const std::string& target) {
  static const auto rules = layerRules();
  const std::string l = layerOf(target);
  return l.empty() || rules.at(dir).count(l) > 0;
}

TEST(Layering, IncludesPointDownOnly) {
  const fs::path root = REDMAX_SOURCE_DIR;
  const auto rules = layerRules();

  int checked = 0;
  for (const auto& rule : rules) {
    const std::string& dir = rule.first;
    for (const auto& inc : scan(root, dir)) {
      if (layerOf(inc.file) != dir) continue;  // a sub-layer's file (core/muscles/hill) has its own rule
      ++checked;
      const std::string where = inc.file + ":" + std::to_string(inc.line) + " includes " + inc.target;
      EXPECT_TRUE(mayInclude(dir, inc.target)) << where << " (upward or sideways dependency)";
      if (inc.target.rfind("tinyxml2", 0) == 0) {
        EXPECT_EQ(dir, "converter") << where << " (tinyxml2 belongs to converter/ only)";
      }
      if (isSimbody(inc.target)) {
        EXPECT_TRUE(dir == "plugin" || dir == "validation") << where << " (Simbody outside plugin/validation)";
      }
      if (inc.target == "LBFGS.h" || inc.target.rfind("LBFGSpp/", 0) == 0 || inc.target.rfind("nlopt", 0) == 0) {
        // the reaching task's optimizers (docs/design.md §10), in its .cpp only
        EXPECT_TRUE(inc.file.rfind("validation/optimize/", 0) == 0 && inc.file.size() > 4 &&
                    inc.file.substr(inc.file.size() - 4) == ".cpp")
            << where << " (LBFGSpp and NLopt only in validation/optimize/*.cpp)";
      }
      if (inc.target.rfind("mujoco/", 0) == 0) {
        // a peer for comparison (docs/contact.md §6.4a), optional: never in a header or the core
        EXPECT_TRUE(inc.file.rfind("validation/peers/", 0) == 0 && inc.file.size() > 4 &&
                    inc.file.substr(inc.file.size() - 4) == ".cpp")
            << where << " (MuJoCo only in validation/peers/*.cpp)";
      }
      if (isSundials(inc.target)) {
        EXPECT_TRUE(dir == "core/integrators" && inc.file.size() > 4 &&
                    inc.file.substr(inc.file.size() - 4) == ".cpp")
            << where << " (SUNDIALS only in core/integrators/*.cpp)";
      }
    }
  }
  EXPECT_GT(checked, 20) << "the scan found almost no includes: wrong source root?";
}

TEST(Layering, DetectsAViolation) {
  // the classifier itself must flag an upward include, or the test above could never fail
  EXPECT_EQ(layerOf("core/dynamics/system.hpp"), "core/dynamics");
  EXPECT_EQ(layerOf("core/model/musculoskeletal_model.hpp"), "core/model");
  EXPECT_FALSE(mayInclude("core/integrators", "core/model/musculoskeletal_model.hpp"));
  EXPECT_FALSE(mayInclude("core/dynamics", "core/model/musculoskeletal_model.hpp"));
  EXPECT_TRUE(mayInclude("core/model", "core/dynamics/system.hpp"));
  EXPECT_TRUE(mayInclude("core/deformable", "core/dynamics/force_term.hpp"));
  EXPECT_FALSE(mayInclude("core/deformable", "core/integrators/integrator.hpp"));
  EXPECT_FALSE(mayInclude("core/dynamics", "core/deformable/deformable_term.hpp"));
  EXPECT_TRUE(mayInclude("converter", "core/model/musculoskeletal_model.hpp"));
  EXPECT_EQ(layerOf("Eigen/Core"), "");
  EXPECT_EQ(layerOf("tools/wrap_training/train.hpp"), "tools");
  EXPECT_EQ(layerOf("core/geometry/wrap_surface.hpp"), "core/geometry");
  // and the rules must refuse upward includes
  EXPECT_FALSE(mayInclude("core/muscles", "core/dynamics/system.hpp"));
  EXPECT_FALSE(mayInclude("core/geometry", "core/muscles/path.hpp"));  // geometry sits below muscles
  EXPECT_FALSE(mayInclude("core/geometry", "core/joints/joint.hpp"));  // and depends on spatial only
  EXPECT_FALSE(mayInclude("core/spatial", "core/geometry/dual.hpp"));
  EXPECT_TRUE(mayInclude("core/geometry", "core/spatial/types.hpp"));
  EXPECT_TRUE(mayInclude("core/muscles", "core/geometry/wrap_surface.hpp"));
  EXPECT_FALSE(mayInclude("core/muscles", "tools/wrap_training/train.hpp"));
  EXPECT_FALSE(mayInclude("validation", "tools/wrap_training/train.hpp"));
  EXPECT_FALSE(mayInclude("tools", "validation/report/csv.hpp"));
  EXPECT_TRUE(mayInclude("tools", "core/muscles/wrap/network.hpp"));
  EXPECT_FALSE(mayInclude("view", "validation/report/csv.hpp"));  // the view sits below validation
  EXPECT_TRUE(mayInclude("validation", "view/view.hpp"));
  EXPECT_TRUE(mayInclude("core/spatial", "Eigen/Core"));
  // the Hill models sit below everything: not even spatial algebra
  EXPECT_EQ(layerOf("core/muscles/hill/muscle_model.hpp"), "core/muscles/hill");
  EXPECT_FALSE(mayInclude("core/muscles/hill", "core/muscles/path.hpp"));
  EXPECT_FALSE(mayInclude("core/muscles/hill", "core/spatial/types.hpp"));
  EXPECT_TRUE(mayInclude("core/muscles", "core/muscles/hill/muscle_model.hpp"));
  EXPECT_TRUE(mayInclude("converter", "core/muscles/hill/factory.hpp"));
  EXPECT_TRUE(isSimbody("Simbody.h"));
  EXPECT_TRUE(isSundials("arkode/arkode_erkstep.h"));
}

}  // namespace
