// A plugin library as an out-of-tree user writes it (loaded by test_scene):
// registers a force element "fixture_push" (a constant force on a body, N,
// along ground x) with its field table.
#include "vdyn/core/fields.h"
#include "vdyn/core/plugin_library.h"
#include "vdyn/core/scene.h"

namespace {
struct PushParams {
  std::string body;
  double force_N = 0;
};
const vdyn::FieldTable<PushParams>& pushFields() {
  static const auto t = vdyn::FieldTable<PushParams>()
                            .string("body", &PushParams::body, "body pushed (bindable: attach chassis)")
                            .number("force_N", &PushParams::force_N, "N", "force along ground x");
  return t;
}

class Push : public vdyn::ForceElementPlugin {
 public:
  Push(std::string name, PushParams p) : ForceElementPlugin("fixture_push", std::move(name)), p_(std::move(p)) {}

 protected:
  void DoAddTo(vdyn::Scene& scene) override {
    SimTK::Force::ConstantForce(scene.updForces(), scene.getBody(p_.body), SimTK::Vec3(0),
                                SimTK::Vec3(p_.force_N, 0, 0));
  }

 private:
  PushParams p_;
};
}  // namespace

VDYN_PLUGIN_EXPORT int vdyn_plugin_abi_version() { return VDYN_PLUGIN_ABI_VERSION; }

VDYN_PLUGIN_EXPORT void vdyn_register_plugins(vdyn::PluginRegistry& registry) {
  registry.add(
      vdyn::PluginKind::ForceElement, "fixture_push",
      [](const vdyn::PluginSpec& spec) -> std::unique_ptr<vdyn::Plugin> {
        PushParams p = pushFields().read(spec.params);
        if (spec.bindings.count("chassis")) p.body = spec.bindings.at("chassis");
        if (p.body.empty()) throw vdyn::Error(spec.params.at("body") + ": missing (give it or attach chassis)");
        return std::make_unique<Push>(spec.name, p);
      },
      vdyn::typeInfo("test fixture: constant force along ground x on a body", pushFields()));
}
