#include "vdyn/vehicles/standard_registry.h"

#include "vdyn/analyses/analyses.h"
#include "vdyn/plugins/builtin.h"
#include "vdyn/vehicles/scene_vehicles.h"

namespace vdyn {

PluginRegistry makeStandardRegistry() {
  PluginRegistry r;
  registerBuiltinPlugins(r);
  registerVehicles(r);
  registerAnalyses(r);
  return r;
}

PluginRegistry& standardRegistry() {
  static PluginRegistry r = makeStandardRegistry();
  return r;
}

}  // namespace vdyn
