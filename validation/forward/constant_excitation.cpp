#include "validation/forward/constant_excitation.hpp"

#include <filesystem>
#include <sstream>

#include "converter/atomic_file.hpp"
#include "converter/osim_reader.hpp"

namespace redmax::validation {

std::string writeConstantExcitationSetup(const std::string& model, const std::string& dir, const std::string& name,
                                         double t1, double excitation, double tolerance) {
  namespace fs = std::filesystem;
  const osim::ModelDescription d = osim::readOsimModel(model);
  fs::create_directories(dir);
  std::ostringstream c;
  c.precision(17);
  c << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenSimDocument Version=\"40000\">\n<ControlSet name=\"constant\">\n"
    << "<objects>\n";
  for (const auto& m : d.muscles) {
    if (!m.is_muscle) continue;
    c << "<ControlLinear name=\"" << m.name << ".excitation\"><is_model_control>true</is_model_control>"
      << "<use_steps>false</use_steps><x_nodes>";
    for (double t : {0.0, t1})
      c << "<ControlLinearNode><t>" << t << "</t><value>" << excitation << "</value></ControlLinearNode>";
    c << "</x_nodes></ControlLinear>\n";
  }
  c << "</objects>\n</ControlSet>\n</OpenSimDocument>\n";
  osim::writeFileAtomic((fs::path(dir) / "controls.xml").string(), c.str());
  std::ostringstream f;
  f.precision(17);
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<OpenSimDocument Version=\"40000\">\n"
    << "<ForwardTool name=\"" << name << "\">\n<model_file>" << fs::absolute(model).string() << "</model_file>\n"
    << "<results_directory>.</results_directory>\n"
    << "<initial_time>0</initial_time>\n<final_time>" << t1 << "</final_time>\n"
    << "<solve_for_equilibrium_for_auxiliary_states>true</solve_for_equilibrium_for_auxiliary_states>\n"
    << "<maximum_number_of_integrator_steps>2000000</maximum_number_of_integrator_steps>\n"
    << "<integrator_error_tolerance>" << tolerance << "</integrator_error_tolerance>\n"
    << "<ControllerSet><objects><ControlSetController name=\"constant\">"
    << "<controls_file>controls.xml</controls_file></ControlSetController></objects></ControllerSet>\n"
    << "</ForwardTool>\n</OpenSimDocument>\n";
  const std::string path = (fs::path(dir) / (name + "_Setup_Forward.xml")).string();
  osim::writeFileAtomic(path, f.str());
  return path;
}

}  // namespace redmax::validation
