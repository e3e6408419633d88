#include "vdyn/plugins/builtin.h"

#include "vdyn/forces/body_force.h"
#include "vdyn/magic_formula/magic_formula_tire.h"
#include "vdyn/path_control/path_control.h"
#include "vdyn/rear_steer/rear_steer.h"
#include "vdyn/speed/speed_hold.h"
#include "vdyn/steering/steering.h"
#include "vdyn/tire/tire_force.h"

namespace vdyn {
void registerBuiltinPlugins(PluginRegistry& r) {
  registerTirePlugins(r);
  registerMagicFormulaTire(r);
  registerBodyForcePlugins(r);
  registerSteeringPlugins(r);
  registerSpeedPlugins(r);
  registerPathControlPlugins(r);
  registerRearSteerPlugins(r);
}

PluginRegistry& builtinPlugins() {
  static PluginRegistry registry = [] {
    PluginRegistry r;
    registerBuiltinPlugins(r);
    return r;
  }();
  return registry;
}
}  // namespace vdyn
