#include "vdyn/plugins/builtin.h"

#include "vdyn/steering/steering.h"
#include "vdyn/tire/tire_force.h"

namespace vdyn {
PluginRegistry& builtinPlugins() {
  static PluginRegistry registry = [] {
    PluginRegistry r;
    registerTirePlugins(r);
    registerSteeringPlugins(r);
    return r;
  }();
  return registry;
}
}  // namespace vdyn
