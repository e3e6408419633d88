// A plugin library with a tire, as an out-of-tree user writes one (loaded by
// test_composition): force element "fixture_stiff_linear", the built-in
// linear tire with its cornering stiffness doubled and its radial stiffness
// 1.5 times the data's (so a steady turn, a transient and a static
// equilibrium all differ from the built-in "linear" with the same data). It
// delegates to the registry it was registered into: the vehicle's tire
// parameters pass through with the two coefficients scaled.
#include "vdyn/core/plugin_library.h"
#include "vdyn/core/scene.h"

namespace {
const double kCorneringScale = 2.0, kRadialScale = 1.5;
}  // namespace

VDYN_PLUGIN_EXPORT int vdyn_plugin_abi_version() { return VDYN_PLUGIN_ABI_VERSION; }

VDYN_PLUGIN_EXPORT void vdyn_register_plugins(vdyn::PluginRegistry& registry) {
  const vdyn::PluginRegistry* reg = &registry;
  registry.add(
      vdyn::PluginKind::ForceElement, "fixture_stiff_linear",
      [reg](const vdyn::PluginSpec& spec) -> std::unique_ptr<vdyn::Plugin> {
        vdyn::Json j = spec.params.json();
        spec.params.markAllRead();
        vdyn::Json& p = j["params"];
        p["cornering_stiffness_N_per_rad"] = kCorneringScale * p.at("cornering_stiffness_N_per_rad").get<double>();
        p["radial_stiffness_N_per_m"] = kRadialScale * p.at("radial_stiffness_N_per_m").get<double>();
        const vdyn::PluginSpec linear{spec.name, vdyn::ParamReader::fromJson(j, spec.params.where()), spec.bindings,
                                      spec.registry};
        return reg->create(vdyn::PluginKind::ForceElement, "linear", linear, spec.params.where());
      },
      {"test fixture: the linear tire with cornering stiffness x2 and radial stiffness x1.5 (keys: the linear "
       "tire's)",
       registry.info(vdyn::PluginKind::ForceElement, "linear").fields});
}
