#include "vdyn/plugins/builtin.h"

#include "vdyn/path_control/path_control.h"
#include "vdyn/rear_steer/rear_steer.h"
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
    registerPathControlPlugins(r);
    registerRearSteerPlugins(r);
    return r;
  }();
  return registry;
}
}  // namespace vdyn
