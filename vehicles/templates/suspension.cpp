// The suspension template registry (vdyn/vehicles/suspension.h).
#include "vdyn/vehicles/suspension.h"

#include <algorithm>

#include "vdyn/templates/double_wishbone.h"
#include "vdyn/templates/macpherson_strut.h"
#include "vdyn/templates/solid_axle.h"

#include "vdyn/plugins/builtin.h"
#include "vdyn/vehicles/anti_roll_bar.h"

namespace vdyn {

void Suspension::build(Scene& scene, SimTK::MobilizedBody& chassis, const std::string (&prefixes)[2],
                       const std::function<void(int side)>& afterCorner) {
  for (int side = 0; side < 2; ++side) {
    DoBuildCorner(scene, chassis, side, prefixes[side]);
    for (const std::string& role : bodyRoles()) bodies_[side][role] = scene.getBody(prefixes[side] + role);
    if (afterCorner) afterCorner(side);
  }
}

bool Suspension::hasBodyRole(const std::string& role) const {
  const std::vector<std::string> roles = bodyRoles();
  return std::find(roles.begin(), roles.end(), role) != roles.end();
}

const SimTK::MobilizedBody& Suspension::getBody(int side, const std::string& role) const {
  if (!hasBodyRole(role)) {
    std::string known;
    for (const std::string& r : bodyRoles()) known += (known.empty() ? "" : ", ") + r;
    throw Error("suspension template '" + templateName() + "' has no body of role '" + role + "' (roles: " + known +
                ")");
  }
  if (side != 0 && side != 1) throw Error("suspension getBody: side must be 0 (right) or 1 (left), got " + std::to_string(side));
  const auto it = bodies_[side].find(role);
  if (it == bodies_[side].end())
    throw Error("suspension template '" + templateName() + "': body '" + role + "' asked for before build()");
  return it->second;
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
  registerSolidAxle(registry);
}

const PluginRegistry& vehiclePlugins() {
  static const PluginRegistry registry = [] {
    PluginRegistry r = builtinPlugins();
    registerSuspensionTemplates(r);
    registerAntiRollBarTemplates(r);
    return r;
  }();
  return registry;
}

}  // namespace vdyn
