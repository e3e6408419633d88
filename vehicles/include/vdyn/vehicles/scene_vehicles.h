#pragma once
// The built-in vehicle builders a scene file names by "vehicle": {"type": ...}:
// quarter_car, bicycle and fourws, each with its attachments (the bindings a
// plugin entry gets from "attach"). standardRegistry() is the registry with
// every built-in kind: plugins (builtinPlugins), these vehicles and the
// analyses (plugins/analyses).
#include "vdyn/core/registry.h"

namespace vdyn {

/// Registers "quarter_car", "bicycle" and "fourws".
void registerVehicles(PluginRegistry& registry);

}  // namespace vdyn
