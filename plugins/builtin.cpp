#include "vdyn/plugins/builtin.h"

#include "vdyn/speed/speed_hold.h"
#include "vdyn/steering/steering.h"
#include "vdyn/tire/tire_force.h"

namespace vdyn {
PluginRegistry& builtinPlugins() {
  static PluginRegistry registry = [] {
    PluginRegistry r;
    registerTirePlugins(r);
    registerSteeringPlugins(r);
    registerSpeedPlugins(r);
    return r;
  }();
  return registry;
}
}  // namespace vdyn
