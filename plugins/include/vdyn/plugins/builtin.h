#pragma once
#include "vdyn/core/registry.h"

namespace vdyn {
/// The registry holding every built-in plugin (tires: gim, fiala, linear; ...).
/// Users register their own plugins in it, or in a registry of their own.
PluginRegistry& builtinPlugins();
/// Registers every built-in plugin (force elements, constraints, controllers) in `registry`.
void registerBuiltinPlugins(PluginRegistry& registry);
}  // namespace vdyn
