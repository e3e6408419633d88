// The library's entry points (docs/plugin_guide.md, "Write a plugin"): vdyn loads the
// library (a scene's "plugin_libraries" or `vdyn run --plugin PATH`), checks
// vdyn_plugin_abi_version() against its own VDYN_PLUGIN_ABI_VERSION and calls
// vdyn_register_plugins with its registry.
#include <memory>

#include "quadratic_drag.h"
#include "vdyn/core/plugin_library.h"

VDYN_PLUGIN_EXPORT int vdyn_plugin_abi_version() { return VDYN_PLUGIN_ABI_VERSION; }

VDYN_PLUGIN_EXPORT void vdyn_register_plugins(vdyn::PluginRegistry& registry) {
  registry.add(
      vdyn::PluginKind::ForceElement, "quadratic_drag",
      [](const vdyn::PluginSpec& spec) -> std::unique_ptr<vdyn::Plugin> {
        vdyn_example::QuadraticDragParams p = vdyn_example::QuadraticDragParams::fromParams(spec.params);
        if (spec.bindings.count("chassis")) p.body = spec.bindings.at("chassis");  // "attach": "chassis"
        return std::make_unique<vdyn_example::QuadraticDragPlugin>(spec.name, p);
      },
      vdyn::typeInfo("aerodynamic drag F = -rho Cd A |v - w| (v - w) / 2 on a body point (examples/aero_drag)",
                     vdyn_example::quadraticDragFields()));
}
