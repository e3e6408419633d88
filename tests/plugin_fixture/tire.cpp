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

/// params[key], or the linear tire's default as its registered field table lists it.
double valueOr(const vdyn::Json& params, const std::string& key, const vdyn::PluginRegistry& registry) {
  if (params.contains(key)) return params.at(key).get<double>();
  for (const auto& f : registry.info(vdyn::PluginKind::ForceElement, "linear").fields)
    if (f.key == "params: " + key) return std::stod(f.default_value);
  throw vdyn::Error("fixture_stiff_linear: the linear tire lists no key '" + key + "'");
}
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
        p["cornering_stiffness_N_per_rad"] = kCorneringScale * valueOr(p, "cornering_stiffness_N_per_rad", *reg);
        p["radial_stiffness_N_per_m"] = kRadialScale * valueOr(p, "radial_stiffness_N_per_m", *reg);
        const vdyn::PluginSpec linear{spec.name, vdyn::ParamReader::fromJson(j, spec.params.where()), spec.bindings,
                                      spec.registry};
        return reg->create(vdyn::PluginKind::ForceElement, "linear", linear, spec.params.where());
      },
      {"test fixture: the linear tire with cornering stiffness x2 and radial stiffness x1.5 (keys: the linear "
       "tire's)",
       registry.info(vdyn::PluginKind::ForceElement, "linear").fields});
}
