// The suspension template registry (vdyn/vehicles/suspension.h).
#include "vdyn/vehicles/suspension.h"

#include "vdyn/templates/double_wishbone.h"
#include "vdyn/templates/macpherson_strut.h"

#include "vdyn/plugins/builtin.h"

namespace vdyn {

void Suspension::build(Scene& scene, SimTK::MobilizedBody& chassis, const std::string (&prefixes)[2],
                       const std::function<void(int side)>& afterCorner) {
  for (int side = 0; side < 2; ++side) {
    DoBuildCorner(scene, chassis, side, prefixes[side]);
    if (afterCorner) afterCorner(side);
  }
}

void Suspension::setPositionFrom(SimTK::State&, int, const Suspension&, const SimTK::State&, double) const {
  throw Error("suspension template '" + templateName() + "' does not start from another template's assembly");
}

std::unique_ptr<Suspension> makeSuspension(const PluginRegistry& registry, const ParamReader& block) {
  std::unique_ptr<Suspension> s =
      registry.createChoice<Suspension>(kSuspensionFamily, block.string("template"), block, NoContext{},
                                        block.at("template"));
  block.requireAllKeysRead();
  return s;
}

void registerSuspensionTemplates(PluginRegistry& registry) {
  registerDoubleWishboneTemplates(registry);
  registerMacPhersonStrut(registry);
}

const PluginRegistry& vehiclePlugins() {
  static const PluginRegistry registry = [] {
    PluginRegistry r = builtinPlugins();
    registerSuspensionTemplates(r);
    return r;
  }();
  return registry;
}

}  // namespace vdyn
