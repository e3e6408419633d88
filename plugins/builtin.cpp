#include "vdyn/plugins/builtin.h"

#include "vdyn/tire/tire_force.h"

namespace vdyn {
PluginRegistry& builtinPlugins() {
  static PluginRegistry registry = [] {
    PluginRegistry r;
    registerTirePlugins(r);
    return r;
  }();
  return registry;
}
}  // namespace vdyn
