// The library's entry points (docs/plugin_guide.md, "Write a plugin").
#include <memory>

#include "pure_pursuit.h"
#include "vdyn/core/plugin_library.h"

VDYN_PLUGIN_EXPORT int vdyn_plugin_abi_version() { return VDYN_PLUGIN_ABI_VERSION; }

VDYN_PLUGIN_EXPORT void vdyn_register_plugins(vdyn::PluginRegistry& registry) {
  registry.add(
      vdyn::PluginKind::Controller, "pure_pursuit",
      [](const vdyn::PluginSpec& spec) -> std::unique_ptr<vdyn::Plugin> {
        vdyn_example::PurePursuitParams p = vdyn_example::PurePursuitParams::fromParams(spec.params);
        if (spec.bindings.count("chassis")) p.chassis = spec.bindings.at("chassis");
        auto path = vdyn::makeReferencePath(spec.params.child("path"));
        return std::make_unique<vdyn_example::PurePursuitPlugin>(spec.name, p, std::move(path));
      },
      vdyn::typeInfo("pure pursuit path follower driving a state-driven steering (examples/pure_pursuit)",
                     vdyn_example::purePursuitFields()));
}
