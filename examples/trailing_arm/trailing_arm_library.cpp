// The library's entry points (docs/plugin_guide.md, "Write a plugin"): a suspension template
// registered in the registry's suspension_template family.
#include "trailing_arm.h"
#include "vdyn/core/plugin_library.h"

VDYN_PLUGIN_EXPORT int vdyn_plugin_abi_version() { return VDYN_PLUGIN_ABI_VERSION; }

VDYN_PLUGIN_EXPORT void vdyn_register_plugins(vdyn::PluginRegistry& registry) {
  vdyn_example::registerTrailingArm(registry);
}
