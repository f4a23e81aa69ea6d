// Registration of the plugin's OpenSim object types when the shared library is loaded, as
// OpenSim's plugin examples do (OpenSim/Examples/Plugins): a static object whose constructor
// registers a prototype of each type, so that `opensim-cmd -L libredmax_opensim.so run-tool`
// can make a RedmaxInverseDynamicsTool from a setup file's element name.
#include "plugin/opensim/redmax_inverse_dynamics_tool.hpp"

namespace redmax::opensim {

void registerTypes() { OpenSim::Object::registerType(RedmaxInverseDynamicsTool()); }

namespace {

struct TypeRegistration {
  TypeRegistration() { registerTypes(); }
};
const TypeRegistration kRegistration;

}  // namespace

}  // namespace redmax::opensim

extern "C" void RegisterTypes_redmax_opensim() { redmax::opensim::registerTypes(); }
