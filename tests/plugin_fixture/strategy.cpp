// A plugin library that adds a rear_steer_strategy (loaded by ch8_maneuvers
// --plugin in Study.Ch8PluginStrategy): "fixture_linear", the linear law
// (6.9) written out of tree, delta_r* = Kr(U) delta_f with Kr of the rear_steer
// plugin's linear bicycle. Its runs equal the built-in "linear" strategy's.
#include "vdyn/core/plugin_library.h"
#include "vdyn/rear_steer/rear_steer.h"

namespace {
class FixtureLinear : public vdyn::RearSteerStrategy {
 public:
  explicit FixtureLinear(const vdyn::LinearBicycleParams& p) : p_(p) {}
  std::string name() const override { return "fixture_linear"; }

 protected:
  vdyn::RearSteerTarget DoCalcTarget(double U, double df, double dfd, double dfdd) const override {
    const double kr = vdyn::calcLinearOptimalRatio(p_, U);
    return {kr * df, kr * dfd, kr * dfdd, kr};
  }

 private:
  vdyn::LinearBicycleParams p_;
};
}  // namespace

VDYN_PLUGIN_EXPORT int vdyn_plugin_abi_version() { return VDYN_PLUGIN_ABI_VERSION; }

VDYN_PLUGIN_EXPORT void vdyn_register_plugins(vdyn::PluginRegistry& registry) {
  registry.addChoice<vdyn::RearSteerStrategy, vdyn::RearSteerContext>(
      "rear_steer_strategy", "fixture_linear",
      [](const vdyn::ParamReader&, const vdyn::RearSteerContext& c) { return std::make_unique<FixtureLinear>(c.linear); },
      vdyn::typeInfo("test fixture: the linear law (6.9) from a plugin library; no keys of its own", vdyn::noFields()));
}
