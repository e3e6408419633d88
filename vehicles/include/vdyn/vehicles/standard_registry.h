#pragma once
// The registry with every built-in kind: the plugins of builtinPlugins() (tires,
// steering, speed hold, path control, rear steer, ...), the vehicles
// (registerVehicles) and the analyses (registerAnalyses). Programs that load
// scene files use it (and may add to it: loadPluginLibrary).
#include "vdyn/core/registry.h"

namespace vdyn {

/// A new registry filled with every built-in kind.
PluginRegistry makeStandardRegistry();
/// One process-wide standard registry (made on first use; thread-safe).
PluginRegistry& standardRegistry();

}  // namespace vdyn
