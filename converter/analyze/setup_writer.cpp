#include "converter/analyze/setup_writer.hpp"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "converter/atomic_file.hpp"
#include "converter/osim_reader.hpp"

namespace redmax::osim {
namespace fs = std::filesystem;

namespace {

std::string xmlEscape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '&') o += "&amp;";
    else if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else o += c;
  }
  return o;
}

std::string number(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}

std::string absolute(const std::string& p) { return p.empty() ? p : fs::absolute(p).lexically_normal().string(); }

}  // namespace

StaticOptimizationSetupFiles writeStaticOptimizationSetup(const IdToolConfig& t,
                                                          const StaticOptimizationSetupOptions& opt,
                                                          const std::string& dir) {
  const ModelDescription d = readOsimModel(t.model_file);
  StaticOptimizationSetupFiles res;

  std::ostringstream rs;
  rs << "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
     << "<ForceSet name=\"gait_study_reserves\"><objects>\n";
  for (const CoordinateDesc& c : d.coordinates) {
    if (c.locked || c.prescribed) continue;
    bool root = false;
    for (const JointDesc& j : d.joints)
      if (j.name == c.joint) root = j.parent_body == d.ground_name || j.parent_body.empty();
    const std::string name = c.name + (root ? "_residual" : "_reserve");
    res.reserves.push_back(name);
    rs << "<CoordinateActuator name=\"" << xmlEscape(name) << "\"><coordinate>" << xmlEscape(c.name)
       << "</coordinate><optimal_force>" << number(root ? opt.residual_optimal_force : opt.reserve_optimal_force)
       << "</optimal_force></CoordinateActuator>\n";
  }
  rs << "</objects></ForceSet>\n</OpenSimDocument>\n";
  fs::create_directories(dir);
  const std::string name = d.name.empty() ? "gait_study" : d.name;
  res.reserves_file = (fs::path(dir) / (name + "_reserves.xml")).string();
  writeFileAtomic(res.reserves_file, rs.str());

  std::ostringstream ss;
  ss << "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n"
     << "<AnalyzeTool name=\"" << xmlEscape(name) << "\">\n"
     << "<model_file>" << xmlEscape(absolute(t.model_file)) << "</model_file>\n"
     << "<replace_force_set>false</replace_force_set>\n"
     << "<force_set_files>" << xmlEscape(fs::path(res.reserves_file).filename().string()) << "</force_set_files>\n"
     << "<results_directory>.</results_directory>\n"
     << "<initial_time>" << number(std::isfinite(t.t0) ? t.t0 : -1e300) << "</initial_time>\n"
     << "<final_time>" << number(std::isfinite(t.t1) ? t.t1 : 1e300) << "</final_time>\n"
     << "<AnalysisSet name=\"Analyses\"><objects>\n"
     << "<StaticOptimization name=\"StaticOptimization\"><on>true</on><step_interval>" << opt.step_interval
     << "</step_interval><use_model_force_set>true</use_model_force_set><activation_exponent>2</activation_exponent>"
        "<use_muscle_physiology>true</use_muscle_physiology><optimizer_convergence_criterion>0.0001"
        "</optimizer_convergence_criterion><optimizer_max_iterations>100</optimizer_max_iterations>"
        "</StaticOptimization>\n"
     << "</objects></AnalysisSet>\n"
     << "<external_loads_file>" << xmlEscape(absolute(t.external_loads_file)) << "</external_loads_file>\n"
     << "<coordinates_file>" << xmlEscape(absolute(t.coordinates_file)) << "</coordinates_file>\n"
     << "<lowpass_cutoff_frequency_for_coordinates>" << number(t.lowpass_cutoff_hz)
     << "</lowpass_cutoff_frequency_for_coordinates>\n"
     << "</AnalyzeTool>\n</OpenSimDocument>\n";
  res.setup_file = (fs::path(dir) / (name + "_Setup_Analyze.xml")).string();
  writeFileAtomic(res.setup_file, ss.str());
  return res;
}

}  // namespace redmax::osim
