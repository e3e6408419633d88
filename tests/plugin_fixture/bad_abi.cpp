// A plugin library built for another plugin ABI version.
#include "vdyn/core/plugin_library.h"
VDYN_PLUGIN_EXPORT int vdyn_plugin_abi_version() { return VDYN_PLUGIN_ABI_VERSION + 100; }
VDYN_PLUGIN_EXPORT void vdyn_register_plugins(vdyn::PluginRegistry&) {}
